// A tap test as a lab runs it, on the Simbody truth: a clamped strip, a 2 ms hammer pulse near the
// tip, three accelerometers, 2 kHz behind a DAQ's 8-pole anti-alias filter at 800 Hz on every
// channel (truth.anti_alias_hz), noise; the hammer's samples drive the model (as a measured input
// would). On the whole record from handbook starting values (8 elements), and in the band 5-300 Hz
// (16 elements: the band's third mode to the noise) from handbook values and from a start 50 % off:
// the fit converges, EI and ρA within 2 % (in the band 0.5 %), ζ within 15 % (2 %), every interval
// covering the truth (in the band under half as wide, and within ±5 % of the value), and the
// identified model's first three natural frequencies and damping ratios against the chain's own
// (scole-crosscheck modes), each within its propagated interval.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <unistd.h>

#include "scoleid/crosscheck/modes.h"
#include "scoleid/identify.h"
#include "scoleid/truth.h"
#include "common/truth_support.h"

using namespace scoleid;

namespace {

std::string tap_scenario(const std::string& initial, const std::string& band = "", int elements = 8) {
  return R"(name: tap-strip
structure: beam
beam: {length: 0.6, left: clamped, right: free, rho_A: 0.4, EI: 30, zeta: 0.01}
inputs:
  - {name: hammer, at: beam, kind: force, location: 0.55, unit: N,
     signal: {type: haversine, amplitude: 5, t0: 0.002, width: 0.002}}
sensors:
  - {name: acc1, at: beam, kind: acceleration, location: 0.3, unit: m/s^2, noise_std: 0.05}
  - {name: acc2, at: beam, kind: acceleration, location: 0.45, unit: m/s^2, noise_std: 0.05}
  - {name: acc3, at: beam, kind: acceleration, location: 0.6, unit: m/s^2, noise_std: 0.05}
simulation: {duration: 1.0, sample_interval: 0.0005, seed: 3}
identification: {estimate: [EI, rho_A, zeta], initial: )" +
         initial + (band.empty() ? std::string() : ", band: " + band) + ", elements: " + std::to_string(elements) + R"(}
truth: {segments: 80, anti_alias_hz: 800}
)";
}

}  // namespace

TEST(TapTest, FromHandbookAndFarStartsTheStripsParametersAndModesAreFound) {
  const io::Scenario sc = io::parse_scenario(tap_scenario("{EI: 27, rho_A: 0.44, zeta: 0.02}"), "tap test");
  const Truth truth = test::identification_truth(sc);
  crosscheck::ModesOptions mo;
  mo.count = 3;
  mo.levels = 1;
  const crosscheck::ModesReport chain = crosscheck::compare_modes(sc, mo);
  ASSERT_EQ(chain.modes.size(), 3u);
  struct Run {
    const char* start;
    const char* band;
  };
  double whole_width = 0.0;
  for (const Run run : {Run{"{EI: 27, rho_A: 0.44, zeta: 0.02}", ""}, Run{"{EI: 27, rho_A: 0.44, zeta: 0.02}", "[5, 300]"},
                        Run{"{EI: 45, rho_A: 0.2, zeta: 0.005}", "[5, 300]"}}) {
    const std::string start = run.start, band = run.band;
    const io::Scenario s = io::parse_scenario(tap_scenario(start, band.empty() ? "none" : band, band.empty() ? 8 : 16), "tap test");
    const auto wall0 = std::chrono::steady_clock::now();
    const Identification id = identify_parameters(s, DataSource::in_memory(truth.table, "tap truth", truth.meta), {});
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    std::printf("start %s, band %s: %.1f s\n%s", start.c_str(), band.empty() ? "none" : band.c_str(), wall,
                id.FullReport().c_str());
    ASSERT_TRUE(id.converged()) << id.verdict();
    const auto& r = id.result();
    // Fitting the band leaves out the modes the model does not follow: the intervals narrow.
    const double width = r.interval.half_width[0] / r.estimate[0];
    if (band.empty()) {
      whole_width = width;
    } else {
      EXPECT_LT(width, 0.5 * whole_width);
    }
    for (std::size_t i = 0; i < r.names.size(); ++i) {
      const auto e = static_cast<Eigen::Index>(i);
      const double rel = r.estimate[e] / r.truth.at(r.names[i]) - 1.0;
      if (!band.empty()) {
        EXPECT_LT(std::abs(rel), r.names[i] == "zeta" ? 0.02 : 0.005) << r.names[i];
        EXPECT_LE(r.interval.half_width[e], 0.05 * r.estimate[e]) << r.names[i];
      }
      EXPECT_LT(std::abs(rel), r.names[i] == "zeta" ? 0.15 : 0.02) << r.names[i];
      ASSERT_TRUE(r.ident.identifiable[i]) << r.names[i] << ": " << r.ident.reason[i];
      EXPECT_LE(std::abs(r.estimate[e] - r.truth.at(r.names[i])), r.interval.half_width[e]) << r.names[i];
    }
    ASSERT_GE(r.modes.size(), 3u);
    for (std::size_t k = 0; k < 3; ++k) {
      const auto& m = r.modes[k];
      const auto& c = chain.modes[k];
      std::printf("  mode %zu: identified %.4f Hz ± %.3g (zeta %.5f ± %.2g); chain (80 segments) %.4f Hz (zeta %.5f)\n", k + 1,
                  m.frequency_hz, m.frequency_half_width_hz, m.damping_ratio, m.damping_half_width, c.chain_hz.front(),
                  c.chain_zeta);
      EXPECT_LE(std::abs(m.frequency_hz - c.chain_hz.front()), m.frequency_half_width_hz) << "mode " << k + 1;
      EXPECT_LE(std::abs(m.damping_ratio - c.chain_zeta), m.damping_half_width) << "mode " << k + 1;
      EXPECT_LT(std::abs(m.frequency_hz / c.chain_hz.front() - 1.0), 0.01) << "mode " << k + 1;
    }
  }
}

// The record as a DAQ writes it, and a scenario with only the lab's facts: the time column in ms
// to 6 significant digits, accelerations in g under headers that carry their units ("acc1 [g]"),
// 0.05 s of pre-trigger, no noise_std anywhere (no truth.json beside the file), no band.
// The defaults do the rest: the sensors find their columns by name, the units are converted, the
// noise levels come from the pre-trigger, the force is windowed, the band is chosen from the
// record, the first attempt starts from the spectral start, the horizons start at the hit.
// Converged, EI and ρA within 1 %, ζ within 10 %, every interval covering the truth.
TEST(TapTest, ADaqFileWithOnlyTheLabsFactsIsIdentified) {
  const std::string truth_yaml = R"(name: daq-strip
structure: beam
beam: {length: 0.6, left: clamped, right: free, rho_A: 0.4, EI: 30, zeta: 0.01}
inputs:
  - {name: hammer, at: beam, kind: force, location: 0.55, unit: N, signal: {type: haversine, amplitude: 5, t0: 0.05, width: 0.002}}
sensors:
  - {name: acc1, at: beam, kind: acceleration, location: 0.3, unit: m/s^2, noise_std: 0.05}
  - {name: acc3, at: beam, kind: acceleration, location: 0.6, unit: m/s^2, noise_std: 0.05}
simulation: {duration: 1.0, sample_interval: 0.0005, seed: 3}
identification: {estimate: [EI, rho_A, zeta], initial: {EI: 27, rho_A: 0.44, zeta: 0.02}, elements: 16}
truth: {segments: 80, anti_alias_hz: 800}
)";
  const Truth truth = test::identification_truth(io::parse_scenario(truth_yaml, "truth.yaml"));
  std::string lab_yaml = truth_yaml;
  for (std::size_t at; (at = lab_yaml.find(", noise_std: 0.05")) != std::string::npos;) lab_yaml.erase(at, 17);
  const io::Scenario lab = io::parse_scenario(lab_yaml, "lab.yaml");
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("scoleid-daq-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string csv = (dir / "daq.csv").string();
  {
    std::ofstream f(csv);
    f << "Time [ms],hammer [N],acc1 [g],acc3 [g]\n";
    const auto& tab = truth.table;
    char buf[128];
    for (std::size_t k = 0; k < tab.t.size(); ++k) {
      std::snprintf(buf, sizeof buf, "%.6g,%.6g,%.6g,%.6g\n", tab.t[k] * 1e3, tab.columns[tab.find("hammer")][k],
                    tab.columns[tab.find("acc1")][k] / 9.80665, tab.columns[tab.find("acc3")][k] / 9.80665);
      f << buf;
    }
  }
  const Identification id = identify_parameters(lab, DataSource::file(csv), {});
  std::filesystem::remove_all(dir);
  std::printf("%s", id.FullReport().c_str());
  const auto& p = id.problem();
  EXPECT_EQ(p.noise_origin, (std::vector<std::string>{"pre-trigger", "pre-trigger"}));
  EXPECT_GE(p.columns.quiet_samples, 50);
  // The band chosen from the record (no band stated): the cantilever's first two modes inside,
  // the third (x = 0.118) outside, where the hammer's cubic reading is wrong by more than a
  // quarter of the 1 % model error; the top where it is wrong by at most half.
  const double base = std::sqrt(30.0 / (0.4 * std::pow(0.6, 4))) / (2.0 * M_PI);
  const double f1 = 1.8751041 * 1.8751041 * base, f2 = 4.6940911 * 4.6940911 * base, f3 = 7.8547574 * 7.8547574 * base;
  const auto& band = p.scenario.identification.band;
  ASSERT_EQ(band.size(), 2u) << p.band_note;
  EXPECT_EQ(p.band_note.rfind("auto: [", 0), 0u) << p.band_note;
  EXPECT_LT(band[0], f1);
  EXPECT_GT(band[1], 1.1 * f2);
  EXPECT_LT(band[1], f3);
  EXPECT_GT(io::cubic_table_error(f3 * 0.0005), 0.0025);
  EXPECT_LE(io::cubic_table_error(band[1] * 0.0005), 0.005 * (1 + 1e-6));
  ASSERT_TRUE(id.converged()) << id.verdict();
  // The first attempt holds (it starts from the spectral start: the handbook EI/rho_A is 10 % off in frequency).
  const auto& res = id.result();
  EXPECT_EQ(res.chosen_attempt, 0);
  EXPECT_LE(res.attempts.front().iterations, 10);
  const auto& r = id.result();
  const std::map<std::string, double> true_values{{"EI", 30.0}, {"rho_A", 0.4}, {"zeta", 0.01}};
  for (std::size_t i = 0; i < r.names.size(); ++i) {
    const auto e = static_cast<Eigen::Index>(i);
    const double truth_value = true_values.at(r.names[i]);
    EXPECT_LT(std::abs(r.estimate[e] / truth_value - 1.0), r.names[i] == "zeta" ? 0.10 : 0.01) << r.names[i];
    ASSERT_TRUE(r.ident.identifiable[i]) << r.names[i];
    EXPECT_LE(std::abs(r.estimate[e] - truth_value), r.interval.half_width[e]) << r.names[i];
  }
}

// A shaker record whose load cell reads with a static offset (-23 N) and the other way round
// (its column is -F - 23): at the start the run names the input for both, and with the offset and
// the sign stated in its conditioning, the estimates are the clean record's (to the writing's
// rounding) and within 1 % of the truth.
TEST(TapTest, AShakerLoadCellWithAnOffsetAndInvertedPolarityIsNamedAndConditionedAway) {
  const std::string yaml = R"(name: shaker-strip
structure: beam
beam: {length: 0.6, left: clamped, right: free, rho_A: 0.4, EI: 30, zeta: 0.01}
inputs:
  - {name: shaker, at: beam, kind: force, location: 0.3, unit: N, signal: {type: chirp, amplitude: 2, t0: 0.1, f0: 5, f1: 250, duration: 1.4}}
sensors:
  - {name: acc1, at: beam, kind: acceleration, location: 0.45, unit: m/s^2, noise_std: 0.02}
  - {name: acc3, at: beam, kind: acceleration, location: 0.6, unit: m/s^2, noise_std: 0.02}
simulation: {duration: 1.5, sample_interval: 0.0005, seed: 5}
identification: {estimate: [EI, rho_A, zeta], initial: {EI: 27, rho_A: 0.44, zeta: 0.02}, elements: 16}
truth: {segments: 80, anti_alias_hz: 800}
)";
  const Truth truth = test::identification_truth(io::parse_scenario(yaml, "truth.yaml"));
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("scoleid-shaker-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  auto write = [&](const std::string& name, double sign, double offset) {
    const std::string csv = (dir / name).string();
    std::ofstream f(csv);
    f << "t,shaker [N],acc1 [m/s^2],acc3 [m/s^2]\n";
    const auto& tab = truth.table;
    char buf[160];
    for (std::size_t k = 0; k < tab.t.size(); ++k) {
      std::snprintf(buf, sizeof buf, "%.9g,%.9g,%.9g,%.9g\n", tab.t[k], sign * tab.columns[tab.find("shaker")][k] + offset,
                    tab.columns[tab.find("acc1")][k], tab.columns[tab.find("acc3")][k]);
      f << buf;
    }
    return csv;
  };
  const std::string clean_csv = write("clean.csv", 1.0, 0.0), raw_csv = write("raw.csv", -1.0, -23.0);
  const io::Scenario sc = io::parse_scenario(yaml, "lab.yaml");
  const Identification clean = identify_parameters(sc, DataSource::file(clean_csv), {});
  // (the runs on a faulty column are only asked for their warnings: a short run, no restarts)
  auto with = [&](const std::string& conditioning, bool short_run) {
    std::string text = yaml;
    const std::string at = "unit: N, signal:";
    if (!conditioning.empty()) text.replace(text.find(at), at.size(), "unit: N, conditioning: " + conditioning + ", signal:");
    if (short_run) text.replace(text.find("elements: 16}"), 13, "elements: 16, max_iterations: 2, restarts: 0}");
    return identify_parameters(io::parse_scenario(text, "lab.yaml"), DataSource::file(raw_csv), {});
  };
  const Identification raw = with("", true);
  const Identification offset_stated = with("{offset: {mean_before: 0.1}}", true);
  const Identification conditioned = with("{offset: {mean_before: 0.1}, sign: -1}", false);
  std::filesystem::remove_all(dir);
  std::printf("clean:\n%s\nraw:\n%s\nconditioned:\n%s", clean.FullReport().c_str(), raw.FullReport().c_str(),
              conditioned.FullReport().c_str());
  auto said = [](const Identification& id, const std::string& a, const std::string& b) {
    const auto w = id.warnings();
    for (const auto& x : w) std::printf("warning: %s\n", x.c_str());
    return std::any_of(w.begin(), w.end(), [&](const std::string& x) { return x.find(a) != std::string::npos && x.find(b) != std::string::npos; });
  };
  // The raw record: the offset named, with the input, and its sign judged with the offset set
  // aside (a force of -23 N from t = 0 would ring the model as no record did).
  EXPECT_TRUE(said(raw, "input 'shaker' has a mean of -23", "offset")) << "no offset warning";
  EXPECT_TRUE(said(raw, "inverted", "input 'shaker'")) << "no polarity warning with the offset present";
  EXPECT_TRUE(said(raw, "inverted", "static offset of input 'shaker' set aside")) << "the offset's setting aside unsaid";
  // The offset stated: the sign named, with the input.
  EXPECT_TRUE(said(offset_stated, "inverted", "input 'shaker'")) << "no polarity warning";
  EXPECT_FALSE(said(offset_stated, "has a mean", "shaker"));
  // The same in frequency (start_check.frf): the raw record's responses half a turn from the
  // model's across the band, the conditioned record's in phase, each at about the model's scale.
  for (const Identification* id : {&raw, &conditioned}) {
    const auto& frf = id->result().start_check.frf;
    ASSERT_EQ(frf.size(), 2u) << id->result().start_check.frf_note;
    for (const auto& pair : frf) {
      std::printf("frf %s/%s: median ratio %.3g, median |phase| %.1f deg, %zu peaks\n", pair.input.c_str(), pair.sensor.c_str(),
                  pair.median_ratio, pair.median_phase_deg, pair.lines.size());
      EXPECT_EQ(pair.input, "shaker");
      EXPECT_FALSE(pair.lines.empty());
      if (id == &raw) { EXPECT_GT(pair.median_phase_deg, 135.0) << pair.sensor; }
      else EXPECT_LT(pair.median_phase_deg, 45.0) << pair.sensor;
      EXPECT_GT(pair.median_ratio, 1.0 / 3.0) << pair.sensor;
      EXPECT_LT(pair.median_ratio, 3.0) << pair.sensor;
    }
  }
  // The clean and the conditioned record: no such warning, the same estimates, within 1 % of the truth.
  for (const Identification* id : {&clean, &conditioned}) {
    for (const auto& x : id->warnings()) EXPECT_EQ(x.find("shaker"), std::string::npos) << x;
    ASSERT_TRUE(id->converged()) << id->verdict();
  }
  const auto& a = clean.result();
  const auto& b = conditioned.result();
  const std::map<std::string, double> true_values{{"EI", 30.0}, {"rho_A", 0.4}, {"zeta", 0.01}};
  for (std::size_t i = 0; i < a.names.size(); ++i) {
    const auto e = static_cast<Eigen::Index>(i);
    EXPECT_NEAR(b.estimate[e], a.estimate[e], 1e-6 * std::abs(a.estimate[e])) << a.names[i];
    EXPECT_LT(std::abs(a.estimate[e] / true_values.at(a.names[i]) - 1.0), a.names[i] == "zeta" ? 0.10 : 0.01) << a.names[i];
  }
}

