// scole-frf-file-bench: a long DAQ record turned into FRFs from its file, end to end (scole-data
// frf, io/frf_record.h), timed and measured for memory. Writes a CSV as a DAQ exports one — a
// time column to 1 µs, a force and two accelerations to 7 significant digits, units in brackets —
// of --seconds at --rate (default 60 s at 51 200 Hz: 3 channels, 9.2 M samples), then runs
// `scole-data frf FILE --input "F [N]" --segment 1.28 -o OUT.csv -q` as a child process: its wall
// time (steady_clock around fork/exec/wait) and its peak resident memory (wait4's ru_maxrss, the
// child's own). The same rounded values fed to the Welch estimator in memory give the reference:
// the file's FRFs must equal it to the 17 digits the CSV holds. The record's responses: the force
// (seeded Gaussian) through two-pole resonators at 120 and 1500 Hz, plus noise.
// Usage: scole-frf-file-bench [--seconds S] [--rate HZ] [--dir DIR] [--keep]
#include <sys/resource.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <complex>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "scoleid/io/data_files.h"
#include "scoleid/io/frf_estimate.h"

#ifndef SCOLE_DATA_EXE
#error "SCOLE_DATA_EXE must name the scole-data executable"
#endif

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

constexpr double kPi = 3.14159265358979323846;

struct Resonator {
  double a1, a2, y1 = 0, y2 = 0;
  Resonator(double f, double r, double rate) : a1(2 * r * std::cos(2 * kPi * f / rate)), a2(-r * r) {}
  double operator()(double x) {
    const double y = a1 * y1 + a2 * y2 + x;
    y2 = y1;
    y1 = y;
    return y;
  }
};

// A value as the DAQ writes it (7 significant digits) and as it reads back.
double rounded(double v, char* buf, int& len) {
  len = std::snprintf(buf, 32, "%.7g", v);
  return std::strtod(buf, nullptr);
}

}  // namespace

int main(int argc, char** argv) {
  double seconds = 60, rate = 51200;
  std::string dir = (fs::temp_directory_path() / ("scole-frf-file-bench-" + std::to_string(::getpid()))).string();
  bool keep = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--seconds" && i + 1 < argc) seconds = std::atof(argv[++i]);
    else if (a == "--rate" && i + 1 < argc) rate = std::atof(argv[++i]);
    else if (a == "--dir" && i + 1 < argc) dir = argv[++i];
    else if (a == "--keep") keep = true;
    else {
      std::fprintf(stderr, "usage: scole-frf-file-bench [--seconds S] [--rate HZ] [--dir DIR] [--keep]\n");
      return 2;
    }
  }
  if (!(seconds >= 4 && rate >= 1000)) {
    std::fprintf(stderr, "scole-frf-file-bench: needs --seconds >= 4 and --rate >= 1000\n");
    return 2;
  }
  fs::create_directories(dir);
  const std::string csv = dir + "/record.csv", out = dir + "/frf.csv";
  const std::size_t n = static_cast<std::size_t>(seconds * rate);
  const long segment = std::lround(1.28 * rate);

  // The record, written as it is generated; the reference estimator fed the same rounded values.
  scoleid::io::WelchOptions o;
  o.sample_rate = rate;
  o.segment = segment;
  o.f_max = 0.8 * 0.5 * rate;
  scoleid::io::WelchFrf reference(2, o);
  {
    std::FILE* f = std::fopen(csv.c_str(), "w");
    if (!f) {
      std::fprintf(stderr, "scole-frf-file-bench: cannot write %s\n", csv.c_str());
      return 1;
    }
    std::fprintf(f, "t [s],F [N],acc1 [m/s^2],acc2 [m/s^2]\n");
    Resonator r1(120, 0.999, rate), r2(1500, 0.998, rate);
    std::mt19937_64 rng(20261206);
    std::normal_distribution<double> g(0.0, 1.0);
    const std::size_t chunk = 65536;
    std::vector<double> x(chunk), y1(chunk), y2(chunk);
    char b0[32], b1[32], b2[32];
    int l0, l1, l2;
    for (std::size_t at = 0; at < n; at += chunk) {
      const std::size_t m = std::min(chunk, n - at);
      for (std::size_t i = 0; i < m; ++i) {
        const double force = g(rng);
        x[i] = rounded(force, b0, l0);
        y1[i] = rounded(1e3 * r1(force) + 0.01 * g(rng), b1, l1);
        y2[i] = rounded(1e2 * r2(force) + 0.01 * g(rng), b2, l2);
        std::fprintf(f, "%.6f,%s,%s,%s\n", double(at + i) / rate, b0, b1, b2);
      }
      reference.add(x.data(), {y1.data(), y2.data()}, m);
    }
    std::fclose(f);
  }
  const auto bytes = fs::file_size(csv);
  const scoleid::io::FrfData ref = reference.result("bench", "F", {"acc1", "acc2"});

  // scole-data frf in a child process of its own.
  const auto start = Clock::now();
  const pid_t pid = fork();
  if (pid == 0) {
    const char* args[] = {SCOLE_DATA_EXE, "frf", csv.c_str(), "--input", "F [N]", "--segment", "1.28", "-o", out.c_str(), "-q", nullptr};
    execv(SCOLE_DATA_EXE, const_cast<char* const*>(args));
    _exit(127);
  }
  int status = 0;
  rusage use{};
  wait4(pid, &status, 0, &use);
  const double wall = std::chrono::duration<double>(Clock::now() - start).count();
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::fprintf(stderr, "scole-frf-file-bench: scole-data frf failed (status %d)\n", status);
    return 1;
  }
  const double peak_mb = double(use.ru_maxrss) / 1024.0;

  // The file's FRFs against the reference.
  const scoleid::io::DataTable got = scoleid::io::read_csv(out);
  double worst = 0;
  bool same_lines = got.t.size() == ref.f_hz.size();
  for (std::size_t k = 0; same_lines && k < got.t.size(); ++k) {
    same_lines = std::abs(got.t[k] - ref.f_hz[k]) <= 1e-9 * ref.f_hz[k];
    for (int s = 0; s < 2; ++s) {
      const std::complex<double> h(got.columns[4 * s][k], got.columns[4 * s + 1][k]);
      worst = std::max(worst, std::abs(h - ref.channels[s].H[k]) / std::abs(ref.channels[s].H[k]));
    }
  }
  std::printf("record %.0f s at %.0f Hz: 3 channels x %zu samples (%.2f M values), CSV %.1f MB\n", seconds, rate, n, 3.0 * n / 1e6,
              double(bytes) / 1e6);
  std::printf("scole-data frf: %d segments of %ld, %zu lines: wall %.2f s (%.0f MB/s of file), peak RSS %.1f MB\n", ref.averages,
              segment, got.t.size(), wall, double(bytes) / 1e6 / wall, peak_mb);
  std::printf("file FRFs vs the in-memory estimate of the same values: lines %s, largest relative difference %.2e\n",
              same_lines ? "equal" : "DIFFER", worst);
  if (!keep) fs::remove_all(dir);
  return same_lines && worst < 1e-12 ? 0 : 1;
}
