#include "scoleid/identify/door/run_door.h"

#include "scoleid/identify/inverse/tied_parameterization.h"
#include "scoleid/io/error.h"

namespace scoleid::identify {

namespace {
// Why a run on this path has no matrix-free Gauss–Newton products (the Krylov method's), or "".
std::string no_matrix_free_products(const Problem& p) {
  if (p.scenario.identification.model == io::Model::Nonlinear) return "the nonlinear model does";
  if (p.frf) return "a frequency-domain run does (its Jacobian is explicit: one adjoint per sensor and line)";
  if (p.objective_options.initial_state_modes > 0) return "an estimated initial state (identification.initial_state: estimate) does";
  if (p.model().has_rate_outputs()) return "velocity and acceleration sensors do";
  return "";
}
}  // namespace

void check_run(const Problem& p, const RunOptions& ro) {
  const auto& id = p.scenario.identification;
  const std::string& src = p.scenario.source;
  const bool nonlinear = id.model == io::Model::Nonlinear;
  if (ro.method.value_or(id.method) == io::Method::GaussNewtonKrylov)
    if (const std::string why = no_matrix_free_products(p); !why.empty())
      throw io::InputError(src + ": method gauss-newton-krylov (--method or identification.method) needs matrix-free "
                                 "Gauss-Newton products, which " + why + " not offer; use gauss-newton or lbfgs");
  const bool sections = !section_families(p.params->names()).empty();
  if (id.smoothness != 0.0) {
    const std::string value = id.smoothness < 0 ? "discrepancy" : io::format_value(id.smoothness);
    if (p.frf)
      io::fail_field(src, "identification.smoothness",
                     "is not available in the frequency domain (identification.domain: frequency fits the FRFs without a prior)", value);
    if (nonlinear) io::fail_field(src, "identification.smoothness", "is not available with the nonlinear model", value);
    if (!sections)
      io::fail_field(src, "identification.smoothness", "needs sectional parameters (X_1 ... X_N) among those estimated", value);
    if (id.smoothness < 0)
      for (std::size_t k = 0; k < p.data.names.size(); ++k)
        if (!(k < p.noise_std.size() && p.noise_std[k] > 0.0))
          io::fail_field(src, "identification.smoothness",
                         "discrepancy needs every sensor's noise level stated (sensor '" + p.data.names[k] + "' has none)",
                         "discrepancy");
  }
  if (id.start == io::Start::CoarseToFine && p.frf)
    io::fail_field(src, "identification.start",
                   "is not available in the frequency domain (its fit starts from the FRFs' peaks, not a coarse-to-fine ladder)",
                   io::to_string(id.start));
  if (id.start == io::Start::CoarseToFine && !sections)
    io::fail_field(src, "identification.start", "needs sectional parameters (X_1 ... X_N) among those estimated",
                   io::to_string(id.start));
}

void check_experiments_run(const ExperimentsProblem& ep, const ExperimentsOptions& eo) {
  const io::Scenario& lead = ep.runs.empty() ? *ep.modes_scenario : ep.runs.front()->scenario;
  if (eo.method.value_or(lead.identification.method) != io::Method::GaussNewtonKrylov) return;
  for (std::size_t i = 0; i < ep.runs.size(); ++i)
    if (const std::string why = no_matrix_free_products(*ep.runs[i]); !why.empty())
      io::fail_field(ep.spec.source, "runs[" + std::to_string(i) + "] (" + ep.spec.runs[i].name + ")",
                     "cannot take method gauss-newton-krylov (--method or the lead scenario's identification.method): it needs "
                     "matrix-free Gauss-Newton products, which " + why + " not offer; use gauss-newton or lbfgs",
                     io::to_string(io::Method::GaussNewtonKrylov));
}

}  // namespace scoleid::identify
