// An identification in the frequency domain (frf_run.h; docs/theory.md §6.10).
#include "scoleid/identify/run/frf_run.h"

#include <stdexcept>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>

#include "scoleid/identify/inverse/modal_misfit.h"
#include "scoleid/identify/run/assessment.h"
#include "scoleid/identify/run/strategy.h"
#include "scoleid/io/error.h"
#include "scoleid/io/frf_estimate.h"
#include "scoleid/io/interrupt.h"
#include "scoleid/io/progress.h"

namespace scoleid::identify {

FitTest frf_fit_test(const Problem& p, FrfMisfit& m, const VectorXd& q) {
  FitTest f;
  const io::FrfData& d = m.data();
  const int L = d.lines(), S = static_cast<int>(d.channels.size());
  const double m_err = model_error(p);
  f.model_error = m_err;
  if (!q.allFinite()) {
    f.message = "not tested: the estimate is not finite";
    return f;
  }
  m.set_horizon(m.data_end());
  const ComplexMatrix H = m.predict(q);
  // The discretisation estimate: the same model on twice the elements.
  ComplexMatrix D = ComplexMatrix::Zero(L, S);
  bool have_d = false;
  try {
    const auto fine = make_structure(p.scenario, 2 * p.structure->elements());
    const auto params = fine->parameterize(p.scenario);
    if (params->names() == p.params->names()) {
      FrfMisfit fm(fine->model(), *params, d, m.sensors(), m.input());
      D = fm.predict(q) - H;
      have_d = D.allFinite();
      if (!have_d) D.setZero();
    }
  } catch (const io::Interrupted&) {
    throw;
  } catch (const std::domain_error&) {
    // A refined model that cannot be solved at q: no discretisation estimate.
  }
  const double kappa = p.frf_variance_dof > 0.0 ? p.frf_variance_dof / (p.frf_variance_dof - 4.0) : 1.0;
  double excess = 0.0, allowed_d = 0.0, allowed_m_unit = 0.0;
  for (int s = 0; s < S; ++s) {
    const auto& ch = d.channels[static_cast<std::size_t>(s)];
    SensorFit sf;
    sf.name = ch.sensor;
    sf.noise_origin = d.estimator == "file" ? "file" : d.estimator == "lines" ? "harmonic fit" : "segments' scatter";
    double chi2 = 0.0, sig = 0.0, res = 0.0, var = 0.0, dd = 0.0, a_d = 0.0, a_m = 0.0;
    for (int k = 0; k < L; ++k) {
      const double v = ch.variance[static_cast<std::size_t>(k)];
      const std::complex<double> delta = H(k, s) - ch.H[static_cast<std::size_t>(k)];
      chi2 += 2.0 * std::norm(delta) / v;
      sig += std::norm(ch.H[static_cast<std::size_t>(k)]);
      res += std::norm(delta);
      var += v;
      dd += std::norm(D(k, s));
      a_d += 8.0 * std::norm(D(k, s)) / v;
      a_m += 2.0 * std::norm(ch.H[static_cast<std::size_t>(k)]) / v;
    }
    sf.rms_signal = std::sqrt(sig / L);
    sf.rms_residual = std::sqrt(res / L);
    sf.noise = std::sqrt(var / L);
    sf.systematic = std::sqrt(std::max(0.0, res - var) / L);
    sf.discretisation = have_d ? std::sqrt(dd / L) : std::nan("");
    sf.allowed = std::sqrt((4.0 * dd + m_err * m_err * sig) / L);
    const double n_s = 2.0 * L;
    sf.explained = chi2 - n_s <= a_d + m_err * m_err * a_m + 3.0 * std::sqrt(2.0 * n_s * kappa);
    excess += chi2 - n_s;
    allowed_d += a_d;
    allowed_m_unit += a_m;
    f.sensors.push_back(sf);
  }
  const double N = 2.0 * L * S, band = 3.0 * std::sqrt(2.0 * N * kappa);
  f.explains_data = excess <= allowed_d + m_err * m_err * allowed_m_unit + band;
  f.within_noise_and_discretisation = excess <= allowed_d + band;
  f.ratio = std::sqrt(std::max(0.0, excess) / (allowed_d + m_err * m_err * allowed_m_unit + band));
  f.model_error_needed = allowed_m_unit > 0 ? std::sqrt(std::max(0.0, excess - allowed_d - band) / allowed_m_unit) : 0.0;
  char msg[400];
  if (f.explains_data && !f.within_noise_and_discretisation)
    std::snprintf(msg, sizeof msg,
                  "passes only with the model-error allowance of %.3g %% (identification.model_error): the residual needs at least %.3g %%, "
                  "beyond what noise and discretisation allow (weighted chi2 %.6g over %.0f values)",
                  100.0 * m_err, 100.0 * f.model_error_needed, excess + N, N);
  else
    std::snprintf(msg, sizeof msg, "%s: weighted chi2 %.6g over %.0f values (noise band %.3g, discretisation %.3g, model error %.3g)%s",
                  f.explains_data ? "explains the data" : "does not explain the data", excess + N, N, band, allowed_d,
                  m_err * m_err * allowed_m_unit,
                  f.explains_data || f.model_error_needed <= 0 ? "" : (", needs a model error of at least " + io::format_value(100.0 * f.model_error_needed) + " %").c_str());
  f.message = msg;
  return f;
}

namespace {
// The iteration table on stderr (io::progress): iteration, parameters, cost, the continuation's top line.
void print_iteration(const Problem& p, const IterationRecord& r) {
  const int P = p.params->size();
  if (r.k == 0) {
    io::progress("%5s", "iter");
    for (int i = 0; i < P; ++i) io::progress(" %13s", p.params->names()[static_cast<std::size_t>(i)].c_str());
    io::progress(" %13s %10s\n", "cost", "up to [Hz]");
  }
  io::progress("%5d", r.k);
  for (int i = 0; i < P; ++i) io::progress(" %13.6g", r.q[i]);
  io::progress(" %13.6e %10.4g\n", r.cost, r.horizon);
}
}  // namespace

// Fisher information of the weighted residuals (all lines) at q (frf_run.h).
FisherInformation frf_fisher(FrfMisfit& m, const VectorXd& q) {
  m.set_horizon(m.data_end());
  VectorXd r;
  MatrixXd J;
  m.residuals(q, r, &J);
  FisherInformation fi;
  fi.F = J.transpose() * J;
  fi.chi2 = r.squaredNorm();
  fi.data_values = static_cast<long>(r.size());
  const double N = static_cast<double>(r.size());
  fi.systematic = std::max(0.0, fi.chi2 - (N + 2.0 * std::sqrt(2.0 * N)));
  for (const auto& ch : m.data().channels) {
    double v = 0.0;
    for (double x : ch.variance) v += x;
    fi.noise_std.push_back(std::sqrt(v / static_cast<double>(ch.variance.size())));
  }
  fi.stated_noise = true;
  return fi;
}

namespace {
// The measured FRFs' resonance peaks: local maxima of P_k = Σ_s |Ĥ_ks|² / Σ_k' |Ĥ_k's|² that are the
// largest within ±3 % of their frequency (at least ±2 lines), stand at least four times (6 dB)
// above the higher of the two lowest points between them and the next higher line on either side
// (their prominence: a resonance rises far above its skirts, a ripple does not), and are at least
// 10⁻³ of the strongest; at most eight, each refined by the parabola through log P at its line and
// its neighbours.
std::vector<double> frf_peaks(const io::FrfData& d) {
  const int L = d.lines();
  std::vector<double> P(static_cast<std::size_t>(L), 0.0);
  for (const auto& ch : d.channels) {
    double total = 0.0;
    for (const auto& h : ch.H) total += std::norm(h);
    if (total > 0)
      for (int k = 0; k < L; ++k) P[static_cast<std::size_t>(k)] += std::norm(ch.H[static_cast<std::size_t>(k)]) / total;
  }
  std::vector<std::pair<double, double>> peaks;  // power, Hz
  for (int k = 1; k + 1 < L; ++k) {
    const double f = d.f_hz[static_cast<std::size_t>(k)];
    if (!(P[static_cast<std::size_t>(k)] > P[static_cast<std::size_t>(k - 1)] && P[static_cast<std::size_t>(k)] >= P[static_cast<std::size_t>(k + 1)]))
      continue;
    bool largest = true;
    for (int i = 0; i < L && largest; ++i) {
      const double fi = d.f_hz[static_cast<std::size_t>(i)];
      const bool near = std::abs(fi - f) <= 0.03 * f || std::abs(i - k) <= 2;
      if (i != k && near && P[static_cast<std::size_t>(i)] > P[static_cast<std::size_t>(k)]) largest = false;
    }
    if (!largest) continue;
    double left = P[static_cast<std::size_t>(k)], right = left;
    for (int i = k - 1; i >= 0 && P[static_cast<std::size_t>(i)] <= P[static_cast<std::size_t>(k)]; --i) left = std::min(left, P[static_cast<std::size_t>(i)]);
    for (int i = k + 1; i < L && P[static_cast<std::size_t>(i)] <= P[static_cast<std::size_t>(k)]; ++i) right = std::min(right, P[static_cast<std::size_t>(i)]);
    if (!(P[static_cast<std::size_t>(k)] >= 4.0 * std::max(left, right))) continue;
    const double a = std::log(P[static_cast<std::size_t>(k - 1)]), b = std::log(P[static_cast<std::size_t>(k)]),
                 c = std::log(P[static_cast<std::size_t>(k + 1)]);
    const double f0 = d.f_hz[static_cast<std::size_t>(k - 1)], f2 = d.f_hz[static_cast<std::size_t>(k + 1)];
    double shift = a - 2 * b + c < 0 ? 0.5 * (a - c) / (a - 2 * b + c) : 0.0;  // in lines, for even spacing
    shift = std::clamp(shift, -0.5, 0.5);
    const double fk = shift < 0 ? f + shift * (f - f0) : f + shift * (f2 - f);
    peaks.emplace_back(P[static_cast<std::size_t>(k)], fk);
  }
  std::sort(peaks.rbegin(), peaks.rend());
  std::vector<double> out;
  for (const auto& [pw, f] : peaks)
    if (pw >= 1e-3 * peaks.front().first && out.size() < 8) out.push_back(f);
  std::sort(out.begin(), out.end());
  return out;
}

// The peaks' start (frf_run.h): the model's natural frequencies fitted to the measured peaks
// (inverse/modal_misfit.h, frequencies alone, each known to a line's spacing), from q0; q0 when that
// fit does not converge or has nothing to fit.
VectorXd peak_start(const Problem& p, const VectorXd& q0, std::string& note) {
  const io::FrfData& d = *p.frf;
  const auto peaks = frf_peaks(d);
  if (peaks.empty()) {
    note = "no resonance peak in the FRFs: the fit starts from the initial values";
    return q0;
  }
  io::ModalData md;
  md.source = "the FRFs' peaks";
  for (std::size_t i = 0; i < peaks.size(); ++i) {
    io::ModalData::Mode mode;
    mode.label = static_cast<int>(i + 1);
    mode.frequency_hz = peaks[i];
    const auto it = std::lower_bound(d.f_hz.begin(), d.f_hz.end(), peaks[i]);
    const double spacing = it != d.f_hz.end() && it != d.f_hz.begin() ? *it - *(it - 1) : 0.01 * peaks[i];
    mode.frequency_std_hz = std::max(spacing, 1e-3 * peaks[i]);
    md.modes.push_back(mode);
  }
  try {
    ModalMisfit modal(p.model(), *p.params, md);
    OptimizerOptions o;
    o.method = io::Method::GaussNewton;
    o.max_iterations = 30;
    const OptimizerSummary s = minimize(modal, q0, o);
    if (!s.converged() || !s.q.allFinite()) {
      note = "the model's modes could not be fitted to the FRFs' " + std::to_string(peaks.size()) + " peaks (" + s.message + "): the fit starts from the initial values";
      return q0;
    }
    char b[200];
    std::snprintf(b, sizeof b, "the model's modes fitted to the FRFs' %zu peaks (%.4g to %.4g Hz) in %d iterations", peaks.size(),
                  peaks.front(), peaks.back(), s.iterations_done);
    note = b;
    return s.q;
  } catch (const io::Interrupted&) {
    throw;
  } catch (const std::domain_error& e) {
    note = std::string("the peaks' start failed (") + e.what() + "): the fit starts from the initial values";
    return q0;
  }
}
}  // namespace

namespace {
// The lower half of the band's refit (frf_run.h): the fit again from q̂ on the lines up to the
// middle one, whose shift enters the interval as the half-record refit's does.
void half_band_refit(const Problem& p, FrfMisfit& m, const OptimizerOptions& o, RunResult& r, IntervalInputs& in) {
  const auto& f = p.frf->f_hz;
  if (f.size() < 4) {
    in.refit_applies = false;  // too few lines to halve: the noise and residual terms alone
    return;
  }
  io::FrfData lower = m.data();
  const std::size_t n = f.size() / 2;
  lower.f_hz.resize(n);
  for (auto& ch : lower.channels) {
    ch.H.resize(n);
    ch.variance.resize(n);
    if (ch.coherence.size() > n) ch.coherence.resize(n);
  }
  FrfMisfit lm(p.model(), *p.params, std::move(lower), m.sensors(), m.input());
  OptimizerOptions half = o;
  half.continuation = false;
  try {
    const OptimizerSummary s = minimize(lm, r.estimate, half);
    in.half_record_estimate = s.q;
    in.half_record_converged = s.converged();
    r.half_record_estimate = s.q;
    r.half_record_converged = s.converged();
  } catch (const std::domain_error&) {
    in.half_record_estimate = VectorXd::Constant(r.estimate.size(), std::nan(""));
    in.half_record_converged = false;
  }
}
}  // namespace

// The declared tolerances' consider terms (frf_run.h; assessment.h): the outputs are the weighted
// residuals of every line at q̂, so an output change d is the weighted change of the model's FRFs,
// and the estimate's response to it (JₖᵀJₖ)⁻¹Jₖᵀ d over the parameters with a finite std.
std::vector<ConsiderTerm> frf_consider_terms(const Problem& p, FrfMisfit& m, const Identifiability& id, const VectorXd& q) {
  if (p.scenario.identification.uncertain.empty()) return {};
  m.set_horizon(m.data_end());
  VectorXd r0;
  MatrixXd J;
  m.residuals(q, r0, &J);
  const int P = static_cast<int>(q.size());
  std::vector<int> keep;
  for (int i = 0; i < P; ++i)
    if (std::isfinite(id.std[i])) keep.push_back(i);
  const auto K = static_cast<Eigen::Index>(keep.size());
  MatrixXd Jk(J.rows(), K);
  for (Eigen::Index a = 0; a < K; ++a) Jk.col(a) = J.col(keep[static_cast<std::size_t>(a)]);
  const Eigen::LDLT<MatrixXd> ldlt(Jk.transpose() * Jk);
  const auto outputs = [&](const io::Scenario& sc) {
    const auto st = make_structure(sc, sc.identification.elements);
    const auto params = st->parameterize(sc);
    FrfMisfit moved(st->model(), *params, *p.frf, p.frf_sensors, p.frf_input, FrfMisfitOptions{1});
    VectorXd r;
    moved.residuals(q, r);
    return r;
  };
  const auto shift = [&](const VectorXd& d) {
    const VectorXd sk = ldlt.solve(Jk.transpose() * d);
    VectorXd out = VectorXd::Zero(P);
    for (Eigen::Index a = 0; a < K; ++a) out[keep[static_cast<std::size_t>(a)]] = sk[a];
    return out;
  };
  return declared_consider_terms(p.scenario, P, r0, outputs, shift);
}

RunResult run_frf_identification(Problem& p, const RunOptions& ro) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto& id = p.scenario.identification;
  RunResult r = start_result(p, io::Model::Linear);
  FrfMisfit m(p.model(), *p.params, *p.frf, p.frf_sensors, p.frf_input);
  r.method = ro.method.value_or(id.method);
  if (r.method == io::Method::GaussNewtonKrylov)
    throw std::logic_error("run_frf_identification: gauss-newton-krylov (identify::check_run refuses it)");
  if (r.method == io::Method::Auto) r.method = io::Method::GaussNewton;
  OptimizerOptions o = optimizer_options(id, r.method, p.params->size(), ro.max_iterations);
  std::vector<IterationRecord> iterates;
  auto on_iteration = [&](const IterationRecord& it) {
    iterates.push_back(it);
    if (ro.verbose) print_iteration(p, it);
  };
  try {
    std::string start_note;
    const VectorXd q0 = peak_start(p, p.params->initial(), start_note);
    if (ro.verbose) io::progress("start: %s\n", start_note.c_str());
    r.frf_start_note = start_note;
    r.summary = minimize(m, q0, o, on_iteration);
    r.estimate = r.summary.q;
    r.fit = frf_fit_test(p, m, r.estimate);
    if (ro.verbose) io::progress("fit test: %s\n", r.fit.message.c_str());
    RunResult::Attempt a;
    a.strategy = "plain";
    a.method = r.method;
    a.termination = to_string(r.summary.termination);
    a.optimizer_converged = r.summary.converged();
    a.cost = m.cost(r.estimate);
    a.iterations = r.summary.iterations_done;
    a.explains_data = r.fit.explains_data;
    a.fit_message = r.fit.message;
    a.estimate = r.estimate;
    r.attempts.push_back(a);
    if (ro.compute_std) {
      const auto ti = std::chrono::steady_clock::now();
      const FisherInformation fi = frf_fisher(m, r.estimate);
      r.ident = identifiability_from(fi, r.estimate, &r.names);
      r.ident.noise_source = "frf";
      IntervalInputs in;
      in.estimate = r.estimate;
      half_band_refit(p, m, o, r, in);
      in.consider = frf_consider_terms(p, m, r.ident, r.estimate);
      r.interval = uncertainty_interval(r.ident, in);
      flag_wide_intervals(r);
      r.identifiability_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - ti).count();
    }
  } catch (const io::Interrupted& e) {
    if (!ro.keep_interrupted || iterates.empty()) throw;
    io::clear_interrupt();
    const IterationRecord& last = iterates.back();
    r.summary.iterations = iterates;
    r.summary.q = last.q;
    r.summary.cost = last.cost;
    r.summary.iterations_done = last.k;
    r.summary.termination = OptimizerSummary::Termination::Interrupted;
    char note[200];
    std::snprintf(note, sizeof note, "%s at iteration %d: the last iterate reached, not converged",
                  e.signal() == SIGALRM ? "the wall-time limit" : e.signal() == SIGINT ? "SIGINT" : "SIGTERM", last.k);
    r.summary.message = note;
    r.estimate = last.q;
    r.fit = FitTest{};
    r.fit.message = std::string("not tested: ") + note;
    r.interrupted_by = e.signal();
    r.interrupted_note = note;
  }
  estimate_modes(p, r, ro.verbose);
  if (r.estimate.allFinite()) {
    m.set_horizon(m.data_end());
    r.frf_model = m.predict(r.estimate);
  }
  r.frf_passes = m.counters().evaluations;
  r.frf_factorisations = m.counters().factorisations;
  r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.summary.wall_seconds = r.wall_seconds;
  return r;
}

}  // namespace scoleid::identify
