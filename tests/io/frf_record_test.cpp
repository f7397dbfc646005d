// FRFs of a data file's columns, the record streamed (frf_record.h):
//   - a CSV of a known FIR system with response noise: every line within 5 std of the exact H once
//     turned into SI from the columns' units (lbf, g, mm), the scaled error's mean near 1;
//   - the streamed CSV (chunks of 65 536 rows) gives the in-memory Welch estimate of the whole record
//     to rounding, and a TDMS of the same record (read whole) the same;
//   - the default segment: the largest power of two up to the record / 4.5;
//   - the lines estimator on a multi-sine;
//   - a dropped sample past the first chunk, a column without a unit, an input that is no force:
//     one InputError naming the sample or column.
#include "scoleid/io/frf_record.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <complex>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "scoleid/io/data_files.h"
#include "scoleid/io/error.h"
#include "scoleid/io/frf_estimate.h"
#include "scoleid/io/tdms.h"

namespace fs = std::filesystem;
using namespace scoleid::io;
using cd = std::complex<double>;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kG = 9.80665, kLbf = 4.4482216152605, kMm = 1e-3;

fs::path scratch() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const fs::path d = fs::temp_directory_path() / ("scoleid-frf-record-" + std::to_string(::getpid()) + "-" + info->name());
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

// A record at fs: F white (in lbf), acc = a F[n] + b F[n-1] + noise (in g), disp = c F[n] + noise
// (in mm). H_acc(f) = a + b e^{-iω/fs} in g/lbf, H_disp = c in mm/lbf.
struct Record {
  double fs = 1024, a = 0.8, b = -0.3, c = 2.0;
  DataTable tab;
  explicit Record(std::size_t n, unsigned seed = 7) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> g(0.0, 1.0);
    tab.names = {"F [lbf]", "acc [g]", "disp [mm]"};
    tab.units = {"lbf", "g", "mm"};
    tab.columns.assign(3, std::vector<double>(n));
    double before = g(rng);
    for (std::size_t i = 0; i < n; ++i) {
      tab.t.push_back(static_cast<double>(i) / fs);
      const double f = g(rng);
      tab.columns[0][i] = f;
      tab.columns[1][i] = a * f + b * before + 0.2 * g(rng);
      tab.columns[2][i] = c * f + 0.1 * g(rng);
      before = f;
    }
  }
  cd H_acc_si(double f) const { return (a + b * std::polar(1.0, -2 * kPi * f / fs)) * kG / kLbf; }
  cd H_disp_si() const { return c * kMm / kLbf; }
};

RecordFrfOptions options() {
  RecordFrfOptions o;
  o.input = "F [lbf]";
  return o;
}

}  // namespace

TEST(FrfRecord, StreamedCsvMatchesTheSystemInSi) {
  const fs::path d = scratch();
  const Record rec(200000);
  write_csv((d / "r.csv").string(), rec.tab);
  const RecordFrf r = frf_of_record((d / "r.csv").string(), {}, options());
  EXPECT_NEAR(r.sample_rate, rec.fs, 1e-9);
  EXPECT_EQ(r.samples, 200000u);
  // Default segment: 2^floor(log2(200000 / 4.5)) = 32768; hop 16384: floor((200000 − 32768)/16384) + 1 segments.
  EXPECT_EQ(r.segments, (200000 - 32768) / 16384 + 1);
  ASSERT_EQ(r.data.channels.size(), 2u);
  EXPECT_EQ(r.orders, (std::vector<int>{2, 0}));
  EXPECT_NEAR(r.data.f_hz.back(), 0.8 * 512, 1024.0 / 32768);
  double worst = 0, mean = 0;
  long n = 0;
  for (std::size_t k = 0; k < r.data.f_hz.size(); ++k) {
    const double f = r.data.f_hz[k];
    for (int s = 0; s < 2; ++s) {
      const cd truth = s == 0 ? rec.H_acc_si(f) : rec.H_disp_si();
      const double z = std::norm(r.data.channels[s].H[k] - truth) / r.data.channels[s].variance[k];
      worst = std::max(worst, z);
      mean += z;
      ++n;
    }
  }
  mean /= double(n);
  std::printf("%ld values (K = %d): mean |H - H_true|^2 / variance %.3f, worst %.2f\n", n, r.segments, mean, worst);
  // |Ĥ1 − H|²/σ̂² follows F(2, 2K − 2) (frf_estimate.h): mean (K − 1)/(K − 2), survival
  // (1 + x/(K − 1))^−(K−1); no value beyond the level one in 1e9 exceeds.
  const double K = r.segments, expected = (K - 1) / (K - 2), bound = (K - 1) * (std::pow(1e-9, -1.0 / (K - 1)) - 1);
  EXPECT_LT(worst, bound) << "a value beyond the F law's 1e-9 level";
  EXPECT_NEAR(mean, expected, 0.1 * expected);
}

TEST(FrfRecord, ChunksChangeNothing) {
  const fs::path d = scratch();
  const Record rec(150001);
  write_csv((d / "r.csv").string(), rec.tab);
  write_tdms(rec.tab, (d / "r.tdms").string());
  RecordFrfOptions o = options();
  o.segment = 4096 / rec.fs;
  o.estimator = RecordFrfEstimator::H2;
  const RecordFrf csv = frf_of_record((d / "r.csv").string(), {}, o);
  const RecordFrf tdms = frf_of_record((d / "r.tdms").string(), {}, o);
  WelchOptions w;
  w.sample_rate = rec.fs;
  w.segment = 4096;
  w.estimator = FrfEstimator::H2;
  w.f_max = 0.8 * 512;
  WelchFrf whole(2, w);
  whole.add(rec.tab.columns[0].data(), {rec.tab.columns[1].data(), rec.tab.columns[2].data()}, rec.tab.t.size());
  const FrfData ref = whole.result("x", "F", {"acc", "disp"});
  ASSERT_EQ(csv.data.f_hz.size(), ref.f_hz.size());
  const double scale[2] = {kG / kLbf, kMm / kLbf};
  for (const RecordFrf* r : {&csv, &tdms})
    for (int s = 0; s < 2; ++s)
      for (std::size_t k = 0; k < ref.f_hz.size(); ++k) {
        EXPECT_NEAR(std::abs(r->data.channels[s].H[k] - ref.channels[s].H[k] * scale[s]), 0.0, 1e-12 * std::abs(ref.channels[s].H[k] * scale[s]));
        EXPECT_NEAR(r->data.channels[s].coherence[k], ref.channels[s].coherence[k], 1e-12);
      }
}

TEST(FrfRecord, LinesOfAMultisine) {
  const fs::path d = scratch();
  const double fs = 1000, lines[] = {7, 31, 113};
  const std::size_t n = 20000;
  DataTable tab;
  tab.names = {"F", "v"};
  tab.columns.assign(2, std::vector<double>(n));
  std::mt19937_64 rng(3);
  std::normal_distribution<double> g(0.0, 0.01);
  const cd H[3] = {{0.5, -0.2}, {-1.0, 0.4}, {0.1, 0.9}};  // m/s per N at each line
  for (std::size_t i = 0; i < n; ++i) {
    const double t = double(i) / fs;
    tab.t.push_back(t);
    for (int l = 0; l < 3; ++l) {
      const cd e = std::polar(1.0, 2 * kPi * lines[l] * t + l);
      tab.columns[0][i] += e.real();
      tab.columns[1][i] += (H[l] * e).real();
    }
    tab.columns[1][i] += g(rng);
  }
  write_csv((d / "r.csv").string(), tab);
  RecordFrfOptions o;
  o.input = "F";
  o.estimator = RecordFrfEstimator::Lines;
  o.lines_hz = {7, 31, 113};
  o.units = {{"F", "N"}, {"v", "m/s"}};
  const RecordFrf r = frf_of_record((d / "r.csv").string(), {}, o);
  ASSERT_EQ(r.data.lines(), 3);
  EXPECT_EQ(r.orders, std::vector<int>{1});
  for (int l = 0; l < 3; ++l) {
    const double z = std::norm(r.data.channels[0].H[l] - H[l]) / r.data.channels[0].variance[l];
    EXPECT_LT(z, 25.0) << "line " << lines[l] << " Hz: " << r.data.channels[0].H[l];
    EXPECT_LT(std::abs(r.data.channels[0].H[l] - H[l]), 1e-3);
  }
}

TEST(FrfRecord, RefusesWithOneLine) {
  const fs::path d = scratch();
  Record rec(100000);
  const auto refuse = [&](const std::string& file, const RecordFrfOptions& o, const std::string& needle) {
    try {
      frf_of_record(file, {}, o);
      ADD_FAILURE() << "not refused: " << needle;
    } catch (const InputError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find(needle), std::string::npos) << m;
      EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    }
  };
  // A sample dropped past the first chunk: sample 70 001 holds the time of 70 002.
  Record gap = rec;
  gap.tab.t.erase(gap.tab.t.begin() + 70000);
  for (auto& c : gap.tab.columns) c.erase(c.begin() + 70000);
  write_csv((d / "gap.csv").string(), gap.tab);
  refuse((d / "gap.csv").string(), options(), "sample 70001 (t = ");
  // No unit: the header says none and neither does --unit.
  Record bare = rec;
  bare.tab.names = {"F", "acc", "disp"};
  write_csv((d / "bare.csv").string(), bare.tab);
  RecordFrfOptions o;
  o.input = "F";
  o.units = {{"F", "N"}, {"acc", "m/s^2"}};
  refuse((d / "bare.csv").string(), o, "column 'disp' (--response): the file states no unit");
  write_csv((d / "r.csv").string(), rec.tab);
  o = options();
  o.input = "acc [g]";
  refuse((d / "r.csv").string(), o, "the input must be a force");
  // --unit replaces a unit the file states wrongly (a force channel labelled g), and says so.
  o = options();
  o.input = "acc [g]";
  o.responses = {"disp [mm]"};
  o.units = {{"acc [g]", "N"}};
  const RecordFrf relabelled = frf_of_record((d / "r.csv").string(), {}, o);
  EXPECT_NE(relabelled.note.find("column 'acc [g]' read in N (--unit; the file says g)"), std::string::npos) << relabelled.note;
  o = options();
  o.responses = {"nope"};
  refuse((d / "r.csv").string(), o, "--response names no column of the file");
}
