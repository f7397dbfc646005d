// Identification from a record as a test lab exports it (docs/data.md): a DAQ CSV with a comment
// line, a time column named "Time [s]", free-text channel names and accelerations in g, mapped to
// the scenario's sensors by `column:` and converted with UDUNITS-2; and the same record as a
// Universal File (dataset 58, ASCII).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "scoleid/identify.h"
#include "scoleid/io/data_files.h"
#include "scoleid/io/data_source.h"
#include "scoleid/io/error.h"
#include "common/scratch.h"
#include "common/test_data.h"

namespace fs = std::filesystem;
using namespace scoleid;

namespace {

constexpr double kG = 9.80665;  // standard gravity [m/s^2] (CGPM 1901)

// A tap test on a clamped aluminium-like strip: a hammer near the tip, two accelerometers.
const char* kStrip = R"(
name: tap-strip
structure: beam
units: SI
beam: {length: 0.6, left: clamped, right: free, rho_A: 0.4, EI: 30, zeta: 0.01}
inputs:
  - {name: hammer, column: "Hammer [N]", kind: force, location: 0.55, unit: N,
     signal: {type: haversine, amplitude: 5, t0: 0.002, width: 0.002}}
sensors:
  - {name: acc1, column: "Acc1 @0.30m [g]", kind: acceleration, location: 0.3, unit: m/s^2, noise_std: 0.02}
  - {name: acc2, column: "Acc2 @tip [g]", kind: acceleration, location: 0.6, unit: m/s^2, noise_std: 0.02}
simulation: {duration: 0.25, sample_interval: 0.0005, seed: 3}
identification: {estimate: [EI, rho_A], initial: {EI: 27, rho_A: 0.44}, elements: 8}
)";

const char* kHeader = "Time [s],Hammer [N],Acc1 @0.30m [g],Acc2 @tip [g]";

fs::path scratch(const std::string& name) {
  const fs::path d = scoleid::test::scratch_root() / name;
  fs::create_directories(d);
  return d;
}

std::string write(const fs::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
  return p.string();
}

// The record in g, as the DAQ writes it (17 digits, so nothing is lost in the file).
struct Record {
  std::vector<double> t, hammer;
  std::vector<std::vector<double>> acc_g;  // per sensor
};

Record tap_record(const io::Scenario& sc) {
  const identify::Measurements m = identify::synthesize(sc, 4 * sc.identification.elements, 1e-8, 2.5e-5, true);
  Record r;
  r.t = m.t;
  r.acc_g.resize(sc.sensors.size());
  for (std::size_t k = 0; k < m.t.size(); ++k) {
    r.hammer.push_back(sc.inputs[0].signal(m.t[k]));
    for (std::size_t j = 0; j < sc.sensors.size(); ++j)
      r.acc_g[j].push_back(m.z(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(j)) / kG);
  }
  return r;
}

std::string daq_csv(const Record& r) {
  std::ostringstream os;
  os << "# DAQ export, 2 kHz, channels in g\n" << kHeader << "\n";
  char buf[64];
  for (std::size_t k = 0; k < r.t.size(); ++k) {
    std::snprintf(buf, sizeof buf, "%.17g,%.17g", r.t[k], r.hammer[k]);
    os << buf;
    for (const auto& c : r.acc_g) {
      std::snprintf(buf, sizeof buf, ",%.17g", c[k]);
      os << buf;
    }
    os << "\n";
  }
  return os.str();
}

// The converter a user writes by hand: the DAQ file's values read, times 9.80665, written with the
// sensors' names as headers.
io::DataTable hand_converted(const std::string& daq_path) {
  io::DataTable daq = io::read_csv(daq_path);
  io::DataTable si;
  si.t = daq.t;
  si.names = {"hammer", "acc1", "acc2"};
  si.columns = {daq.columns[0], daq.columns[1], daq.columns[2]};
  for (std::size_t j = 1; j < 3; ++j)
    for (double& x : si.columns[j]) x *= kG;
  return si;
}

// One dataset 58 (ASCII, double precision, even abscissa): a time response as test programs write it.
std::string uff58(const std::string& id1, int node, int spec, const std::string& label, const std::string& unit,
                  const std::vector<double>& t, const std::vector<double>& y) {
  char buf[256];
  std::string s = "    -1\n    58\n";
  s += id1 + "\nNONE\n01-Dec-26 10:00:00\nNONE\nNONE\n";
  std::snprintf(buf, sizeof buf, "%5d%10d%5d%10d %-10s%10d%4d %-10s%10d%4d\n", 1, 0, 0, 0, "tap", node, 3, "NONE", 0, 0);
  s += buf;
  std::snprintf(buf, sizeof buf, "%10d%10zu%10d%13.5E%13.5E%13.5E\n", 4, t.size(), 1, t.front(), t[1] - t[0], 0.0);
  s += buf;
  std::snprintf(buf, sizeof buf, "%10d%5d%5d%5d %-20s %-20s\n", 17, 0, 0, 0, "Time", "s");
  s += buf;
  std::snprintf(buf, sizeof buf, "%10d%5d%5d%5d %-20s %-20s\n", spec, 0, 0, 0, label.c_str(), unit.c_str());
  s += buf;
  for (int k = 0; k < 2; ++k) {
    std::snprintf(buf, sizeof buf, "%10d%5d%5d%5d %-20s %-20s\n", 0, 0, 0, 0, "NONE", "NONE");
    s += buf;
  }
  for (std::size_t k = 0; k < y.size(); ++k) {
    std::snprintf(buf, sizeof buf, "%20.12E", y[k]);
    s += buf;
    if (k % 4 == 3 || k + 1 == y.size()) s += "\n";
  }
  return s + "    -1\n";
}

io::Scenario without_columns(io::Scenario sc) {
  for (auto& s : sc.sensors) s.column.clear();
  for (auto& in : sc.inputs) in.column.clear();
  return sc;
}

}  // namespace

TEST(LabData, DaqCsvInGIdentifiesAsTheHandConvertedFileDigitForDigit) {
  io::Scenario sc = io::parse_scenario(kStrip, "tap-strip.yaml");
  // The whole record (as before the band was chosen by default): this hammer is sampled without an
  // anti-alias filter, 4 samples across its pulse, and in the automatic band [6, 141] Hz its
  // reading's error leaves a residual 1.01 times the fit test's allowance (EI +0.09 %), where the
  // whole record passes (EI -1.4 %, within its interval).
  sc.identification.band_mode = io::IdentificationSpec::BandMode::None;
  const fs::path dir = scratch("daq");
  const std::string daq = write(dir / "tap.csv", daq_csv(tap_record(sc)));
  const std::string si = (dir / "tap-si.csv").string();
  io::write_csv(si, hand_converted(daq));

  const Identification a = identify_parameters(sc, DataSource::file(daq), {});
  const Identification b = identify_parameters(without_columns(sc), DataSource::file(si), {});
  ASSERT_EQ(a.names(), b.names());
  for (Eigen::Index i = 0; i < a.estimate().size(); ++i) EXPECT_EQ(a.estimate()[i], b.estimate()[i]) << a.names()[i];
  EXPECT_EQ(a.result().summary.iterations_done, b.result().summary.iterations_done);
  EXPECT_TRUE(a.converged()) << a.verdict();
  // And its interval holds the strip's EI 30 and rho_A 0.4 (the hammer's column, 4 samples across
  // its 2 ms pulse, is the record's largest error: the estimates' common scale).
  const auto params = a.to_json()["parameters"];
  const double truth[] = {30.0, 0.4};
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_LE(params[i]["interval"]["low"].get<double>(), truth[i]) << params[i]["name"];
    EXPECT_GE(params[i]["interval"]["high"].get<double>(), truth[i]) << params[i]["name"];
    EXPECT_NEAR(params[i]["estimate"].get<double>() / truth[i], 1.0, 0.05) << params[i]["name"];
  }
  // identify.json says where each sensor's values came from and the factor applied.
  const auto src = a.to_json()["data_columns"]["sources"];
  ASSERT_EQ(src.size(), 3u);
  EXPECT_EQ(src[0]["column"], "Acc1 @0.30m [g]");
  EXPECT_EQ(src[0]["column_unit"], "g");
  EXPECT_EQ(src[0]["unit"], "m/s^2");
  EXPECT_DOUBLE_EQ(src[0]["scale"].get<double>(), kG);
  EXPECT_EQ(src[2]["name"], "hammer");
  EXPECT_EQ(src[2]["scale"].get<double>(), 1.0);
}

TEST(LabData, UnitsThatCannotBeConvertedAreRefusedNamingFileColumnAndBoth) {
  const io::Scenario base = io::parse_scenario(kStrip, "tap-strip.yaml");
  const fs::path dir = scratch("refused");
  const std::string text = daq_csv(tap_record(base));
  auto error_of = [&](const std::string& from, const std::string& to, io::Scenario sc, const std::string& name) {
    std::string t = text;
    t.replace(t.find(from), from.size(), to);
    const std::string p = write(dir / name, t);
    try {
      prepare(sc, DataSource::file(p));
    } catch (const io::InputError& e) {
      return std::make_pair(p, std::string(e.what()));
    }
    return std::make_pair(p, std::string());
  };
  // The hammer's column in g: a force cannot be read from an acceleration (nor a gram).
  io::Scenario sc = base;
  sc.inputs[0].column = "Hammer [g]";
  auto [p1, e1] = error_of("Hammer [N]", "Hammer [g]", sc, "force-in-g.csv");
  EXPECT_EQ(e1, "data file '" + p1 + "': column 'Hammer [g]' (inputs[0], 'hammer'): cannot convert 'g' into 'N': 'g' is not a unit of force");
  // A unit no one knows.
  sc = base;
  sc.sensors[1].column = "Acc2 @tip [gee]";
  auto [p2, e2] = error_of("Acc2 @tip [g]", "Acc2 @tip [gee]", sc, "unknown.csv");
  EXPECT_EQ(e2, "data file '" + p2 + "': column 'Acc2 @tip [gee]' (sensors[1], 'acc2'): cannot convert 'gee' into 'm/s^2': 'gee' is not a unit UDUNITS-2 knows");
  // A column with a unit, a sensor without one in a scenario without a unit system: no silent label.
  sc = base;
  sc.units = io::units::System::None;
  sc.sensors[0].unit.clear();
  auto [p3, e3] = error_of("# DAQ", "# DAQ", sc, "no-unit.csv");
  EXPECT_EQ(e3, "data file '" + p3 + "': column 'Acc1 @0.30m [g]' (sensors[0], 'acc1'): is in 'g' but sensors[0] states no unit to convert it into: give sensors[0].unit or the scenario's units");
  // ... while the unit system alone gives it one.
  sc.units = io::units::System::SI;
  EXPECT_NO_THROW(prepare(sc, DataSource::file(p3)));
}

TEST(LabData, ScenarioUnitsMustAgreeWithTheUnitSystem) {
  using scoleid::test::replaced;
  using scoleid::test::scenario_error;
  EXPECT_EQ(scenario_error(replaced(kStrip, "unit: m/s^2", "unit: ft/s^2"), "strip.yaml"),
            "strip.yaml: sensors[0].unit must be the acceleration unit of the scenario's units (SI: m/s^2), got 'ft/s^2'");
  EXPECT_EQ(scenario_error(replaced(kStrip, "unit: N", "unit: m"), "strip.yaml"),
            "strip.yaml: inputs[0].unit must be a unit of force ('m' is not a unit of force), got 'm'");
  // The same unit spelled otherwise is the same unit.
  EXPECT_NO_THROW(io::parse_scenario(replaced(kStrip, "unit: m/s^2", "unit: m s-2"), "strip.yaml"));
}

TEST(LabData, TheSameRecordAsAUniversalFileIdentifiesTheSame) {
  const io::Scenario sc = io::parse_scenario(kStrip, "tap-strip.yaml");
  const fs::path dir = scratch("uff");
  const Record r = tap_record(sc);
  const std::string daq = write(dir / "tap.csv", daq_csv(r));
  // The DAQ file's values (as the CSV test reads them) into a UFF file: 13 significant digits.
  const io::DataTable d = io::read_csv(daq);
  const std::string uff = write(dir / "tap.uff", uff58("Hammer [N]", 55, 13, "Force", "N", d.t, d.columns[0]) +
                                                     uff58("Acc1 @0.30m [g]", 30, 12, "Acceleration", "g", d.t, d.columns[1]) +
                                                     uff58("Acc2 @tip [g]", 60, 12, "Acceleration", "g", d.t, d.columns[2]));
  const io::DataTable u = io::read_data(uff);
  EXPECT_EQ(u.names, d.names);
  EXPECT_EQ(u.units, (std::vector<std::string>{"N", "g", "g"}));
  ASSERT_EQ(u.t.size(), d.t.size());
  const Identification a = identify_parameters(sc, DataSource::file(daq), {});
  const Identification b = identify_parameters(sc, DataSource::file(uff), {});
  for (Eigen::Index i = 0; i < a.estimate().size(); ++i)
    EXPECT_NEAR(b.estimate()[i] / a.estimate()[i], 1.0, 1e-6) << a.names()[i];
  EXPECT_EQ(a.converged(), b.converged());
  // A spectrum is no record to identify from: refused naming the record and its type.
  std::string psd = uff58("Acc1 @0.30m [g]", 30, 12, "Acceleration", "g", d.t, d.columns[1]);
  psd.replace(psd.find("    1         0"), 5, "   12");
  const std::string p = write(dir / "spectrum.uff", psd);
  try {
    prepare(sc, DataSource::file(p));
    FAIL();
  } catch (const io::InputError& e) {
    EXPECT_EQ(std::string(e.what()), "UFF file '" + p + "': record 1 (dataset 58 at line 2, 'Acc1 @0.30m [g]'): function type 12 (Spectrum) is not a time response; only time responses (type 1) are data to identify from");
  }
}

// A DAQ header writes each channel's unit beside its name: "acc1 [g]" is the sensor acc1's column
// without any `column:` in the scenario, and the record identifies as with the columns named.
TEST(LabData, ChannelsNamedWithTheirUnitsAreTheSensorsOfThatName) {
  const io::Scenario sc = io::parse_scenario(kStrip, "strip.yaml");
  const Record r = tap_record(sc);
  const fs::path d = scratch("units-in-names");
  std::string csv = daq_csv(r);
  const std::string named = write(d / "named.csv", csv.replace(csv.find(kHeader), std::string(kHeader).size(),
                                                                   "Time [s],hammer [N],acc1 [g],acc2 [g]"));
  const std::string original = write(d / "daq.csv", daq_csv(r));
  const Identification a = identify_parameters(sc, DataSource::file(original), {});
  const Identification b = identify_parameters(without_columns(sc), DataSource::file(named), {});
  EXPECT_EQ(a.estimate(), b.estimate());
  // Two columns that are both the name with a unit: refused, naming both.
  std::string twice = daq_csv(r);
  twice.replace(twice.find(kHeader), std::string(kHeader).size(), "Time [s],hammer [N],acc1 [g],acc1 [m/s^2]");
  try {
    prepare(without_columns(sc), DataSource::file(write(d / "twice.csv", twice)));
    ADD_FAILURE() << "two candidate columns accepted";
  } catch (const io::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("columns 'acc1 [g]' and 'acc1 [m/s^2]' are both 'acc1' with a unit"), std::string::npos) << e.what();
  }
}

// A record that starts at rest holds each channel's noise: without a stated noise_std, the
// sensors get it from the samples before the hammer (within the √(2/N) scatter of N samples), the
// origin says so; a stated level is kept; a clean simulation's zeros give none; a start that
// already rings gives no more than the noise (the first-difference bound).
TEST(LabData, NoiseLevelsComeFromTheQuietStartWhenNotStated) {
  io::Scenario sc = io::parse_scenario(kStrip, "strip.yaml");
  sc.inputs[0].signal = io::parse_scenario(std::string(kStrip).replace(std::string(kStrip).find("t0: 0.002"), 9, "t0: 0.1"),
                                           "strip.yaml").inputs[0].signal;
  const double sigma = 0.02;
  const identify::Measurements m = identify::synthesize(sc, 4 * sc.identification.elements, 1e-8, 2.5e-5, true);
  auto table = [&](const identify::Measurements& meas, double ring) {
    io::DataTable tab;
    tab.source = "quiet.csv";
    tab.t = meas.t;
    tab.names = {"hammer", "acc1", "acc2"};
    tab.columns.assign(3, {});
    for (std::size_t k = 0; k < meas.t.size(); ++k) {
      tab.columns[0].push_back(sc.inputs[0].signal(meas.t[k]));
      tab.columns[1].push_back(meas.z(static_cast<Eigen::Index>(k), 0) + ring * std::sin(2 * M_PI * 20 * meas.t[k]));
      tab.columns[2].push_back(meas.z(static_cast<Eigen::Index>(k), 1));
    }
    return tab;
  };
  io::Scenario unstated = without_columns(sc);
  for (auto& s : unstated.sensors) s.noise_std = 0.0;
  unstated.identification.band_mode = io::IdentificationSpec::BandMode::None;  // the levels as read, not as a band filters them
  auto p = prepare(unstated, DataSource::in_memory(table(m, 0.0), "quiet.csv"));
  const int quiet = p->columns.quiet_samples;
  std::printf("  trigger at %.4f s, %d quiet samples; noise %.4g and %.4g (true %.3g, scatter %.2g)\n", p->columns.trigger_time, quiet,
              p->noise_std[0], p->noise_std[1], sigma, std::sqrt(2.0 / quiet));
  EXPECT_GT(quiet, 180);
  EXPECT_NEAR(p->columns.trigger_time, 0.1, 0.002);
  for (std::size_t j = 0; j < 2; ++j) {
    EXPECT_NEAR(p->noise_std[j] / sigma, 1.0, 3.0 * std::sqrt(2.0 / quiet)) << j;
    EXPECT_EQ(p->noise_origin[j], "pre-trigger");
  }
  // A stated level is used as stated; the other sensor's comes from the quiet start.
  io::Scenario one = unstated;
  one.sensors[1].noise_std = 0.05;
  p = prepare(one, DataSource::in_memory(table(m, 0.0), "quiet.csv"));
  EXPECT_EQ(p->noise_std[1], 0.05);
  EXPECT_EQ(p->noise_origin[1], "scenario");
  EXPECT_EQ(p->noise_origin[0], "pre-trigger");
  // A clean record: zeros before the hammer say nothing of the noise.
  const identify::Measurements clean = identify::synthesize(sc, 4 * sc.identification.elements, 1e-8, 2.5e-5, false);
  p = prepare(unstated, DataSource::in_memory(table(clean, 0.0), "quiet.csv"));
  EXPECT_EQ(p->noise_std[0], 0.0);
  EXPECT_EQ(p->columns.quiet_samples, 0);
  // A start that already rings (20 Hz, ten times the noise): the level is not inflated by it.
  p = prepare(unstated, DataSource::in_memory(table(m, 10 * sigma), "quiet.csv"));
  std::printf("  ringing start: acc1 noise %.4g (its quiet samples' RMS about %.3g)\n", p->noise_std[0], 10 * sigma / std::sqrt(2.0));
  EXPECT_LT(p->noise_std[0], 1.3 * sigma);
}

// A hammer's force channel reads its converter's noise before and after the hit. Taken as force,
// that noise drives the model at every sample (an accelerometer answers force directly); the
// default force window zeroes the column outside the hit, recorded with the hits it found. A
// second hit is named. `window: none` keeps the column as it is.
TEST(LabData, AnImpactForceIsWindowedByDefaultAndADoubleHitIsNamed) {
  std::string yaml = kStrip;
  yaml.replace(yaml.find("t0: 0.002, width: 0.002"), 23, "t0: 0.05, width: 0.004");  // a soft tip: 6 samples over a tenth
  io::Scenario sc = without_columns(io::parse_scenario(yaml, "strip.yaml"));
  sc.identification.elements = 16;
  sc.identification.band = {5.0, 300.0};  // a sampled hammer's content near the sampling rate is not the model's to follow
  const identify::Measurements m = identify::synthesize(sc, 4 * sc.identification.elements, 1e-8, 2.5e-5, true);
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.01);  // N: the force channel's converter noise
  io::DataTable tab;
  tab.source = "hammer.csv";
  tab.t = m.t;
  tab.names = {"hammer", "acc1", "acc2"};
  tab.columns.assign(3, {});
  for (std::size_t k = 0; k < m.t.size(); ++k) {
    tab.columns[0].push_back(sc.inputs[0].signal(m.t[k]) + noise(rng));
    for (int j = 0; j < 2; ++j) tab.columns[static_cast<std::size_t>(j + 1)].push_back(m.z(static_cast<Eigen::Index>(k), j));
  }
  const Identification windowed = identify_parameters(sc, DataSource::in_memory(tab, "hammer.csv"), {});
  io::Scenario raw_sc = sc;
  raw_sc.inputs[0].conditioning.window = io::Conditioning::Window::None;
  const Identification raw = identify_parameters(raw_sc, DataSource::in_memory(tab, "hammer.csv"), {});
  const auto& st = windowed.problem().columns.stepped_inputs.at(0);
  ASSERT_TRUE(st.windowed);
  EXPECT_FALSE(raw.problem().columns.stepped_inputs.at(0).windowed);
  EXPECT_LE(st.window_from, 0.05);
  EXPECT_GE(st.window_to, 0.053);
  EXPECT_LT(st.window_to - st.window_from, 0.01);
  ASSERT_EQ(st.hits.size(), 1u);
  // The model's response before the window: nothing with it; the noise's answer without.
  auto before_window_rms = [&](const Identification& id) {
    const io::DataTable fit = id.fit_table();
    double s = 0.0;
    int n = 0;
    for (std::size_t k = 0; k < fit.t.size() && fit.t[k] < st.window_from - 0.001; ++k, ++n) s += std::pow(fit.columns[4][k], 2);  // acc2_predicted
    return std::sqrt(s / n);
  };
  const double w_rms = before_window_rms(windowed), r_rms = before_window_rms(raw);
  std::printf("  window %.5g .. %.5g s, %zu hit(s)\n", st.window_from, st.window_to, st.hits.size());
  std::printf("  tip acceleration predicted before the window (%.4g s): %.3g m/s^2 windowed, %.3g raw\n", st.window_from, w_rms, r_rms);
  std::printf("  windowed: EI %.5g rho_A %.5g (%s); raw: EI %.5g rho_A %.5g (%s)\n", windowed.estimate()[0], windowed.estimate()[1],
              windowed.converged() ? "converged" : "not converged", raw.estimate()[0], raw.estimate()[1],
              raw.converged() ? "converged" : "not converged");
  EXPECT_EQ(w_rms, 0.0);
  EXPECT_GT(r_rms, 1e-4);
  EXPECT_TRUE(windowed.converged()) << windowed.verdict();
  EXPECT_NEAR(windowed.estimate()[0] / 30.0, 1.0, 0.01);
  EXPECT_NEAR(windowed.estimate()[1] / 0.4, 1.0, 0.01);
  // A double hit: two 2 ms taps, the second of 40 % four milliseconds after the first.
  io::DataTable twice = tab;
  auto haversine = [](double t, double t0, double w) { return t < t0 || t > t0 + w ? 0.0 : 0.5 * (1.0 - std::cos(2 * M_PI * (t - t0) / w)); };
  for (std::size_t k = 0; k < twice.t.size(); ++k)
    twice.columns[0][k] = 5.0 * haversine(twice.t[k], 0.05, 0.002) + 2.0 * haversine(twice.t[k], 0.054, 0.002) + noise(rng);
  const auto p = prepare(sc, DataSource::in_memory(twice, "hammer.csv"));
  const auto& st2 = p->columns.stepped_inputs.at(0);
  ASSERT_EQ(st2.hits.size(), 2u);
  EXPECT_NEAR(st2.hits[1].first - st2.hits[0].first, 0.004, 0.0006);
  EXPECT_NEAR(st2.hits[1].second, 0.4, 0.05);
}

// data.window: a record that holds, after the test, a knock while the strip was handled (a burst
// the hammer did not cause). Fitted whole, the model is driven to explain it; within the window
// the estimates are the strip's. A window that holds no sample is refused, naming the field and
// the record's span.
TEST(LabData, AFitWindowLeavesOutWhatTheRecordHoldsAfterTheTest) {
  std::string yaml = kStrip;
  yaml.replace(yaml.find("t0: 0.002, width: 0.002"), 23, "t0: 0.05, width: 0.004");
  yaml.replace(yaml.find("duration: 0.25"), 14, "duration: 0.5");
  io::Scenario sc = without_columns(io::parse_scenario(yaml, "strip.yaml"));
  sc.identification.elements = 16;
  sc.identification.band = {5.0, 300.0};
  const identify::Measurements m = identify::synthesize(sc, 4 * sc.identification.elements, 1e-8, 2.5e-5, true);
  io::DataTable tab;
  tab.source = "knock.csv";
  tab.t = m.t;
  tab.names = {"hammer", "acc1", "acc2"};
  tab.columns.assign(3, {});
  for (std::size_t k = 0; k < m.t.size(); ++k) {
    const double t = m.t[k];
    // The knock: 0.4 s in, a 90 Hz burst of 5 m/s^2 under a Gaussian envelope of 10 ms at both sensors.
    const double knock = 5.0 * std::exp(-std::pow((t - 0.42) / 0.01, 2)) * std::sin(2 * M_PI * 90 * t);
    tab.columns[0].push_back(sc.inputs[0].signal(t));
    for (int j = 0; j < 2; ++j) tab.columns[static_cast<std::size_t>(j + 1)].push_back(m.z(static_cast<Eigen::Index>(k), j) + knock);
  }
  const Identification whole = identify_parameters(sc, DataSource::in_memory(tab, "knock.csv"), {});
  io::Scenario windowed_sc = sc;
  windowed_sc.data.window = {0.0, 0.38};
  const Identification windowed = identify_parameters(windowed_sc, DataSource::in_memory(tab, "knock.csv"), {});
  const auto& w = windowed.problem().columns.window;
  ASSERT_EQ(w.size(), 2u);
  EXPECT_EQ(w[0], 0.0);
  EXPECT_NEAR(w[1], 0.38, 0.0005);
  EXPECT_EQ(windowed.problem().data.t.back(), w[1]);
  std::printf("  whole record: EI %.5g rho_A %.5g (%s); window [0, 0.38]: EI %.5g rho_A %.5g (%s)\n", whole.estimate()[0],
              whole.estimate()[1], whole.converged() ? "converged" : "not converged", windowed.estimate()[0], windowed.estimate()[1],
              windowed.converged() ? "converged" : "not converged");
  EXPECT_FALSE(whole.converged() && std::abs(whole.estimate()[0] / 30.0 - 1.0) < 0.01 && std::abs(whole.estimate()[1] / 0.4 - 1.0) < 0.01)
      << "the knock left no mark: the test shows nothing";
  EXPECT_TRUE(windowed.converged()) << windowed.verdict();
  EXPECT_NEAR(windowed.estimate()[0] / 30.0, 1.0, 0.01);
  EXPECT_NEAR(windowed.estimate()[1] / 0.4, 1.0, 0.01);
  io::Scenario outside = sc;
  outside.data.window = {2.0, 3.0};
  const std::string why = test::input_error_of([&] { prepare(outside, DataSource::in_memory(tab, "knock.csv")); });
  EXPECT_NE(why.find("data.window"), std::string::npos) << why;
  EXPECT_NE(why.find("holds 0 samples"), std::string::npos) << why;
  EXPECT_NE(why.find("from 0 to 0.5 s"), std::string::npos) << why;
}
