// No wrong answer called converged (docs/theory.md §7.3, §7.6, §8.1):
//  - the noise-aware misfit profile: on data that are the model's output plus white noise of the
//    stated level, the profile at the truth is zero wherever the residual is within the noise's
//    expected share and its band — and without the stated level it is the plain ratio;
//  - short noisy records (0.5 s of a pinned beam, 51 samples, noise 6 % of the signal): over 60
//    noise draws none is reported converged with an interval that misses the truth;
//  - beam-ei8 with noise 1e-4 m (seeds 1 and 7), where the plain run stops in a sawtooth minimum
//    7-19 std off: the smoothed restart reaches the minimum near the truth, every section within
//    its interval;
//  - the spectral start: the record's peak against the analytic frequency, and the start that
//    scales a uniform beam's frequencies by exactly the ratio.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include "scoleid/identify/inverse/spectral_start.h"
#include "scoleid/identify/run/identify_run.h"
#include "test_support.h"

using namespace scoleid::identify;

namespace {

std::string short_record(unsigned seed, double noise) {
  return R"(name: short-pinned
structure: beam
beam: {length: 10, left: pinned, right: pinned, rho_A: 67, EI: 23000, zeta: 0}
inputs:
  - {name: P, at: beam, kind: force, location: 5, unit: N, signal: {type: step, amplitude: 10, t0: 0}}
sensors:
  - {name: w_mid, at: beam, kind: displacement, location: 5, unit: m, noise_std: )" +
         std::to_string(noise) + R"(}
simulation: {duration: 0.5, sample_interval: 0.01, seed: )" +
         std::to_string(seed) + R"(}
identification:
  parameterization: physical
  estimate: [EI, rho_A]
  initial: {rho_A: 63, EI: 19000}
  elements: 10
)";
}

enum class Outcome { Covered, False, NotConverged };

Outcome classify(const Problem& p, const RunResult& r) {
  if (!r.converged()) return Outcome::NotConverged;
  const VectorXd truth = p.params->truth();
  for (int i = 0; i < truth.size(); ++i) {
    if (!r.ident.identifiable[static_cast<std::size_t>(i)]) continue;
    if (!(std::abs(r.estimate[i] - truth[i]) <= r.interval.half_width[i])) return Outcome::False;
  }
  return Outcome::Covered;
}

}  // namespace

TEST(NoiseAwareProfile, TheNoisesShareIsNotCountedAsPhaseLost) {
  // The model's own output plus white noise at the stated level: at the truth the residual is the
  // noise alone.
  auto c = test_support::make_case(short_record(1, 1e-4), false);
  Problem& p = *c.p;
  const VectorXd q = p.params->truth();
  const Objective::MisfitProfile with = c.obj->misfit_profile(q);
  ObjectiveOptions o = p.objective_options;
  o.noise_std.clear();
  Objective plain(p.model(), *p.params, p.signals, p.data, o);
  const Objective::MisfitProfile without = plain.misfit_profile(q);
  ASSERT_EQ(with.misfit.size(), without.misfit.size());
  int zero = 0, positive_without = 0;
  for (std::size_t i = 0; i < with.misfit.size(); ++i) {
    zero += with.misfit[i] == 0.0;
    positive_without += without.misfit[i] > 0.0;
    EXPECT_LE(with.misfit[i], without.misfit[i] + 1e-15);
  }
  std::printf("  profile points: %zu; zero with the stated noise %d, positive without %d; at the end %.3e vs %.3e\n",
              with.misfit.size(), zero, positive_without, with.misfit.back(), without.misfit.back());
  EXPECT_GE(zero, static_cast<int>(0.9 * static_cast<double>(with.misfit.size())));
  EXPECT_EQ(positive_without, static_cast<int>(without.misfit.size()));
}

TEST(FalseConvergence, ShortNoisyRecordsAreNeverCalledConvergedWhenWrong) {
  int covered = 0, wrong = 0, not_converged = 0;
  for (unsigned seed = 1; seed <= 60; ++seed) {
    auto sc = scoleid::io::parse_scenario(short_record(seed, 1e-4), "short record");
    auto [p, r] = test_support::quiet_run(sc);
    const Outcome o = classify(*p, r);
    covered += o == Outcome::Covered;
    wrong += o == Outcome::False;
    not_converged += o == Outcome::NotConverged;
    if (seed == 1 || seed == 18 || o == Outcome::False)
      std::printf("  seed %2u: EI %+.1f %%, rho_A %+.1f %%, %s\n", seed, 100 * (r.estimate[0] / 23000 - 1),
                  100 * (r.estimate[1] / 67 - 1),
                  o == Outcome::Covered ? "converged, covered" : o == Outcome::False ? "CONVERGED AND WRONG" : "not converged");
    if (seed == 1 || seed == 18) {
      EXPECT_NE(o, Outcome::False) << "seed " << seed;
    }
  }
  std::printf("  60 draws: converged and covered %d, not converged %d, converged and wrong %d\n", covered, not_converged, wrong);
  EXPECT_EQ(wrong, 0);
  EXPECT_GE(covered, 50);  // the honest answer is also the usual one
}

TEST(FalseConvergence, TheSmoothedRestartLeavesBeamEi8sSawtoothMinimum) {
  for (unsigned seed : {1u, 7u}) {
    auto sc = scoleid::io::load_scenario("beam-ei8");
    for (auto& s : sc.sensors) s.noise_std = 1e-4;
    sc.simulation.seed = seed;
    auto [p, r] = test_support::quiet_run(sc);
    const VectorXd truth = p->params->truth();
    ASSERT_TRUE(r.converged()) << "seed " << seed;
    const auto& chosen = r.attempts[static_cast<std::size_t>(r.chosen_attempt)];
    std::printf("  seed %u: chosen %s (J %.6e; first attempt %.6e); largest section error %.2f %%\n", seed,
                chosen.strategy.c_str(), chosen.cost, r.attempts[0].cost, 100 * test_support::max_rel_error(*p, r.estimate));
    EXPECT_LT(test_support::max_rel_error(*p, r.estimate), 0.03) << "seed " << seed;
    for (int i = 0; i < truth.size(); ++i) {
      if (r.ident.identifiable[static_cast<std::size_t>(i)]) {
        EXPECT_LE(std::abs(r.estimate[i] - truth[i]), r.interval.half_width[i]) << "seed " << seed << " section " << i + 1;
      }
    }
  }
}

TEST(SpectralStart, ThePeakIsTheStrongestModeAndTheStartScalesTheFrequenciesByTheRatio) {
  // Two decaying sines, 13.5 Hz the stronger: the peak within 0.5 % of it.
  std::vector<double> t(2000);
  MatrixXd z(2000, 2);
  for (int i = 0; i < 2000; ++i) {
    t[static_cast<std::size_t>(i)] = 5e-4 * i;
    const double s = t[static_cast<std::size_t>(i)];
    z(i, 0) = std::exp(-1.0 * s) * std::sin(2 * M_PI * 13.5 * s) + 0.3 * std::exp(-3.0 * s) * std::sin(2 * M_PI * 84.0 * s);
    z(i, 1) = 0.5 * z(i, 0);
  }
  const auto f = dominant_frequency(t, z);
  ASSERT_TRUE(f.has_value());
  std::printf("  peak %.4f Hz (13.5 Hz the stronger mode)\n", *f);
  EXPECT_NEAR(*f, 13.5, 0.005 * 13.5);
  // Fewer than four cycles in the record: no peak.
  std::vector<double> ts(t.begin(), t.begin() + 200);
  const auto fs = dominant_frequency(ts, z.topRows(200));
  EXPECT_TRUE(!fs || *fs >= 4.0 / (ts.back() - ts.front())) << *fs;

  // A uniform beam: every frequency ∝ √(EI/ρA), so the start EI × r, ρA / r scales them all by r.
  auto c = test_support::make_case(R"(name: spectral
structure: beam
beam: {length: 0.6, left: clamped, right: free, rho_A: 0.4, EI: 30, zeta: 0.01}
inputs: [{name: F, location: 0.55, signal: {type: haversine, amplitude: 2, t0: 0.001, width: 0.004}}]
sensors: [{name: a, kind: acceleration, location: 0.6}]
simulation: {duration: 0.5, sample_interval: 0.0005}
identification: {parameterization: physical, estimate: [EI, rho_A, zeta], initial: {EI: 45, rho_A: 0.25, zeta: 0.02}, elements: 8}
)",
                                   false);
  const Problem& p = *c.p;
  const VectorXd q0 = p.params->initial();
  c.obj->set_horizon(c.obj->data_end());
  const SpectralStart ss = spectral_start(p.model(), *p.params, q0, p.data, c.obj->predict(q0));
  ASSERT_EQ(ss.q.size(), 3) << ss.note;
  const double r = ss.ratio;
  EXPECT_NEAR(ss.data_hz / ss.model_hz, r, 0.01 * r);  // the strongest pair lined up agrees with the common ratio
  std::printf("  record %.4f Hz, model at the start %.4f Hz: start EI %.4g, rho_A %.4g, zeta %.4g\n", ss.data_hz, ss.model_hz,
              ss.q[0], ss.q[1], ss.q[2]);
  EXPECT_NEAR(ss.q[0], q0[0] * r, 1e-6 * q0[0] * r);
  EXPECT_NEAR(ss.q[1], q0[1] / r, 1e-6 * q0[1] / r);
  EXPECT_NEAR(ss.q[2], q0[2], 1e-9);
  // The record's peak is the truth's first mode: √(EI/ρA) of the truth against the start's.
  const double r_true = std::sqrt((30.0 / 0.4) / (q0[0] / q0[1]));
  EXPECT_NEAR(r, r_true, 0.01 * r_true);
}

// The record's peaks are lined up with the model's by their pattern, not strongest with strongest:
// a cantilever's frequencies stand as 1 : 6.267 : 17.55 : 34.39; a record whose third mode is the
// strongest, against a model (10 % low in frequency) whose first is, gives the common ratio.
TEST(SpectralStart, PeaksArePairedByTheirPatternNotByStrength) {
  const double ratios[] = {1.0, 6.26689, 17.5475, 34.3861};
  std::vector<SpectralPeak> data, model;
  const double f1 = 13.46, r = 1.0 / 0.905;
  const double data_power[] = {0.05, 0.2, 0.6, 0.1}, model_power[] = {0.7, 0.2, 0.08, 0.02};
  for (int k = 0; k < 4; ++k) {
    data.push_back({f1 * ratios[k], data_power[k]});
    model.push_back({f1 / r * ratios[k], model_power[k]});
  }
  const auto m = match_peaks(data, model);
  ASSERT_TRUE(m.has_value());
  std::printf("  ratio %.5f (true %.5f), %d pairs\n", m->ratio, r, m->pairs);
  EXPECT_NEAR(m->ratio, r, 1e-9 * r);
  EXPECT_EQ(m->pairs, 4);
  // Strongest with strongest would have said 236.2 / 12.18 = 19.4.
  EXPECT_NEAR(m->data_hz / m->model_hz, r, 1e-9 * r);
  // A record with one peak the model does not have (an extra 50 Hz line, the strongest) keeps the
  // same ratio: the shift that lines up the most peaks wins.
  data.push_back({50.0, 0.9});
  const auto m2 = match_peaks(data, model);
  ASSERT_TRUE(m2.has_value());
  EXPECT_NEAR(m2->ratio, r, 1e-9 * r);
  EXPECT_EQ(m2->pairs, 4);
  // No shift within a factor 10: no match.
  EXPECT_FALSE(match_peaks({{1000.0, 1.0}}, {{1.0, 1.0}}).has_value());
}

// The peaks of a record: every mode whose peak is above 10⁻³ of the strongest, within a quarter bin.
TEST(SpectralStart, SpectralPeaksFindEachDecayingSine) {
  std::vector<double> t(4000);
  MatrixXd z(4000, 1);
  const double f[] = {13.5, 84.6, 236.9};
  for (int i = 0; i < 4000; ++i) {
    const double s = t[static_cast<std::size_t>(i)] = 5e-4 * i;
    // (each still ringing at the record's middle, where the Hann window weighs most)
    z(i, 0) = std::exp(-1.0 * s) * std::sin(2 * M_PI * f[0] * s) + 0.5 * std::exp(-2.0 * s) * std::sin(2 * M_PI * f[1] * s) +
              0.3 * std::exp(-3.0 * s) * std::sin(2 * M_PI * f[2] * s);
  }
  auto peaks = spectral_peaks(t, z);
  for (const auto& pk : peaks) std::printf("  found %.3f Hz, power %.3g\n", pk.f, pk.power);
  ASSERT_GE(peaks.size(), 3u);
  std::sort(peaks.begin(), peaks.end(), [](const SpectralPeak& a, const SpectralPeak& b) { return a.f < b.f; });
  for (int k = 0; k < 3; ++k) {
    std::printf("  peak %d: %.3f Hz (sine %.1f Hz)\n", k + 1, peaks[static_cast<std::size_t>(k)].f, f[k]);
    EXPECT_NEAR(peaks[static_cast<std::size_t>(k)].f, f[k], 0.25) << k;  // a quarter of the bin 1/T = 0.5 Hz
  }
}
