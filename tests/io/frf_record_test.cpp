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

#include <algorithm>
#include <cmath>
#include <complex>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "scoleid/io/data_files.h"
#include "scoleid/io/error.h"
#include "scoleid/io/frf_estimate.h"
#include "scoleid/io/quiet_start.h"
#include "common/scratch.h"
#include "scoleid/io/tdms.h"

namespace fs = std::filesystem;
using namespace scoleid::io;
using cd = std::complex<double>;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kG = 9.80665, kLbf = 4.4482216152605, kMm = 1e-3;

fs::path scratch() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const fs::path d = scoleid::test::scratch_root() / info->name();
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

// The quiet start's noise (quiet_start.h): white noise's σ from its samples; a drift or a start
// already ringing lowers the estimate (the first difference's), never raises it; zero says nothing.
TEST(QuietStart, TheNoiseBeforeTheHit) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> g(0.0, 0.02);
  std::vector<double> y(400), drift(400), zero(400, 0.0);
  for (std::size_t i = 0; i < y.size(); ++i) {
    y[i] = g(rng);
    drift[i] = y[i] + 0.5 * double(i) / 400.0;  // a slow drift of 25 sigma
  }
  const double s = quiet_start_noise(y.data(), y.size()), sd = quiet_start_noise(drift.data(), drift.size());
  std::printf("white: %.4f (0.02), with a drift: %.4f\n", s, sd);
  EXPECT_NEAR(s, 0.02, 0.1 * 0.02);  // 400 samples: about 4 % sampling error
  EXPECT_NEAR(sd, 0.02, 0.1 * 0.02);
  EXPECT_EQ(quiet_start_noise(zero.data(), zero.size()), 0.0);
  // The trigger: the first sample above a twentieth of the peak, and 4 samples of margin.
  std::vector<double> x(300, 0.0);
  x[120] = 0.04;
  x[121] = 1.0;
  EXPECT_EQ(trigger_sample(x.data(), x.size()), 121u);
  EXPECT_EQ(quiet_samples(121), 117u);
  EXPECT_EQ(quiet_samples(53), 0u);
  EXPECT_EQ(trigger_sample(zero.data(), zero.size()), zero.size());
}

// Impact (frf_record.h): a hit from rest through a resonator, written as a CSV in lbf and g. The FRFs
// are the resonator's transfer function at z = e^{(a + iω)/fs} in SI; each value's variance rests on
// the response's noise read off the quiet start (|Ĥ − H|² / variance averages 1 over the lines); a
// stated level replaces it; a record whose hit comes too early for a quiet start, stated nothing,
// is refused naming the column.
TEST(FrfRecord, AnImpactFromItsQuietStart) {
  const fs::path d = scratch();
  const double fs = 1000, r = 0.999, theta = 2 * kPi * 40 / fs, sigma = 0.01;
  const std::size_t n = 4000, hit = 300;
  std::mt19937_64 rng(9);
  std::normal_distribution<double> g(0.0, sigma);
  DataTable tab;
  tab.names = {"F [lbf]", "acc [g]"};
  tab.units = {"lbf", "g"};
  tab.columns.assign(2, std::vector<double>(n, 0.0));
  for (std::size_t i = 0; i < 6; ++i) tab.columns[0][hit + i] = 5.0 * std::sin(kPi * double(i + 1) / 7.0);  // a 6-sample pulse
  double y1 = 0, y2 = 0;
  for (std::size_t i = 0; i < n; ++i) {
    tab.t.push_back(double(i) / fs);
    const double y = 2 * r * std::cos(theta) * y1 - r * r * y2 + tab.columns[0][i];
    tab.columns[1][i] = y + g(rng);
    y2 = y1;
    y1 = y;
  }
  write_csv((d / "hit.csv").string(), tab);
  RecordFrfOptions o;
  o.input = "F [lbf]";
  o.estimator = RecordFrfEstimator::Impact;
  // The default window leaves a hundredth at the end: ln 100 / T.
  EXPECT_DOUBLE_EQ(frf_of_record((d / "hit.csv").string(), {}, o).data.decay, std::log(100.0) / (double(n) / fs));
  // e^{-5 t}: the response left at the end, windowed, 2e-9 of its start (below the noise).
  const double a = 5.0;
  o.decay = a;
  const RecordFrf f = frf_of_record((d / "hit.csv").string(), {}, o);
  EXPECT_DOUBLE_EQ(f.data.decay, a);
  EXPECT_NE(f.note.find("1 of 1 noise levels from the quiet start (296 samples)"), std::string::npos) << f.note;
  const double sigma_hat = quiet_start_noise(tab.columns[1].data(), 296);
  double mean = 0, worst = 0, w2 = 0, var_error = 0;
  for (std::size_t i = 0; i < n; ++i) w2 += std::exp(-2 * a * double(i) / fs);
  const std::size_t lines = f.data.f_hz.size();
  for (std::size_t k = 0; k < lines; ++k) {
    const cd z1 = std::exp(-cd(a, 2 * kPi * f.data.f_hz[k]) / fs);
    const cd exact = 1.0 / (1.0 - 2 * r * std::cos(theta) * z1 + r * r * z1 * z1) * kG / kLbf;  // g/lbf in SI
    const double z = std::norm(f.data.channels[0].H[k] - exact) / f.data.channels[0].variance[k];
    mean += z / double(lines);
    worst = std::max(worst, z);
    // The variance: σ̂² Σw² / |X_k|² in the file's units, times the square of the units' ratio.
    cd X = 0;
    for (std::size_t i = hit; i < hit + 6; ++i)
      X += std::exp(-a * double(i) / fs) * tab.columns[0][i] * std::polar(1.0, -2 * kPi * double(k + 1) * double(i) / double(n));
    const double v = sigma_hat * sigma_hat * w2 / std::norm(X) * std::pow(kG / kLbf, 2);
    var_error = std::max(var_error, std::abs(f.data.channels[0].variance[k] / v - 1));
  }
  std::printf("sigma from the quiet start %.5f (true %.5f); %zu lines: |H - H_true|^2 / variance mean %.3f, worst %.1f; variance vs "
              "sigma^2 sum w^2 / |X|^2: %.1e\n",
              sigma_hat, sigma, lines, mean, worst, var_error);
  EXPECT_NEAR(sigma_hat, sigma, 0.15 * sigma);
  EXPECT_LT(var_error, 1e-9);
  // Each |δH|²/variance is (σ/σ̂)² times an exponential of mean 1; the window correlates lines within
  // about a/π Hz, so their mean scatters widely, but none lies beyond e^-30.
  EXPECT_LT(worst, 30.0);
  EXPECT_GT(mean, 0.4);
  EXPECT_LT(mean, 2.5);
  // Static offsets on both channels (a load cell's 0.3 lbf, an accelerometer's 0.05 g) are the quiet
  // start's means: removed, the FRFs are those of the clean record to rounding.
  DataTable offset = tab;
  for (double& v : offset.columns[0]) v += 0.3;
  for (double& v : offset.columns[1]) v += 0.05;
  write_csv((d / "offset.csv").string(), offset);
  const RecordFrf fo = frf_of_record((d / "offset.csv").string(), {}, o);
  EXPECT_NE(fo.note.find("each channel's mean there removed"), std::string::npos) << fo.note;
  double offset_error = 0;
  for (std::size_t k = 0; k < lines; ++k)
    offset_error = std::max(offset_error, std::abs(fo.data.channels[0].H[k] - f.data.channels[0].H[k]) /
                                              std::sqrt(f.data.channels[0].variance[k]));
  std::printf("offsets removed: largest change %.2e of a value's std\n", offset_error);
  EXPECT_LT(offset_error, 0.05);  // the quiet start's mean carries its noise: 0.01 g / sqrt(296) against the std
  // A stated level (in the column's unit, g) is used as stated: the variance scales by its square.
  o.noise = {{"acc [g]", 2 * sigma_hat}};
  const RecordFrf stated = frf_of_record((d / "hit.csv").string(), {}, o);
  EXPECT_NE(stated.note.find("0 of 1 noise levels"), std::string::npos) << stated.note;
  EXPECT_NEAR(stated.data.channels[0].variance[10], 4 * f.data.channels[0].variance[10], 1e-9 * stated.data.channels[0].variance[10]);
  // The hit at sample 30: no quiet start, nothing stated: refused, naming the column.
  DataTable early = tab;
  std::rotate(early.columns[0].begin(), early.columns[0].begin() + 270, early.columns[0].end());
  std::rotate(early.columns[1].begin(), early.columns[1].begin() + 270, early.columns[1].end());
  write_csv((d / "early.csv").string(), early);
  o.noise.clear();
  try {
    frf_of_record((d / "early.csv").string(), {}, o);
    ADD_FAILURE() << "not refused";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("column 'acc [g]' has no noise level"), std::string::npos) << m;
    EXPECT_NE(m.find("30 samples precede the hit"), std::string::npos) << m;
    EXPECT_NE(m.find("--noise"), std::string::npos) << m;
  }
  // --decay and --noise belong to the impact estimator.
  RecordFrfOptions welch = options();
  welch.input = "F [lbf]";
  welch.decay = 2;
  EXPECT_THROW(frf_of_record((d / "hit.csv").string(), {}, welch), InputError);
}
