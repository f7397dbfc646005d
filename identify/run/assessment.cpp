#include "scoleid/identify/run/assessment.h"
#include "scoleid/identify/door/scenario_door.h"
#include "scoleid/identify/point_failure.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <cstdio>
#include <optional>
#include <stdexcept>

#include "scoleid/identify/inverse/tied_parameterization.h"

#include "scoleid/io/error.h"
#include "scoleid/io/interrupt.h"
#include "scoleid/io/scenario_fields.h"

namespace scoleid::identify {

std::vector<ConsiderTerm> declared_consider_terms(const io::Scenario& sc, int P, const VectorXd& y0,
                                                  const std::function<VectorXd(const io::Scenario&)>& outputs,
                                                  const std::function<VectorXd(const VectorXd&)>& shift) {
  std::vector<ConsiderTerm> terms;
  for (const auto& u : sc.identification.uncertain) {
    ConsiderTerm t;
    t.field = u.field;
    io::Scenario hi = sc, lo = sc;
    VectorXd d;
    if (u.is_switch) {
      *io::bool_field(hi, u.field) = u.alternative;
      t.value = *io::bool_field(lo, u.field) ? 1.0 : 0.0;
      t.delta = 1.0;
      d = outputs(hi) - y0;
    } else {
      double* vh = io::numeric_field(hi, u.field);
      double* vl = io::numeric_field(lo, u.field);
      t.value = *vh;
      t.delta = u.tolerance;
      *vh += u.tolerance;
      *vl -= u.tolerance;
      // Central where both sides are valid scenarios; one-sided at the edge of the valid range (a
      // sensor at the tip of the mast cannot move beyond it); the door refused a tolerance with
      // neither (check_scenario).
      const UncertainSides sides = uncertain_sides(sc, u);
      if (sides.high && sides.low) d = 0.5 * (outputs(hi) - outputs(lo));
      else if (sides.high) d = outputs(hi) - y0;
      else if (sides.low) d = y0 - outputs(lo);
      else throw std::logic_error("consider_terms: '" + u.field + "' has no valid side (identify::check_scenario refuses it)");
    }
    // Found only at q̂, after the fit: a quantity the outputs do not depend on has no consider term
    // (0, said), one whose move leaves no finite response no interval (NaN, said). The door refused
    // an estimated one (io::validate_scenario).
    const std::string moved = "identification.uncertain." + u.field + " (" +
                              (u.is_switch ? std::string(u.alternative ? "true" : "false") : io::format_value(u.tolerance)) + ")";
    if (!d.allFinite()) {
      t.shift = VectorXd::Constant(P, std::nan(""));
      t.note = moved + " makes the model's response non-finite: no consider term, no interval";
    } else if (!(d.squaredNorm() > 0)) {
      t.shift = VectorXd::Zero(P);
      t.note = moved + " does not change the model's outputs at the estimate: its consider term is 0";
    } else {
      t.shift = shift(d);
    }
    terms.push_back(t);
  }
  return terms;
}

namespace {

// Consider terms (interval.h): for each declared tolerance, the bias of the least-squares
// estimate when the structure's value is θ + Δθ and the model's θ: F⁻¹ Gᵀ W G_θ Δθ, with G_θ Δθ
// the central difference of the model's outputs at q̂ (or the difference to the alternative model
// form), over the parameters the Fisher test kept. A quantity the outputs do not depend on at q̂
// (an estimated one: the parameters overwrite it) is refused.
// Y0 and G: the model's outputs and their sensitivities at q (the Fisher step's). `discretisation`:
// the fit test's estimate d of the identifier's discretisation error at q (empty: none).
std::vector<ConsiderTerm> consider_terms(const Problem& p, const Identifiability& id, const VectorXd& q, const MatrixXd& Y0,
                                         const MatrixXd& G, const MatrixXd& discretisation) {
  std::vector<ConsiderTerm> terms;
  const auto& uncertain = p.scenario.identification.uncertain;
  if (uncertain.empty() && discretisation.size() == 0) return terms;
  const int P = static_cast<int>(q.size()), ns = static_cast<int>(Y0.cols());
  std::vector<int> keep;
  for (int i = 0; i < P; ++i)
    if (std::isfinite(id.std[i])) keep.push_back(i);
  const auto K = static_cast<Eigen::Index>(keep.size());
  MatrixXd Gk(G.rows(), K);
  for (Eigen::Index a = 0; a < K; ++a) Gk.col(a) = G.col(keep[static_cast<std::size_t>(a)]);
  VectorXd w(G.rows());
  for (Eigen::Index r = 0; r < G.rows(); ++r) {
    const double sd = id.noise_std[static_cast<std::size_t>(r % ns)];
    w[r] = 1.0 / (sd * sd);
  }
  const MatrixXd F = Gk.transpose() * w.asDiagonal() * Gk;
  const Eigen::LDLT<MatrixXd> ldlt(F);
  auto flat = [&](const MatrixXd& Y) {  // row i*ns + k, as G
    VectorXd v(Y.size());
    for (Eigen::Index i = 0; i < Y.rows(); ++i)
      for (Eigen::Index k = 0; k < Y.cols(); ++k) v[i * ns + k] = Y(i, k);
    return v;
  };
  // The model's outputs at q̂ with the scenario changed (the same data, inputs and time step).
  auto outputs = [&](const io::Scenario& sc) {
    const auto st = make_structure(sc, sc.identification.elements);
    const auto params = st->parameterize(sc);
    Objective o(st->model(), *params, p.signals, p.data, p.objective_options);
    return flat(o.predict(q));
  };
  // The identifier's own discretisation (docs/theory.md §8.2): the refined model's outputs differ
  // from the identifier's by d at q̂, and the least-squares fit absorbs the part of d the
  // parameters can mimic — a bias the residual does not show. Taken at 2d, as the fit test's
  // allowance (the refined model's own error and the fit's redistribution of it).
  if (discretisation.rows() == Y0.rows() && discretisation.cols() == Y0.cols() && discretisation.allFinite() && K > 0) {
    ConsiderTerm t;
    t.field = "discretisation";
    t.value = static_cast<double>(p.structure->elements());
    t.delta = 0.0;
    const VectorXd d = 2.0 * flat(discretisation);
    const VectorXd sk = ldlt.solve(Gk.transpose() * (w.asDiagonal() * d));
    t.shift = VectorXd::Zero(P);
    for (Eigen::Index a = 0; a < K; ++a) t.shift[keep[static_cast<std::size_t>(a)]] = sk[a];
    if (t.shift.allFinite()) terms.push_back(t);
  }
  const auto shift = [&](const VectorXd& d) {
    const VectorXd sk = ldlt.solve(Gk.transpose() * (w.asDiagonal() * d));
    VectorXd out = VectorXd::Zero(P);
    for (Eigen::Index a = 0; a < K; ++a) out[keep[static_cast<std::size_t>(a)]] = sk[a];
    return out;
  };
  for (auto& t : declared_consider_terms(p.scenario, P, flat(Y0), outputs, shift)) terms.push_back(std::move(t));
  return terms;
}

// χ² = Σ r²/σ² of outputs Y against the data, with the Fisher step's noise levels; with a band
// (band_filter.h) times the noise gain g, since only about g of the filtered values are independent
// (the likelihood-ratio bounds below are for independent values).
double chi_square(const Problem& p, const RunResult& r, const MatrixXd& Y) {
  double c = 0.0;
  for (Eigen::Index i = 0; i < Y.rows(); ++i)
    for (Eigen::Index k = 0; k < Y.cols(); ++k) {
      const double sd = static_cast<std::size_t>(k) < r.ident.noise_std.size() ? r.ident.noise_std[static_cast<std::size_t>(k)] : 0.0;
      if (!(sd > 0.0)) continue;
      c += std::pow(Y(i, k) - p.data.z(i, k), 2) / (sd * sd);
    }
  return p.band_gain * c;
}

// The other-minimum test (docs/theory.md §8.1): every other attempt that converged and explains the
// data ended at a point the Fisher matrix of the estimate cannot see. If its χ² is within 4 of the
// estimate's (the likelihood-ratio bound of one degree of freedom at 95 %, as for the mirror), the
// data cannot tell the two apart, and every parameter whose two values lie more than 2 std apart
// is flagged. One state solve per such attempt.
void flag_other_minima(const Problem& p, Objective& obj, RunResult& r, const MatrixXd& Y) {
  if (r.ident.identifiable.empty()) return;
  double c0 = -1.0;
  for (std::size_t a = 0; a < r.attempts.size(); ++a) {
    const auto& at = r.attempts[a];
    if (static_cast<int>(a) == r.chosen_attempt || !at.optimizer_converged || !at.explains_data ||
        at.estimate.size() != r.estimate.size() || !at.estimate.allFinite())
      continue;
    std::vector<int> differ;
    for (Eigen::Index i = 0; i < r.estimate.size(); ++i)
      if (r.ident.identifiable[static_cast<std::size_t>(i)] && std::abs(at.estimate[i] - r.estimate[i]) > 2.0 * r.ident.std[i])
        differ.push_back(static_cast<int>(i));
    if (differ.empty()) continue;
    MatrixXd Ya;
    try {
      Ya = obj.predict(at.estimate);
    } catch (const std::exception& e) {
      if (!point_failure(e)) throw;
      continue;
    }
    if (c0 < 0) c0 = chi_square(p, r, Y);
    const double d = chi_square(p, r, Ya) - c0;
    r.ident.other_minimum_chi2_difference = std::isfinite(r.ident.other_minimum_chi2_difference)
                                                ? std::min(r.ident.other_minimum_chi2_difference, d)
                                                : d;
    if (!(d < 4.0)) continue;
    for (int i : differ) {
      const auto u = static_cast<std::size_t>(i);
      r.ident.identifiable[u] = false;
      char buf[300];
      std::snprintf(buf, sizeof buf,
                    "the %s start ends at %.6g instead of %.6g and fits the data as well (chi-square difference %.3g, below "
                    "4): the data cannot tell the two apart",
                    at.strategy.c_str(), at.estimate[i], r.estimate[i], d);
      r.ident.reason[u] = buf;
    }
  }
}

// The mirror test (docs/theory.md §8.1): the Fisher matrix sees only the estimate's neighbourhood,
// so a second profile that explains the data as well is invisible to it. A beam's sections have one
// such candidate by construction — the profile reversed end for end, which a symmetric support,
// load and sensor layout cannot tell from the original. Each family of sections X_1 … X_N is
// reversed (the other parameters kept) and the model's χ² there compared with the estimate's,
// with the same noise levels as the Fisher step: if the difference is below 4 (the
// likelihood-ratio bound of one degree of freedom at 95 %, rounded) the data cannot tell the two
// profiles apart, and every section whose mirrored value lies more than 2 std from its estimate is
// flagged. One state solve; none when the estimate is its own mirror within 2 std.
void flag_mirror_ambiguity(const Problem& p, Objective& obj, RunResult& r, const MatrixXd& Y) {
  const auto families = section_families(r.names);
  if (families.empty() || r.ident.identifiable.empty()) return;
  VectorXd qm = r.estimate;
  for (const auto& f : families)
    for (std::size_t j = 0; j < f.size(); ++j) qm[f[j]] = r.estimate[f[f.size() - 1 - j]];
  std::vector<int> differ;
  for (const auto& f : families)
    for (int i : f) {
      const auto u = static_cast<std::size_t>(i);
      if (!r.ident.identifiable[u]) continue;
      if (std::abs(qm[i] - r.estimate[i]) > 2.0 * r.ident.std[i]) differ.push_back(i);
    }
  if (differ.empty()) return;
  MatrixXd Ym;
  try {
    Ym = obj.predict(qm);
  } catch (const std::exception& e) {
    if (!point_failure(e)) throw;
    return;  // the mirrored profile cannot be solved: no second candidate
  }
  const double c0 = chi_square(p, r, Y), c1 = chi_square(p, r, Ym);
  r.ident.mirror_chi2_difference = c1 - c0;
  if (!(c1 - c0 < 4.0)) return;
  for (int i : differ) {
    const auto u = static_cast<std::size_t>(i);
    r.ident.identifiable[u] = false;
    char buf[260];
    if (c1 - c0 > -4.0)
      std::snprintf(buf, sizeof buf,
                    "the profile reversed end for end (this section %.6g instead of %.6g) fits the data as well (chi-square "
                    "difference %.3g, below 4): the data cannot tell the two apart",
                    qm[i], r.estimate[i], c1 - c0);
    else  // the mirror is the better fit: the estimate is not the best one
      std::snprintf(buf, sizeof buf,
                    "the profile reversed end for end (this section %.6g instead of %.6g) fits the data better (chi-square "
                    "lower by %.3g): the estimate is not the best fit",
                    qm[i], r.estimate[i], c0 - c1);
    r.ident.reason[u] = buf;
  }
}
// The record's own modes (record_modes.h) in the fitted band, else below the data's Nyquist
// frequency; none without stated noise levels (the significance of a miss rests on them).
RecordModes own_modes(const Problem& p, Objective& obj, const RunResult& r, const MatrixXd& Y, double information_scale,
                      bool stated_noise) {
  const Measurements& data = obj.data();
  if (!stated_noise || data.t.size() < 3 || static_cast<Eigen::Index>(r.ident.std.size()) != r.estimate.size()) return {};
  RecordModesOptions o;
  o.information_scale = information_scale;
  o.f_hi_hz = 0.5 * static_cast<double>(data.t.size() - 1) / (data.t.back() - data.t.front());
  if (const auto& band = p.scenario.identification.band; band.size() == 2 && band[1] > 0) {
    o.f_lo_hz = band[0];
    o.f_hi_hz = std::min(o.f_hi_hz, band[1]);
  }
  std::vector<bool> kept;
  for (double sd : r.ident.std) kept.push_back(std::isfinite(sd));
  try {
    return record_modes(obj, p.model(), *p.params, r.estimate, Y, r.ident.noise_std, kept, o);
  } catch (const std::exception& e) {
    if (!point_failure(e)) throw;
    return {};  // the model at the estimate cannot be stepped with the modes freed
  }
}
}  // namespace

IntervalInputs assessment_refits(const Problem& p, Objective& obj, const OptimizerOptions& oo, const VectorXd& estimate,
                                 int sweep_threads) {
  IntervalInputs ii;
  ii.estimate = estimate;
  if (const Measurements half_data = first_half(p.data); half_data.t.size() >= 2) {
    ObjectiveOptions o = p.objective_options;
    if (sweep_threads > 0) o.sweep_threads = sweep_threads;
    Objective half(p.model(), *p.params, p.signals, half_data, o);
    OptimizerOptions oh = oo;
    oh.continuation = false;
    const OptimizerSummary s = minimize(half, estimate, oh, [&](const IterationRecord&) { io::check_interrupt(); });
    ii.half_record_estimate = s.q;
    ii.half_record_converged = s.converged();
  }
  if (oo.smoothness_weight > 0.0) {
    OptimizerOptions os = oo;
    os.smoothness_weight = oo.smoothness_weight / 10.0;
    os.continuation = false;
    const OptimizerSummary s = minimize(obj, estimate, os, [&](const IterationRecord&) { io::check_interrupt(); });
    ii.smoothing_estimate = s.q;
    ii.smoothing_converged = s.converged();
  }
  return ii;
}

FisherInformation band_information(const Problem& p, FisherInformation fi) {
  if (!(p.band_gain < 1.0) || !fi.stated_noise) return fi;
  // Formed with the filtered noise level σ√g and the filtered sensitivities, F counts every sample
  // as independent: the band's information is g F (band_filter.h). Of the N values about g N are
  // independent: χ²'s band for the noise is N ± 2√(2N/g).
  // The systematic share is in the same units: χ² over N correlated values counts each independent
  // one 1/g times, so its share is scaled by g too (resolution = std·√systematic stays the change
  // of q whose output effect equals the residual beyond the noise).
  fi.F *= p.band_gain;
  const double Nd = static_cast<double>(fi.data_values);
  fi.systematic = p.band_gain * std::max(0.0, fi.chi2 - Nd - 2.0 * std::sqrt(2.0 * Nd / p.band_gain));
  return fi;
}

std::vector<io::SensorSpec> sensors_with_noise(const Problem& p) {
  std::vector<io::SensorSpec> sensors = p.scenario.sensors;
  for (std::size_t j = 0; j < sensors.size() && j < p.noise_std.size(); ++j) sensors[j].noise_std = p.noise_std[j];
  return sensors;
}

std::string noise_origin(const Problem& p, const std::string& fisher_source) {
  if (fisher_source != "scenario") return fisher_source;
  std::vector<std::string> origins;  // the distinct origins, in sensor order
  for (const auto& o : p.noise_origin)
    if (std::find(origins.begin(), origins.end(), o) == origins.end()) origins.push_back(o);
  std::string origin;
  for (const auto& o : origins) origin += (origin.empty() ? "" : " and ") + o;
  return origin;
}

void assess_estimate(const Problem& p, Objective& obj, const OptimizerOptions& oo, RunResult& r,
                     const IntervalInputs* made_already) {
  const auto ti = std::chrono::steady_clock::now();
  // The model's outputs and their sensitivities at q̂, kept for the mirror test and the interval
  // (the outputs are the fit test's, when it kept them).
  const MatrixXd Y = r.predicted.size() > 0 ? r.predicted : obj.predict(r.estimate);
  const MatrixXd G = obj.output_sensitivities(r.estimate);
  const FisherInformation fi = fisher_information(obj.data(), Y, G, sensors_with_noise(p));
  const bool band_scaled = p.band_gain < 1.0 && fi.stated_noise;
  r.ident = identifiability_from(band_information(p, fi), r.estimate, &p.params->names());
  flag_mirror_ambiguity(p, obj, r, Y);
  flag_other_minima(p, obj, r, Y);
  r.ident.noise_source = noise_origin(p, r.ident.noise_source);
  IntervalInputs ii = made_already && made_already->estimate.size() == r.estimate.size() &&
                             (made_already->estimate.array() == r.estimate.array()).all()
                         ? *made_already
                         : assessment_refits(p, obj, oo, r.estimate);
  if (ii.half_record_estimate.size() != 0) {
    r.half_record_estimate = ii.half_record_estimate;
    r.half_record_converged = ii.half_record_converged;
  }
  ii.consider = consider_terms(p, r.ident, r.estimate, Y, G, r.fit.discretisation);
  r.interval = uncertainty_interval(r.ident, ii);
  flag_wide_intervals(r);
  r.record_modes = own_modes(p, obj, r, Y, band_scaled ? p.band_gain : 1.0, fi.stated_noise);
  r.identifiability_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - ti).count();
}

Measurements first_half(const Measurements& data) {
  Measurements first = data;
  const double t_half = first.t.front() + 0.5 * (first.t.back() - first.t.front());
  std::size_t n = 0;
  while (n < first.t.size() && first.t[n] <= t_half) ++n;
  first.t.resize(n);
  first.z.conservativeResize(static_cast<Eigen::Index>(n), Eigen::NoChange);
  return first;
}

void flag_wide_intervals(RunResult& r) {
  for (std::size_t i = 0; i < r.names.size() && i < r.interval.too_wide.size(); ++i)
    if (r.ident.identifiable[i] && r.interval.too_wide[i]) {
      r.ident.identifiable[i] = false;
      char buf[160];
      std::snprintf(buf, sizeof buf, "uncertainty interval ±%.3g is %.3g of the estimate: above 0.5",
                    r.interval.half_width[static_cast<Eigen::Index>(i)],
                    r.interval.half_width[static_cast<Eigen::Index>(i)] / std::abs(r.estimate[static_cast<Eigen::Index>(i)]));
      r.ident.reason[i] = buf;
    }
}

}  // namespace scoleid::identify
