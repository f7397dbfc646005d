#include "scoleid/crosscheck/case_identification.h"

#include <cmath>
#include <random>
#include <string>

#include "scoleid/crosscheck/table.h"
#include "scoleid/identify.h"
#include "scoleid/io/error.h"

namespace scoleid::crosscheck {

using nlohmann::json;

namespace {
json num(double v) { return json_number(v); }
}  // namespace

// One identification on `p` into the result row of one case (or seed).
json identify_row(std::shared_ptr<identify::Problem> problem) {
  const Identification id = scoleid::identify_parameters(problem, IdentifyOptions{});
  const identify::Problem& p = id.problem();
  const identify::RunResult& r = id.result();
  json row;
  row["converged"] = r.converged();
  row["optimizer_converged"] = r.summary.converged();
  row["explains_data"] = r.fit.explains_data;
  row["fit_ratio"] = r.fit.ratio;
  row["fit_test"] = r.fit.message;
  row["termination"] = identify::to_string(r.summary.termination);
  row["iterations"] = r.summary.iterations_done;
  row["iterations_all_attempts"] = r.iterations_all_attempts();
  row["seconds"] = r.wall_seconds;
  row["parameters"] = json::array();
  for (std::size_t i = 0; i < r.names.size(); ++i) {
    const auto e = static_cast<Eigen::Index>(i);
    const auto it = p.true_values.find(r.names[i]);
    if (it == p.true_values.end())
      throw io::InputError("truth file for " + p.data_source + ": no true value for parameter '" + r.names[i] + "'");
    const double truth = it->second, est = r.estimate[e];
    const bool ok = r.ident.identifiable.size() > i && r.ident.identifiable[i];
    const double hw = r.interval.half_width.size() > e ? r.interval.half_width[e] : std::nan("");
    json q{{"name", r.names[i]},
           {"truth", num(truth)},
           {"estimate", num(est)},
           {"relative_error", num(est / truth - 1.0)},
           {"std", num(r.ident.std.size() > e ? r.ident.std[e] : std::nan(""))},
           {"resolution", num(r.ident.resolution.size() > e ? r.ident.resolution[e] : std::nan(""))},
           {"half_record_shift", num(r.interval.half_record_shift.size() > e ? r.interval.half_record_shift[e] : std::nan(""))},
           {"half_width", num(ok ? hw : std::nan(""))},
           {"relative_half_width", num(ok ? hw / std::abs(truth) : std::nan(""))},
           {"identifiable", ok},
           {"covered", ok && std::isfinite(hw) && std::abs(est - truth) <= hw}};
    if (!ok && r.ident.reason.size() > i) q["not_identifiable_because"] = r.ident.reason[i];
    row["parameters"].push_back(q);
  }
  return row;
}

// Gaussian noise of `relative` × each sensor's RMS, seeded; the level is stated to the identifier
// (it is what a test engineer knows of the instrument).
void add_noise(identify::Problem& p, double relative, unsigned seed) {
  if (p.band_gain < 1.0)
    throw io::InputError(p.scenario.source + ": identification.band: the noise a suite or campaign adds would come after "
                         "the band's filter; state the sensors' noise_std in the scenario instead");
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  auto& z = p.data.z;
  for (Eigen::Index k = 0; k < z.cols(); ++k) {
    const double rms = std::sqrt(z.col(k).squaredNorm() / static_cast<double>(z.rows()));
    const double sd = relative * rms;
    for (Eigen::Index i = 0; i < z.rows(); ++i) z(i, k) += sd * n01(rng);
    const auto kk = static_cast<std::size_t>(k);
    if (p.noise_std.size() <= kk) p.noise_std.resize(kk + 1, 0.0);
    if (p.noise_origin.size() <= kk) p.noise_origin.resize(kk + 1, "");
    p.noise_std[kk] = sd;
    p.noise_origin[kk] = "scenario";
  }
  p.objective_options.noise_std = p.noise_std;  // the continuation's noise share (objective.h)
}

}  // namespace scoleid::crosscheck
