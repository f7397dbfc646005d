#include "scoleid/identify/run/strategy.h"

#include "scoleid/io/error.h"
#include "scoleid/io/scenario_fields.h"

namespace scoleid::identify {

io::Method resolve_method(io::Method requested, int parameters, bool smoothness_prior, bool matrix_free_products) {
  if (requested != io::Method::Auto) return requested;
  if (parameters <= kExplicitGaussNewtonParameters) return io::Method::GaussNewton;
  if (smoothness_prior)
    return matrix_free_products && parameters > kExplicitGaussNewtonWithPrior ? io::Method::GaussNewtonKrylov
                                                                              : io::Method::GaussNewton;
  return io::Method::Lbfgs;
}

OptimizerOptions optimizer_options(const io::IdentificationSpec& id, io::Method method, int parameters,
                                   std::optional<int> max_iterations) {
  OptimizerOptions oo;
  oo.method = method;
  oo.max_iterations = max_iterations.value_or(id.max_iterations);
  oo.gradient_tolerance = id.gradient_tolerance;
  oo.step_tolerance = id.step_tolerance;
  oo.steepest_weights = id.steepest_weights;
  oo.continuation = id.continuation_misfit > 0;
  if (oo.continuation) oo.continuation_misfit = id.continuation_misfit;
  if (!oo.steepest_weights.empty() && static_cast<int>(oo.steepest_weights.size()) != parameters)
    throw std::logic_error("optimizer_options: " + std::to_string(oo.steepest_weights.size()) + " steepest weights for " +
                           std::to_string(parameters) + " parameters (io::validate_scenario refuses it)");
  return oo;
}

OptimizerOptions cautious_continuation(const OptimizerOptions& options, const io::IdentificationSpec& id) {
  OptimizerOptions oc = options;
  oc.continuation = true;
  oc.continuation_misfit = (id.continuation_misfit > 0 ? id.continuation_misfit : OptimizerOptions{}.continuation_misfit) / 4.0;
  return oc;
}

std::string cautious_continuation_label(const OptimizerOptions& options) {
  return std::string(io::to_string(options.method)) + ", horizon continuation at misfit " +
         io::format_value(options.continuation_misfit);
}

bool ladder_first(const io::IdentificationSpec& id, std::size_t sections) {
  if (id.start == io::Start::CoarseToFine && sections == 0)
    throw std::logic_error("ladder_first: coarse_to_fine without a sectional family (identify::check_run refuses it)");
  return id.start == io::Start::CoarseToFine ||
         (id.start == io::Start::Auto && sections > static_cast<std::size_t>(kExplicitGaussNewtonParameters));
}

}  // namespace scoleid::identify
