// scole-read-bench: how fast the data readers take a large record, and the memory they need.
// Writes a LabVIEW Measurement file (text, X_Columns One: a time column and the channels) of about
// --mb megabytes and a TDMS file (float64 channels, written as a DAQ logger writes: a first
// segment with metadata, then segments of raw data only, --segment samples per channel each) into
// --dir, then reads each in its own child process (this program re-executed with the hidden
// --child mode, so that its peak RSS is its own): the best of --repeat reads (steady_clock) and
// the growth of VmHWM over the reads. Reported per format: file size, samples, seconds, MB/s of
// file, and peak memory against the table read (samples x (channels + 1) x 8 bytes) and against
// the file. A record holds at most 5e6 samples (io/limits.h), which caps the TDMS file at
// 5e6 x channels x 8 bytes.
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "scoleid/io/error.h"
#include "scoleid/io/limits.h"
#include "scoleid/io/lvm.h"
#include "scoleid/io/tdms.h"

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

// VmHWM of this process in bytes.
double peak_rss() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::atof(line.c_str() + 6) * 1024.0;
  return 0.0;
}

// A smooth signal of channel j at sample k.
double signal(int j, std::size_t k) {
  const double t = static_cast<double>(k) * 1e-4;
  return (j + 1) * std::sin(2.0 * M_PI * (3.0 + j) * t) + 0.25 * std::cos(2.0 * M_PI * 37.0 * t);
}

std::size_t write_lvm(const fs::path& path, double megabytes, int channels) {
  std::FILE* out = std::fopen(path.c_str(), "w");
  if (!out) throw std::runtime_error("cannot write " + path.string());
  std::fprintf(out,
               "LabVIEW Measurement\t\nWriter_Version\t2\nReader_Version\t2\nSeparator\tTab\nDecimal_Separator\t.\n"
               "Multi_Headings\tNo\nX_Columns\tOne\nTime_Pref\tRelative\n***End_of_Header***\t\n\t\nChannels\t%d\n",
               channels);
  std::string units = "Y_Unit_Label", names = "X_Value", dx = "Delta_X", x0 = "X0", dim = "X_Dimension";
  for (int j = 0; j < channels; ++j) {
    units += j % 2 ? "\tg" : "\tNewtons";
    names += "\tch" + std::to_string(j);
    dx += "\t1.000000E-4";
    x0 += "\t0.0000000000000000E+0";
    dim += "\tTime";
  }
  std::fprintf(out, "%s\n%s\n%s\n%s\n***End_of_Header***\t\n%s\tComment\n", units.c_str(), dim.c_str(), x0.c_str(), dx.c_str(),
               names.c_str());
  const double target = megabytes * 1e6;
  std::size_t k = 0;
  char row[1024];
  for (long written = std::ftell(out); written < target && k < static_cast<std::size_t>(scoleid::io::limits::kMaxSamples); ++k) {
    int n = std::snprintf(row, sizeof row, "%.6f", static_cast<double>(k) * 1e-4);
    for (int j = 0; j < channels; ++j) n += std::snprintf(row + n, sizeof row - n, "\t%.9f", signal(j, k));
    row[n++] = '\n';
    std::fwrite(row, 1, static_cast<std::size_t>(n), out);
    written += n;
  }
  std::fclose(out);
  return k;
}

// Little-endian bytes.
template <class T>
void put(std::string& s, T v) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof v);
  s.append(b, sizeof(T));
}
void put_text(std::string& s, const std::string& t) {
  put<std::uint32_t>(s, static_cast<std::uint32_t>(t.size()));
  s += t;
}

std::size_t write_tdms(const fs::path& path, double megabytes, int channels, std::size_t per_segment) {
  const std::size_t samples = std::min<std::size_t>(static_cast<std::size_t>(megabytes * 1e6 / (8.0 * channels)),
                                                    static_cast<std::size_t>(scoleid::io::limits::kMaxSamples));
  std::ofstream out(path, std::ios::binary);
  std::vector<double> block(per_segment);
  for (std::size_t at = 0; at < samples; at += per_segment) {
    const std::size_t n = std::min(per_segment, samples - at);
    std::string meta;
    const bool first = at == 0;
    const bool same_layout = !first && n == per_segment;
    if (first || !same_layout) {
      put<std::uint32_t>(meta, static_cast<std::uint32_t>(channels + 2));
      put_text(meta, "/");
      put<std::uint32_t>(meta, 0xFFFFFFFFu);
      put<std::uint32_t>(meta, 0);
      put_text(meta, "/'bench'");
      put<std::uint32_t>(meta, 0xFFFFFFFFu);
      put<std::uint32_t>(meta, 0);
      for (int j = 0; j < channels; ++j) {
        put_text(meta, "/'bench'/'ch" + std::to_string(j) + "'");
        put<std::uint32_t>(meta, 20);
        put<std::uint32_t>(meta, 10);  // float64
        put<std::uint32_t>(meta, 1);
        put<std::uint64_t>(meta, n);
        put<std::uint32_t>(meta, first ? 3 : 0);
        if (first) {
          put_text(meta, "wf_increment");
          put<std::uint32_t>(meta, 10);
          put<double>(meta, 1e-4);
          put_text(meta, "wf_start_offset");
          put<std::uint32_t>(meta, 10);
          put<double>(meta, 0.0);
          put_text(meta, "unit_string");
          put<std::uint32_t>(meta, 0x20);
          put_text(meta, j % 2 ? "g" : "Newtons");
        }
      }
    }
    const std::uint32_t toc = (meta.empty() ? 0u : (1u << 1) | (1u << 2)) | (1u << 3);
    const std::uint64_t raw = static_cast<std::uint64_t>(n) * 8 * channels;
    std::string lead = "TDSm";
    put<std::uint32_t>(lead, toc);
    put<std::uint32_t>(lead, 4713);
    put<std::uint64_t>(lead, meta.size() + raw);
    put<std::uint64_t>(lead, meta.size());
    out.write(lead.data(), static_cast<std::streamsize>(lead.size()));
    out.write(meta.data(), static_cast<std::streamsize>(meta.size()));
    for (int j = 0; j < channels; ++j) {
      for (std::size_t k = 0; k < n; ++k) block[k] = signal(j, at + k);
      out.write(reinterpret_cast<const char*>(block.data()), static_cast<std::streamsize>(n * 8));
    }
  }
  if (!out) throw std::runtime_error("cannot write " + path.string());
  return samples;
}

// The child: reads `path` `repeat` times; prints "seconds samples columns hwm_growth".
int child(const std::string& format, const std::string& path, int repeat) {
  const double before = peak_rss();
  double best = 1e300;
  std::size_t samples = 0, columns = 0;
  for (int r = 0; r < repeat; ++r) {
    const auto t0 = Clock::now();
    const scoleid::io::DataTable tab = format == "lvm" ? scoleid::io::read_lvm(path) : scoleid::io::read_tdms(path);
    best = std::min(best, std::chrono::duration<double>(Clock::now() - t0).count());
    samples = tab.t.size();
    columns = tab.columns.size();
  }
  std::printf("%.6f %zu %zu %.0f\n", best, samples, columns, peak_rss() - before);
  return 0;
}

struct Result {
  double seconds = 0, growth = 0;
  std::size_t samples = 0, columns = 0;
};

Result run_child(const char* self, const std::string& format, const fs::path& path, int repeat) {
  int fds[2];
  if (pipe(fds) != 0) throw std::runtime_error("pipe");
  const pid_t pid = fork();
  if (pid == 0) {
    dup2(fds[1], 1);
    close(fds[0]);
    const std::string r = std::to_string(repeat);
    execl(self, self, "--child", format.c_str(), path.c_str(), r.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  close(fds[1]);
  std::string text;
  char buf[256];
  for (ssize_t n; (n = read(fds[0], buf, sizeof buf)) > 0;) text.append(buf, static_cast<std::size_t>(n));
  close(fds[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  Result r;
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 ||
      std::sscanf(text.c_str(), "%lf %zu %zu %lf", &r.seconds, &r.samples, &r.columns, &r.growth) != 4)
    throw std::runtime_error(format + " child failed (status " + std::to_string(status) + "): " + text);
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    if (argc == 5 && std::string(argv[1]) == "--child") return child(argv[2], argv[3], std::atoi(argv[4]));
    double mb = 200;
    int channels = 4, repeat = 3;
    std::size_t per_segment = 100000;
    fs::path dir = fs::temp_directory_path() / ("scole-read-bench-" + std::to_string(getpid()));
    bool keep = false;
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      auto next = [&]() -> std::string {
        if (i + 1 >= argc) throw std::runtime_error(a + " needs a value");
        return argv[++i];
      };
      if (a == "--mb") mb = std::atof(next().c_str());
      else if (a == "--channels") channels = std::atoi(next().c_str());
      else if (a == "--repeat") repeat = std::atoi(next().c_str());
      else if (a == "--segment") per_segment = static_cast<std::size_t>(std::atol(next().c_str()));
      else if (a == "--dir") dir = next();
      else if (a == "--keep") keep = true;
      else throw std::runtime_error("usage: scole-read-bench [--mb 200] [--channels 4] [--repeat 3] [--segment 100000] [--dir D] [--keep]");
    }
    fs::create_directories(dir);
    const fs::path lvm = dir / "bench.lvm", tdms = dir / "bench.tdms";
    std::printf("writing %.0f MB files into %s (%d channels) ...\n", mb, dir.c_str(), channels);
    write_tdms(tdms, mb, channels, per_segment);
    write_lvm(lvm, mb, channels);
    std::printf("%-5s %10s %9s %4s %9s %9s %12s %14s %13s\n", "file", "MB", "samples", "ch", "best s", "MB/s", "peak MB",
                "peak/table", "peak/file");
    for (const auto& [format, path] : {std::pair<std::string, fs::path>{"tdms", tdms}, {"lvm", lvm}}) {
      const Result r = run_child(argv[0], format, path, repeat);
      const double file_mb = static_cast<double>(fs::file_size(path)) / 1e6;
      const double table = static_cast<double>(r.samples) * static_cast<double>(r.columns + 1) * 8.0;
      std::printf("%-5s %10.1f %9zu %4zu %9.3f %9.1f %12.1f %14.2f %13.2f\n", format.c_str(), file_mb, r.samples, r.columns, r.seconds,
                  file_mb / r.seconds, r.growth / 1e6, r.growth / table, r.growth / (file_mb * 1e6));
    }
    if (!keep) fs::remove_all(dir);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "scole-read-bench: %s\n", e.what());
    return 1;
  }
}
