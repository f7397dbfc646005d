// run_truth (truth.csv / truth.json contents): Gaussian sensor noise with the scenario's std and
// seed on outputs only, reproducible for a seed; columns and metadata copied from the scenario;
// the "auto" integrator choice follows the chain's spectrum.
// The acquisition's anti-alias filter (truth.anti_alias_hz) passes its band and stops what would fold.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <string>

#include "scoleid/io/band_filter.h"
#include "scoleid/io/error.h"
#include "scoleid/io/scenario.h"
#include "scoleid/model/truth_run.h"
#include "test_support.h"

using namespace scoleid;
using namespace scoleid::model;

namespace {

io::Scenario beam(double noise, unsigned seed) {
  const std::string yaml = R"(name: noise-beam
structure: beam
beam: {length: 10, left: clamped, right: free, rho_A: 67, EI: [23000, 30000], zeta: 0}
inputs:
  - {name: P, kind: force, location: 10, unit: N, signal: {type: haversine, amplitude: 10, t0: 0.1, width: 0.5}}
  - {name: M, kind: moment, location: 5, unit: N m, signal: {type: sine, amplitude: 3, frequency: 0.7}}
sensors:
  - {name: w_tip, location: 10, unit: m, noise_std: )" + std::to_string(noise) + R"(}
  - {name: slope_mid, kind: rotation, location: 5, unit: rad}
simulation: {duration: 2, sample_interval: 0.002, seed: )" + std::to_string(seed) + R"(}
truth: {segments: 10, integrator: rk-merson, accuracy: 1e-8}
)";
  return io::parse_scenario(yaml, "test");
}

}  // namespace

TEST(TruthRun, NoiseIsGaussianWithTheScenarioStdOnOutputsOnlyAndSeeded) {
  const double sd = 1e-4;
  const TruthResult clean = run_truth(beam(0.0, 7));
  const TruthResult a = run_truth(beam(sd, 7));
  const TruthResult b = run_truth(beam(sd, 7));
  const TruthResult c = run_truth(beam(sd, 8));
  ASSERT_EQ(a.table.names, (std::vector<std::string>{"P", "M", "w_tip", "slope_mid"}));
  const std::size_t N = a.table.t.size();
  ASSERT_EQ(N, 1001u);
  double mean = 0, var = 0;
  for (std::size_t i = 0; i < N; ++i) {
    EXPECT_EQ(a.table.columns[0][i], clean.table.columns[0][i]);
    EXPECT_EQ(a.table.columns[1][i], clean.table.columns[1][i]);
    EXPECT_EQ(a.table.columns[3][i], clean.table.columns[3][i]);   // noise_std 0: untouched
    EXPECT_EQ(a.table.columns[2][i], b.table.columns[2][i]);        // same seed, same data
    const double e = a.table.columns[2][i] - clean.table.columns[2][i];
    mean += e / N;
    var += e * e / N;
  }
  var -= mean * mean;
  // N = 1001 samples: the sample std is within 3 sigma = 3/sqrt(2N) = 6.7 % of sd, the mean
  // within 3 sd/sqrt(N).
  EXPECT_NEAR(std::sqrt(var) / sd, 1.0, 0.067);
  EXPECT_LT(std::abs(mean), 3 * sd / std::sqrt(double(N)));
  EXPECT_NE(a.table.columns[2][100], c.table.columns[2][100]);
  // Inputs are the signals at the sample times.
  EXPECT_DOUBLE_EQ(a.table.columns[1][250], 3 * std::sin(2 * M_PI * 0.7 * a.table.t[250]));
}

TEST(TruthRun, MetadataCopiesTheScenario) {
  const TruthResult r = run_truth(beam(1e-4, 3));
  const auto& m = r.meta;
  ASSERT_EQ(m.columns.size(), 4u);
  EXPECT_EQ(m.columns[1].kind, "input");
  EXPECT_EQ(m.columns[1].quantity, "moment");
  EXPECT_EQ(m.columns[1].unit, "N m");
  EXPECT_EQ(m.columns[2].kind, "output");
  EXPECT_EQ(m.columns[2].noise_std, 1e-4);
  EXPECT_EQ(m.columns[3].quantity, "rotation");
  EXPECT_EQ(m.columns[3].location, 5.0);
  EXPECT_EQ(m.true_parameters.at("EI_1"), 23000.0);
  EXPECT_EQ(m.true_parameters.at("EI_2"), 30000.0);
  EXPECT_EQ(m.true_parameters.count("EI"), 0u);
  EXPECT_EQ(m.generator.at("segments"), 10);
  EXPECT_EQ(m.generator.at("seed"), 3);
  EXPECT_EQ(m.settings.at("beam").at("EI").size(), 2u);
}

// Kelvin–Voigt damping (paper-beam-2, c_kv = 2·0.1·√(ρA·EI)) overdamps the chain's top modes: "auto" takes
// BDF. SCOLE's zeta leaves them ringing: from rest (every truth run), Gauss–Legendre, also under the
// slew's bang-bang moment; started deformed or moving, the trapezoidal rule. Simple supports are
// constraints, which neither implicit rule projects onto: explicit RK (paper-beam-1, -3).
TEST(TruthRun, AutoIntegratorFollowsTheSpectrum) {
  for (const auto& [name, expect] : std::vector<std::pair<std::string, std::string>>{
           {"paper-beam-1", "rk-merson"}, {"paper-beam-2", "cpodes"}, {"paper-beam-3", "rk-merson"},
           {"paper-scole-1", "gauss-legendre"}, {"scole-slew", "gauss-legendre"}}) {
    const io::Scenario sc = io::load_scenario(name);
    const auto st = prepare_structure(sc, 20);
    EXPECT_EQ(choose_integrator(st->system(), st->system().getDefaultState()), expect) << name;
  }
  const auto st = prepare_structure(io::load_scenario("paper-scole-1"), 10);
  SimTK::State deformed = st->system().getDefaultState();
  test::deform(*st, deformed, 0.002);
  EXPECT_EQ(choose_integrator(st->system(), deformed), "trapezoidal");
  SimTK::State moving = st->system().getDefaultState();
  moving.updU()[0] = 1e-3;
  EXPECT_EQ(choose_integrator(st->system(), moving), "trapezoidal");
}

TEST(TruthRun, TheAntiAliasFilterPassesTheBandAndStopsWhatWouldFoldIntoIt) {
  // truth.anti_alias_hz: 200 at 1 kHz output. A moment input of 50 Hz + 900 Hz, both of amplitude
  // 1: unfiltered, the 900 Hz term samples as a 100 Hz one of amplitude 1. Recorded after the
  // filter: the 50 Hz term with the filter's own gain and phase (io::BandFilter at the 8-times denser
  // rate), the 900 Hz one below 1e-4; the output grid k dt; the noise, added after, at its stated
  // level.
  auto yaml = [](double noise) {
    return R"(name: aa-beam
structure: beam
beam: {length: 10, left: clamped, right: free, rho_A: 67, EI: 23000, zeta: 0.01}
inputs:
  - {name: M, kind: moment, location: 5, unit: N m,
     signal: [{type: sine, amplitude: 1, frequency: 50}, {type: sine, amplitude: 1, frequency: 900}]}
sensors:
  - {name: w_tip, location: 10, unit: m, noise_std: )" + std::to_string(noise) + R"(}
simulation: {duration: 1, sample_interval: 0.001, seed: 4}
truth: {segments: 6, integrator: rk-merson, accuracy: 1e-6, anti_alias_hz: 200}
)";
  };
  const TruthResult r = run_truth(io::parse_scenario(yaml(0.0), "test"));
  ASSERT_EQ(r.table.t.size(), 1001u);
  EXPECT_NEAR(r.table.t[500], 0.5, 1e-12);
  const std::complex<double> G = io::BandFilter(0.0, 200.0, 0.001 / kAntiAliasOversample).response(50.0);
  EXPECT_NEAR(std::abs(G), 1.0, 1e-3);
  double worst = 0.0;
  for (std::size_t k = 300; k < r.table.t.size(); ++k) {  // the filter's transient gone (its poles decay in ~10 ms)
    const double t = r.table.t[k];
    worst = std::max(worst, std::abs(r.table.columns[0][k] - std::abs(G) * std::sin(2 * M_PI * 50 * t + std::arg(G))));
  }
  EXPECT_LT(worst, 1e-4);
  EXPECT_EQ(r.meta.generator.at("anti_alias_hz"), 200.0);
  // The noise is white at the stated level after the filter.
  const double sd = 1e-5;
  const TruthResult n = run_truth(io::parse_scenario(yaml(sd), "test"));
  double var = 0.0;
  for (std::size_t k = 0; k < n.table.t.size(); ++k) var += std::pow(n.table.columns[1][k] - r.table.columns[1][k], 2) / 1001;
  EXPECT_NEAR(std::sqrt(var) / sd, 1.0, 0.067);
}

TEST(TruthRun, ASineTheRecordWouldAliasIsRefusedBeforeAnyStep) {
  // paper-beam-2 driven at 1e20 Hz (the record samples at 100 Hz): refused at once, naming the
  // input's frequency; below the Nyquist frequency it runs, the implicit methods' step following the sine.
  io::Scenario sc = io::load_scenario("paper-beam-2");
  sc.simulation.duration = 0.5;
  sc.truth.segments = 6;
  io::SignalTerm sine;
  sine.type = io::SignalTerm::Type::Sine;
  sine.amplitude = 1.0;
  sine.f0 = 1e20;
  sc.inputs[0].signal = io::Signal({sine});
  try {
    run_truth(sc);
    ADD_FAILURE() << "accepted";
  } catch (const io::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("inputs[0].signal.frequency"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("1e+20"), std::string::npos) << e.what();
  }
  sine.f0 = 40.0;
  sc.inputs[0].signal = io::Signal({sine});
  sc.truth.integrator = "trapezoidal";
  const TruthResult r = run_truth(sc);
  EXPECT_EQ(r.table.t.size(), 51u);
  EXPECT_LE(r.summary.max_step, std::cbrt(12.0 * sc.truth.accuracy) / (2 * M_PI * 40.0) * (1 + 1e-12));
  sc.truth.integrator = "gauss-legendre";
  const TruthResult g = run_truth(sc);
  EXPECT_EQ(g.table.t.size(), 51u);
  EXPECT_LE(g.summary.max_step, std::pow(720.0 * sc.truth.accuracy, 0.2) / (2 * M_PI * 40.0) * (1 + 1e-12));
}

TEST(TruthRun, ARecordOfNothingIsRefusedNamingWhatIsMissing) {
  // No sensors: nothing is recorded; no input with a signal: the structure stays at rest.
  const std::string base = "name: v\nbeam: {length: 10, left: pinned, right: pinned, rho_A: 67, EI: 23000}\n";
  const std::string load = "inputs: [{name: P, location: 5, signal: {type: step, amplitude: 1}}]\n";
  const std::string sensor = "sensors: [{name: w, location: 5}]\n";
  auto error_of = [](const std::string& yaml) {
    try {
      run_truth(io::parse_scenario(yaml, "s.yaml"));
    } catch (const io::InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error_of(base + load + "sensors: []\n").find("sensors must list at least one sensor"), std::string::npos);
  EXPECT_NE(error_of(base + "inputs: []\n" + sensor).find("inputs must give at least one input a signal"), std::string::npos);
  EXPECT_NE(error_of(base + sensor).find("inputs"), std::string::npos);
}

TEST(TruthRun, NoiseThatWouldDrownTheRecordIsRefused) {
  // The midspan of a pinned beam under a 1 N step moves ~1e-3 m (static PL³/48EI = 9e-4 m): noise
  // of 1e20 m, and of 10 m (1e4 times the signal), is refused naming the field; 1e-5 m is written.
  auto with_noise = [](const std::string& sd) {
    return io::parse_scenario("name: v\nbeam: {length: 10, left: pinned, right: pinned, rho_A: 67, EI: 23000}\n"
                              "inputs: [{name: P, location: 5, signal: {type: step, amplitude: 1}}]\n"
                              "sensors: [{name: w, location: 5, noise_std: " + sd + "}]\n"
                              "simulation: {duration: 2, sample_interval: 0.01}\ntruth: {segments: 6}\n",
                              "s.yaml");
  };
  for (const char* sd : {"1e20", "10"}) {
    try {
      run_truth(with_noise(sd));
      ADD_FAILURE() << sd << " accepted";
    } catch (const io::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("sensors[0].noise_std"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("nothing but noise"), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(run_truth(with_noise("1e-5")).table.t.size(), 201u);
}

// A tap rings the modes up to about twice the inverse of the pulse's width, and the fixed-step
// methods' step follows them (docs/theory.md §9.5): a 6 ms haversine on a 0.5 m aluminium strip
// (modes 9.8, 61, 172, 337 Hz), accelerometers sampled at 1 kHz. With the step the fundamental
// alone allows (about the 1 ms sample) the third and fourth modes sat at omega h = 1.1 and 2.1,
// and the record was 5 % of its peak off. Against RK-Merson at 1e-10 (error-controlled steps that
// follow every mode of the chain), the default Gauss-Legendre record is now 3.6e-4 of its peak
// off (the modes above the sample rate, not followed, and the chain's top modes).
TEST(TruthRun, ATapsRecordFollowsTheModesThePulseRings) {
  const io::Scenario tap = io::parse_scenario(R"(name: tap-strip
structure: beam
beam: {length: 0.5, left: clamped, right: free, EI: 3.88, rho_A: 0.2025, zeta: 0.004}
inputs:
  - {name: hammer, kind: force, location: 0.45, unit: N, signal: {type: haversine, amplitude: 10, t0: 0.01, width: 0.006}}
sensors:
  - {name: acc_mid, kind: acceleration, location: 0.25, unit: m/s^2}
  - {name: acc_tip, kind: acceleration, location: 0.5, unit: m/s^2}
simulation: {duration: 0.5, sample_interval: 0.001}
truth: {segments: 40}
)", "test");
  const TruthResult a = run_truth(tap);
  TruthOptions reference;
  reference.integrator = "rk-merson";
  reference.accuracy = 1e-10;
  const TruthResult b = run_truth(tap, reference);
  ASSERT_EQ(a.summary.integrator, "gauss-legendre");
  std::printf("gauss-legendre step %.3g s\n", a.summary.max_step);
  ASSERT_EQ(a.table.t.size(), b.table.t.size());
  for (std::size_t c = 1; c < 3; ++c) {
    double peak = 0.0, diff = 0.0;
    for (std::size_t i = 0; i < a.table.t.size(); ++i) {
      peak = std::max(peak, std::abs(b.table.columns[c][i]));
      diff = std::max(diff, std::abs(a.table.columns[c][i] - b.table.columns[c][i]));
    }
    std::printf("%s: peak %.4g m/s^2, largest difference %.3g of it\n", a.table.names[c].c_str(), peak, diff / peak);
    ASSERT_GT(peak, 0.0);
    EXPECT_LT(diff / peak, 1e-3) << a.table.names[c];
  }
}

// A load that starts after a quiet stretch, at a sample time: Simbody's variable-step methods keep
// the long steps of the structure at rest unless restarted at the load's breakpoint, and stepped
// over it (a frame's record read F/m at the hit and nothing after). The record of a hit at
// t0 = 5 samples is that of the hit at 0, shifted by 5 samples.
TEST(TruthRun, ALoadStartingOnASampleAfterRestIsFollowed) {
  const auto frame = [](const std::string& t0) {
    return io::parse_scenario(R"(name: late-hit
structure: frame
frame: {heights: [0.3, 0.3], EI: 3.3, floor_mass: 1, tau: 2.0e-4}
inputs:
  - {name: hammer, at: frame, kind: force, location: 0.6, unit: N, signal: {type: haversine, amplitude: 20, t0: )" + t0 + R"(, width: 0.01}}
sensors:
  - {name: acc2, at: frame, kind: acceleration, location: 0.6, unit: m/s^2}
  - {name: w1, at: frame, kind: displacement, location: 0.3, unit: m}
simulation: {duration: 0.6, sample_interval: 0.002}
truth: {segments: 16, integrator: cpodes}
)", "test");
  };
  const TruthResult now = run_truth(frame("0"));
  const TruthResult later = run_truth(frame("0.01"));
  const std::size_t shift = 5, n = now.table.t.size();
  for (std::size_t c = 1; c < 3; ++c) {
    double peak = 0.0, diff = 0.0;
    for (std::size_t i = 0; i + shift < n; ++i) {
      peak = std::max(peak, std::abs(now.table.columns[c][i]));
      diff = std::max(diff, std::abs(later.table.columns[c][i + shift] - now.table.columns[c][i]));
    }
    std::printf("%s: peak %.4g, largest difference of the shifted records %.3g of it (%ld steps)\n", now.table.names[c].c_str(),
                peak, diff / peak, static_cast<long>(later.summary.steps_taken));
    ASSERT_GT(peak, 0.0);
    EXPECT_LT(diff / peak, 1e-3) << now.table.names[c];
  }
}
