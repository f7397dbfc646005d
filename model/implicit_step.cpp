#include "scoleid/model/implicit_step.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace scoleid::model {

bool ImplicitStepOptions::IsValid(std::string* why) const {
  auto bad = [why](const std::string& m) { if (why) *why = m; return false; };
  if (!(accuracy > 0 && accuracy < 1)) return bad("accuracy must be in (0, 1)");
  if (!(max_step >= 0)) return bad("max_step must be >= 0");
  if (!(reference_omega >= 0)) return bad("reference_omega must be >= 0");
  if (!(newton_fraction > 0 && newton_fraction <= 1)) return bad("newton_fraction must be in (0, 1]");
  if (max_newton_iterations < 2) return bad("max_newton_iterations must be >= 2");
  if (!(refresh_contraction > 0 && refresh_contraction < 1)) return bad("refresh_contraction must be in (0, 1)");
  return true;
}

double implicit_step_bound(const ImplicitStepOptions& options, double omega_1, double phase) {
  if (options.max_step > 0) return options.max_step;
  if (omega_1 > 0) return phase / omega_1;
  return std::numeric_limits<double>::infinity();
}

long long equal_steps(double span, double max_step) {
  return std::max<long long>(1, static_cast<long long>(std::ceil(span / max_step - 1e-9)));
}

}  // namespace scoleid::model
