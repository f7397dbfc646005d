// Mismatch scenarios: the Simbody truth with truth.overrides.
// - End to end: the reflector's CM offset 5 % larger than the identifier's model, then the FE
//   identifier on the truth's files. The truth records the values it used; the identifier's
//   estimates move far beyond the chain's own lumping bias — the size of the mismatch, measured.
// - Sensor overrides: a sensor misaligned by 1° reads the projection of the same motion onto its
//   tilted axis; bias and drift add bias + drift·t to the ideal read-out; a moved sensor reads
//   what a sensor placed there reads.
// - Servo lag (scole.actuator_lag τ): the lagged force history against the closed-form
//   convolution of the command with the kernel e^{-t/τ}/τ; in the truth, a small τ delays the
//   response by τ to first order, a large one changes it; the FE model refuses τ > 0.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "scoleid/identify/door/scenario_door.h"
#include "scoleid/identify/fe/structure.h"
#include "scoleid/io/data_files.h"
#include "scoleid/io/error.h"
#include "scoleid/io/scenario.h"
#include "scoleid/model/inputs.h"
#include "scoleid/model/truth_run.h"

namespace fs = std::filesystem;

namespace {
int sh(const std::string& cmd) {
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}
nlohmann::json read_json(const fs::path& p) {
  std::ifstream in(p);
  return nlohmann::json::parse(in);
}
double worst_error(const nlohmann::json& identify) {
  double w = 0.0;
  for (const auto& p : identify["parameters"]) w = std::max(w, std::abs(p["relative_error"].get<double>()));
  return w;
}
}  // namespace

TEST(TruthOverrides, ReflectorOffsetMismatchEndToEnd) {
  const fs::path dir = fs::temp_directory_path() / ("scoleid-overrides-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::string base = scoleid::io::builtin_scenario_yaml("paper-scole-1");
  base.replace(base.find("truth: {segments: 40}"), 21, "truth: {segments: 10}");
  const scoleid::io::Scenario nominal = scoleid::io::parse_scenario(base, "paper-scole-1");
  const double rx = 1.05 * nominal.scole.reflector_rx, ry = 1.05 * nominal.scole.reflector_ry;
  std::ostringstream ov;
  ov.precision(17);
  ov << base.substr(0, base.find("truth: {segments: 10}")) << "truth:\n  segments: 10\n  overrides:\n    scole: {reflector_rx: "
     << rx << ", reflector_ry: " << ry << "}\n";
  std::ofstream(dir / "base.yaml") << base;
  std::ofstream(dir / "ov.yaml") << ov.str();
  int status[2] = {-1, -1};
  for (int k = 0; k < 2; ++k) {
    const std::string d = (dir / (k ? "ov" : "base")).string();
    ASSERT_EQ(sh(std::string(SCOLE_TRUTH_EXE) + " --quiet --scenario " + d + ".yaml --out " + d + "/truth"), 0) << d;
    status[k] = sh(std::string(SCOLE_IDENTIFY_EXE) + " -q --scenario " + d + ".yaml --data " + d + "/truth/truth.csv --out " +
                   d + "/identify > /dev/null 2>&1");
  }
  // The matched model explains its data; the mismatched one converges, and exits 1 exactly when its
  // fit test says the model does not explain the data (the wrong geometry shows in the residual).
  EXPECT_EQ(status[0], 0);
  const auto ov_run = read_json(dir / "ov" / "identify" / "identify.json");
  EXPECT_TRUE(ov_run["optimizer_converged"].get<bool>());
  EXPECT_EQ(status[1] == 0, ov_run["fit_test"]["explains_data"].get<bool>()) << ov_run["fit_test"]["message"];
  EXPECT_EQ(ov_run["converged"].get<bool>(), ov_run["fit_test"]["explains_data"].get<bool>());
  std::printf("mismatched run: exit %d, fit test: %s\n", status[1], ov_run["fit_test"]["message"].get<std::string>().c_str());
  // The truth says what it simulated.
  const auto meta = read_json(dir / "ov" / "truth" / "truth.json");
  EXPECT_DOUBLE_EQ(meta["settings"]["truth"]["overrides"]["scole"]["reflector_rx"].get<double>(), rx);
  EXPECT_DOUBLE_EQ(meta["settings"]["scole"]["reflector_rx"].get<double>(), nominal.scole.reflector_rx);
  // The bias of the mismatched run dwarfs the matched run's (chain lumping at n = 10).
  const double matched = worst_error(read_json(dir / "base" / "identify" / "identify.json"));
  const double mismatched = worst_error(read_json(dir / "ov" / "identify" / "identify.json"));
  std::printf("worst relative parameter error: matched %.3e, reflector offset +5 %% in the truth %.3e\n", matched, mismatched);
  EXPECT_LT(matched, 2e-2);
  EXPECT_GT(mismatched, 3.0 * matched);
  fs::remove_all(dir);
}

namespace {
using scoleid::io::DataTable;

const std::vector<double>& column(const DataTable& t, const std::string& name) {
  const int c = t.find(name);
  if (c < 0) throw std::runtime_error("no column " + name);
  return t.columns[static_cast<std::size_t>(c)];
}
double max_abs(const std::vector<double>& v) {
  double m = 0.0;
  for (double x : v) m = std::max(m, std::abs(x));
  return m;
}
// max |a - b| / max |b|
double relative_difference(const std::vector<double>& a, const std::vector<double>& b) {
  double d = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k) d = std::max(d, std::abs(a[k] - b[k]));
  return d / max_abs(b);
}

// A 1.5 s SCOLE truth on 6 segments: force and moment pulses at the reflector; mast-tip and
// reflector sensors along the axes, copies of them for the overrides to act on, and a pair for
// the location override (roll_moved at s = 65, roll_100 at s = 100).
std::string sensor_scenario(const std::string& overrides) {
  return R"(name: sensor-mismatch
structure: scole
scole: {actuator_stroke: 5}
inputs:
  - {name: F_x, at: reflector, kind: force, direction: x, unit: lb, signal: {type: haversine, amplitude: 10, t0: 0, width: 0.6}}
  - {name: F_y, at: reflector, kind: force, direction: y, unit: lb, signal: {type: haversine, amplitude: 10, t0: 0.1, width: 0.6}}
  - {name: M_z, at: reflector, kind: moment, direction: z, unit: lb ft, signal: {type: haversine, amplitude: 200, t0: 0, width: 0.5}}
sensors:
  - {name: roll_tip, at: mast, location: 130, direction: y, unit: ft}
  - {name: axial_tip, at: mast, location: 130, direction: z, unit: ft}
  - {name: roll_tip_tilted, at: mast, location: 130, direction: y, unit: ft}
  - {name: rot_y, at: reflector, kind: rotation, direction: y, unit: rad}
  - {name: rot_z, at: reflector, kind: rotation, direction: z, unit: rad}
  - {name: rot_y_tilted, at: reflector, kind: rotation, direction: y, unit: rad}
  - {name: roll_tip_biased, at: mast, location: 130, direction: y, unit: ft}
  - {name: roll_moved, at: mast, location: 65, direction: y, unit: ft}
  - {name: roll_100, at: mast, location: 100, direction: y, unit: ft}
simulation: {duration: 1.5, sample_interval: 0.01}
truth:
  segments: 6
)" + overrides;
}

constexpr double kBias = 2.0e-3, kDrift = -1.5e-3;  // ft, ft/s
const std::string kSensorOverrides = R"(  overrides:
    sensors:
      - {name: roll_tip_tilted, direction: [0, 0.99985, 0.01745]}
      - {name: rot_y_tilted, direction: [0, 0.99985, 0.01745]}
      - {name: roll_tip_biased, bias: 2.0e-3, drift: -1.5e-3}
      - {name: roll_moved, location: 100}
)";
}  // namespace

// The misaligned sensors read d_y y + d_z z of the aligned ones (d the normalised direction) to
// round-off, on a displacement (where z, the axial motion, is second order) and on a rotation
// (where the reflector's torsion makes the z part large).
TEST(SensorOverrides, MisalignedSensorReadsTheProjectionOntoItsTiltedAxis) {
  namespace io = scoleid::io;
  const io::Scenario sc = io::parse_scenario(sensor_scenario(kSensorOverrides), "sensor-mismatch");
  const io::Scenario ts = io::truth_scenario(sc);
  const std::vector<double> d = ts.sensors[2].direction;
  ASSERT_EQ(ts.sensors[5].direction, d);
  EXPECT_NEAR(std::hypot(d[0], d[1], d[2]), 1.0, 1e-15);
  EXPECT_EQ(sc.sensors[2].direction, (std::vector<double>{0, 1, 0}));  // the identifier's sensor
  EXPECT_NEAR(std::atan2(d[2], d[1]) * 180 / M_PI, 1.0, 1e-3);
  const auto r = scoleid::model::run_truth(sc);
  struct Pair { const char *tilted, *y, *z; };
  for (const Pair p : {Pair{"roll_tip_tilted", "roll_tip", "axial_tip"}, Pair{"rot_y_tilted", "rot_y", "rot_z"}}) {
    const auto &m = column(r.table, p.tilted), &y = column(r.table, p.y), &z = column(r.table, p.z);
    const double scale = max_abs(y) + max_abs(z);
    double worst = 0.0;
    for (std::size_t k = 0; k < m.size(); ++k) worst = std::max(worst, std::abs(m[k] - (d[1] * y[k] + d[2] * z[k])) / scale);
    std::printf("  %s: max |y_tilted - (d_y y + d_z z)| / (max|y| + max|z|) = %.2e; d_z max|z| / max|y| = %.2e, "
                "(1 - d_y) = %.2e\n",
                p.tilted, worst, d[2] * max_abs(z) / max_abs(y), 1 - d[1]);
    EXPECT_LT(worst, 1e-12) << p.tilted;
    // The tilt is visible: the aligned read-out differs from the tilted one by far more.
    EXPECT_GT(relative_difference(m, y), 1e-5) << p.tilted;
  }
  // The z part of the tilted rotation is not negligible against the tolerance.
  EXPECT_GT(d[2] * max_abs(column(r.table, "rot_z")), 1e6 * 1e-12 * max_abs(column(r.table, "rot_y")));
}

// bias and drift: the biased sensor minus the same sensor in the run without overrides is
// bias + drift·t at every sample; every other column of the two runs is identical (the
// overrides touch the read-outs only); a moved sensor reads what a sensor placed there reads.
TEST(SensorOverrides, BiasDriftAndLocationChangeTheReadOutOnly) {
  namespace io = scoleid::io;
  const io::Scenario base = io::parse_scenario(sensor_scenario(""), "sensor-base");
  const io::Scenario sc = io::parse_scenario(sensor_scenario(kSensorOverrides), "sensor-mismatch");
  const auto r0 = scoleid::model::run_truth(base);
  const auto r = scoleid::model::run_truth(sc);
  ASSERT_EQ(r.table.t, r0.table.t);
  const auto &biased = column(r.table, "roll_tip_biased"), &ideal = column(r0.table, "roll_tip_biased");
  double worst = 0.0;
  for (std::size_t k = 0; k < biased.size(); ++k) {
    const double expected = kBias + kDrift * r.table.t[k];
    worst = std::max(worst, std::abs((biased[k] - ideal[k]) - expected) / (kBias + std::abs(kDrift) * 1.5));
  }
  std::printf("  bias/drift: max |(y - y_0) - (bias + drift t)| / (bias + |drift| T) = %.2e over %zu samples "
              "(signal max %.3e ft)\n",
              worst, biased.size(), max_abs(ideal));
  EXPECT_LT(worst, 1e-12);
  EXPECT_EQ(column(r.table, "roll_tip"), column(r0.table, "roll_tip"));
  EXPECT_EQ(column(r.table, "rot_z"), column(r0.table, "rot_z"));
  // Location: the sensor at s = 65 moved to 100 reads roll_100 (of the same run and of the base run).
  const auto &moved = column(r.table, "roll_moved"), &at100 = column(r.table, "roll_100");
  const double dmoved = relative_difference(moved, at100);
  std::printf("  location 65 -> 100: max |y_moved - y_100| / max |y_100| = %.2e; before the move %.2e\n", dmoved,
              relative_difference(column(r0.table, "roll_moved"), at100));
  EXPECT_LT(dmoved, 1e-12);
  EXPECT_GT(relative_difference(column(r0.table, "roll_moved"), at100), 0.1);
  EXPECT_EQ(at100, column(r0.table, "roll_100"));
  // truth.json: the settings echo names each overridden sensor and the fields that differ.
  const nlohmann::json& ov = r.meta.settings["truth"]["overrides"];
  EXPECT_FALSE(ov.contains("scole"));
  ASSERT_EQ(ov["sensors"].size(), 4u);
  EXPECT_EQ(ov["sensors"][2], (nlohmann::json{{"name", "roll_tip_biased"}, {"bias", kBias}, {"drift", kDrift}}));
  EXPECT_EQ(ov["sensors"][3], (nlohmann::json{{"name", "roll_moved"}, {"location", 100.0}}));
  EXPECT_EQ(r.meta.settings["sensors"][7]["location"], 65.0);  // the identifier's sensor
  EXPECT_TRUE(io::has_truth_overrides(sc));
  EXPECT_FALSE(io::has_truth_overrides(base));
}

// The servo lag τ ḟ + f = g, f(0) = g(0), for a haversine g = A (1 − cos ω u)/2 on
// u = t − t0 in [0, w), ω = 2π/w: with the response of τ y' + y = cos ωu, y(0) = 0,
//   y = (cos ωu + ωτ sin ωu − e^{−u/τ}) / (1 + ω²τ²),
// f = A/2 (1 − e^{−u/τ} − y) on [0, w] and f(w) e^{−(u − w)/τ} after; for a step A at t0,
// f = A (1 − e^{−u/τ}); for a sine A sin ωt from t = 0, f = A (sin ωt − ωτ cos ωt + ωτ e^{−t/τ}) /
// (1 + ω²τ²). The precomputed history matches them to 1e-7 of A for τ from 1 ms to 1 s, between
// its nodes as at them, and beyond its end (t_end = 1 s, checked to 1.5 s).
TEST(ActuatorLag, LaggedHaversineAndStepMatchTheirClosedForms) {
  namespace io = scoleid::io;
  using scoleid::model::LaggedSignal;
  const double A = 2.5, t0 = 0.2, w = 0.5, om = 2 * M_PI / w;
  io::SignalTerm h;
  h.type = io::SignalTerm::Type::Haversine;
  h.amplitude = A;
  h.t0 = t0;
  h.width = w;
  io::SignalTerm st;
  st.type = io::SignalTerm::Type::Step;
  st.amplitude = A;
  st.t0 = 0.3;
  io::SignalTerm sn;
  sn.type = io::SignalTerm::Type::Sine;
  sn.amplitude = A;
  sn.f0 = 3.0;
  const double os = 2 * M_PI * sn.f0;
  for (double tau : {1e-3, 1e-2, 0.1, 1.0}) {
    auto haversine = [&](double t) {
      const double u = t - t0;
      if (u <= 0) return 0.0;
      auto on = [&](double x) {
        const double y = (std::cos(om * x) + om * tau * std::sin(om * x) - std::exp(-x / tau)) / (1 + om * om * tau * tau);
        return 0.5 * A * (-std::expm1(-x / tau) - y);
      };
      return u <= w ? on(u) : on(w) * std::exp(-(u - w) / tau);
    };
    auto sine = [&](double t) {
      return A * (std::sin(os * t) - os * tau * std::cos(os * t) + os * tau * std::exp(-t / tau)) / (1 + os * os * tau * tau);
    };
    const LaggedSignal fh(io::Signal({h}), tau, 1.0), fs(io::Signal({st}), tau, 1.0), fn(io::Signal({sn}), tau, 1.0);
    double eh = 0.0, es = 0.0, en = 0.0;
    for (int k = 0; k <= 15000; ++k) {
      const double t = k * 1e-4 + 0.37e-5 * (k % 7);  // on and between nodes; past t_end = 1 from 1.0
      eh = std::max(eh, std::abs(fh(t) - haversine(t)) / A);
      es = std::max(es, std::abs(fs(t) - (t >= 0.3 ? -A * std::expm1(-(t - 0.3) / tau) : 0.0)) / A);
      en = std::max(en, std::abs(fn(t) - sine(t)) / A);
    }
    std::printf("  tau %g s: max |f - f_exact| / A: haversine %.2e (%zu nodes), step %.2e (%zu), sine %.2e (%zu)\n", tau,
                eh, fh.nodes(), es, fs.nodes(), en, fn.nodes());
    EXPECT_LT(eh, 1e-7) << tau;
    EXPECT_LT(en, 1e-7) << tau;
    EXPECT_LT(es, 1e-13) << tau;
  }
  // f(0) = g(0): a command that jumps at t = 0 is not lagged.
  const LaggedSignal f0(io::Signal::step(A, 0.0), 0.1, 1.0);
  EXPECT_EQ(f0(0.0), A);
  EXPECT_EQ(f0(0.7), A);
}

namespace {
// A 1.5 s SCOLE truth driven by proof-mass actuator 1 alone (centred by its spring, 1 Hz), a
// haversine command along y from t = 0.2 s; the mast's roll displacement and velocity at the
// actuator and at the tip.
scoleid::io::Scenario lag_scenario(const std::string& scole_extra, const std::string& overrides) {
  return scoleid::io::parse_scenario(R"(name: lag
structure: scole
scole: {actuator_stroke: 5, actuator_stiffness: 8, actuator_damping: 0.3)" + scole_extra + R"(}
inputs:
  - {name: A1_y, at: actuator1, kind: force, direction: y, unit: lb, signal: {type: haversine, amplitude: 1, t0: 0.2, width: 0.4}}
sensors:
  - {name: roll_act, at: mast, location: 43.333333333333336, direction: y, unit: ft}
  - {name: vroll_act, at: mast, kind: velocity, location: 43.333333333333336, direction: y, unit: ft/s}
  - {name: roll_tip, at: mast, location: 130, direction: y, unit: ft}
  - {name: vroll_tip, at: mast, kind: velocity, location: 130, direction: y, unit: ft/s}
simulation: {duration: 1.5, sample_interval: 0.01}
truth:
  segments: 6
)" + overrides, "lag");
}
}  // namespace

// In the truth: to first order in τ the lag delays the force by τ, so y_τ − y_0 = −τ ẏ_0 (ẏ_0 the
// velocity sensor at the same station); at τ = 1e-8 the outputs are those of τ = 0 to 1e-6; at
// τ = 0.1 s they change by far more than 1e-3. The lag reads the same in the scole: section and
// in truth.overrides.scole.
TEST(ActuatorLag, TruthResponseIsDelayedToFirstOrderAndChangedByALargeLag) {
  using scoleid::model::run_truth;
  const auto r0 = run_truth(lag_scenario("", ""));
  const auto tiny = run_truth(lag_scenario("", "  overrides:\n    scole: {actuator_lag: 1.0e-8}\n"));
  const auto small = run_truth(lag_scenario("", "  overrides:\n    scole: {actuator_lag: 1.0e-5}\n"));
  const auto big = run_truth(lag_scenario(", actuator_lag: 0.1", ""));
  const auto big_ov = run_truth(lag_scenario("", "  overrides:\n    scole: {actuator_lag: 0.1}\n"));
  for (const char* s : {"roll_act", "roll_tip"}) {
    const std::string v = std::string("v") + s;
    const auto &y0 = column(r0.table, s), &ys = column(small.table, s), &v0 = column(r0.table, v);
    double first_order = 0.0;
    for (std::size_t k = 0; k < y0.size(); ++k) first_order = std::max(first_order, std::abs(ys[k] - y0[k] + 1e-5 * v0[k]));
    first_order /= 1e-5 * max_abs(v0);
    const double d_tiny = relative_difference(column(tiny.table, s), y0);
    const double d_small = relative_difference(ys, y0);
    const double d_big = relative_difference(column(big.table, s), y0);
    std::printf("  %s: max|y_tau - y_0| / max|y_0|: tau 1e-8 %.2e, 1e-5 %.2e, 0.1 %.2e; "
                "max|y_1e-5 - y_0 + 1e-5 v_0| / (1e-5 max|v_0|) = %.2e\n",
                s, d_tiny, d_small, d_big, first_order);
    EXPECT_LT(d_tiny, 1e-6) << s;
    EXPECT_LT(first_order, 1e-3) << s;
    EXPECT_GT(d_big, 1e-3) << s;
    EXPECT_EQ(column(big.table, s), column(big_ov.table, s)) << s;  // scole: or overrides: alike
  }
  // The input column is the command, lag or not (the identifier's input).
  EXPECT_EQ(column(big.table, "A1_y"), column(r0.table, "A1_y"));
  EXPECT_EQ(big_ov.meta.settings["truth"]["overrides"]["scole"], (nlohmann::json{{"actuator_lag", 0.1}}));
}

// The FE identifier has no servo lag: it refuses one in its own scole: section, with one line
// naming the field and the place a mismatch study sets it; a lag under truth.overrides does not
// reach it.
TEST(ActuatorLag, FiniteElementModelRefusesALag) {
  // The identifier's door refuses a lag outside truth.overrides: its model has no servo state.
  namespace io = scoleid::io;
  try {
    scoleid::identify::check_scenario(lag_scenario(", actuator_lag: 0.05", ""));
    FAIL() << "no error";
  } catch (const io::InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "lag: scole.actuator_lag must be 0: the finite-element model has no servo lag: set it under "
              "truth.overrides.scole to study the mismatch, got 0.05");
  }
  const io::Scenario ov = lag_scenario("", "  overrides:\n    scole: {actuator_lag: 0.05}\n");
  EXPECT_NO_THROW(scoleid::identify::check_scenario(ov));
  EXPECT_NO_THROW(scoleid::identify::make_structure(ov, 4));
  EXPECT_DOUBLE_EQ(io::truth_scenario(ov).scole.actuator_lag, 0.05);
}

TEST(SensorOverrides, AKindsOwnFieldsAreOverriddenByTheirRules) {
  // A strain gauge bonded twice as far from the neutral axis reads exactly twice the strain
  // (ε = −offset · M / EI); a relative gauge whose reference end is moved reads what a gauge placed
  // there reads. The truth records both; a value its kind's rule refuses is refused by name.
  namespace io = scoleid::io;
  const std::string head =
      "name: gauges\n"
      "beam: {length: 0.6, left: clamped, right: free, rho_A: 0.4, EI: 30}\n"
      "inputs: [{name: F, location: 0.55, signal: {type: haversine, amplitude: 2, t0: 0.001, width: 0.004}}]\n"
      "sensors:\n"
      "  - {name: eps, kind: strain, location: 0.04, offset: 0.0015}\n"
      "  - {name: rel, kind: relative_displacement, location: 0.6, reference: 0.3}\n"
      "  - {name: rel_02, kind: relative_displacement, location: 0.6, reference: 0.2}\n"
      "simulation: {duration: 0.02, sample_interval: 0.0005}\n";
  const auto truth = [&](const std::string& overrides) {
    return head + "truth:\n  overrides:\n    sensors:\n" + overrides;
  };
  const io::Scenario base = io::parse_scenario(head, "gauges");
  const io::Scenario sc = io::parse_scenario(
      truth("      - {name: eps, offset: 0.003}\n      - {name: rel, reference: 0.2}\n"), "gauges-moved");
  EXPECT_EQ(sc.sensors[0].field("offset"), 0.0015);  // the identifier's gauges are as stated
  const auto r0 = scoleid::model::run_truth(base);
  const auto r = scoleid::model::run_truth(sc);
  const auto &eps = column(r.table, "eps"), &eps0 = column(r0.table, "eps");
  ASSERT_EQ(eps.size(), eps0.size());
  for (std::size_t k = 0; k < eps.size(); ++k) EXPECT_EQ(eps[k], 2.0 * eps0[k]) << "sample " << k;
  EXPECT_GT(max_abs(eps0), 0.0);
  EXPECT_EQ(column(r.table, "rel"), column(r.table, "rel_02"));
  EXPECT_GT(relative_difference(column(r0.table, "rel"), column(r0.table, "rel_02")), 0.1);
  const nlohmann::json& ov = r.meta.settings["truth"]["overrides"]["sensors"];
  ASSERT_EQ(ov.size(), 2u);
  EXPECT_EQ(ov[0], (nlohmann::json{{"name", "eps"}, {"offset", 0.003}}));
  EXPECT_EQ(ov[1], (nlohmann::json{{"name", "rel"}, {"reference", 0.2}}));
  const auto error_of = [&](const std::string& overrides) {
    try {
      io::parse_scenario(truth(overrides), "gauges-wrong");
    } catch (const io::InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const std::string ends = error_of("      - {name: rel, reference: 0.6}\n");
  EXPECT_NE(ends.find("truth.overrides.sensors[0].reference"), std::string::npos) << ends;
  EXPECT_NE(ends.find("must differ from location"), std::string::npos) << ends;
  const std::string onto = error_of("      - {name: rel, location: 0.3}\n");
  EXPECT_NE(onto.find("truth.overrides.sensors[0].location"), std::string::npos) << onto;
  const std::string off = error_of("      - {name: rel, reference: 0.7}\n");
  EXPECT_NE(off.find("must lie on the beam"), std::string::npos) << off;
  const std::string zero = error_of("      - {name: eps, offset: 0}\n");
  EXPECT_NE(zero.find("truth.overrides.sensors[0].offset"), std::string::npos) << zero;
  EXPECT_NE(zero.find("must be nonzero"), std::string::npos) << zero;
}
