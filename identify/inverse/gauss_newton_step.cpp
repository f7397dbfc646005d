#include "scoleid/identify/inverse/gauss_newton_step.h"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace scoleid::identify {

TrustRegionStep trust_region_step(const Eigen::MatrixXd& H, const Eigen::VectorXd& g, double radius, double lambda_min) {
  if (!(radius > 0)) throw std::invalid_argument("trust_region_step: radius must be > 0");
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(H);
  const Eigen::VectorXd mu = es.eigenvalues().cwiseMax(0.0);
  const Eigen::VectorXd gt = es.eigenvectors().transpose() * g;
  const double mu_max = mu.size() ? mu.maxCoeff() : 0.0;
  auto norm2 = [&](double lam) {
    double s = 0.0;
    for (int i = 0; i < mu.size(); ++i) {
      const double d = mu[i] + lam;
      if (gt[i] == 0.0) continue;
      if (!(d > 0.0)) return std::numeric_limits<double>::infinity();
      s += (gt[i] / d) * (gt[i] / d);
    }
    return s;
  };
  TrustRegionStep st;
  // Pure Gauss–Newton when H is numerically nonsingular in the directions g loads and the step fits.
  double lam = std::max(0.0, lambda_min);
  const double tiny = std::max(1e-14 * std::max(mu_max, 1e-300), lam);
  bool fits = true;
  for (int i = 0; i < mu.size(); ++i)
    if (gt[i] != 0.0 && mu[i] + lam <= tiny && lam == 0.0) fits = false;
  if (!fits || norm2(lam) > radius * radius) {
    // ‖δ(λ)‖ <= ‖g‖/λ, so λ_hi = ‖g‖/Δ is feasible; bisection in log λ down to the boundary.
    double hi = std::max(g.norm() / radius, tiny), lo = tiny;
    if (norm2(lo) <= radius * radius) {
      hi = lo;
    } else {
      for (int it = 0; it < 200 && hi / lo > 1.0 + 1e-10; ++it) {
        const double mid = std::sqrt(lo * hi);
        (norm2(mid) > radius * radius ? lo : hi) = mid;
      }
    }
    lam = hi;
    st.on_boundary = true;
  }
  Eigen::VectorXd c(mu.size());
  for (int i = 0; i < mu.size(); ++i) c[i] = gt[i] == 0.0 ? 0.0 : -gt[i] / (mu[i] + lam);
  st.delta = es.eigenvectors() * c;
  st.lambda = lam;
  st.predicted = -(g.dot(st.delta) + 0.5 * st.delta.dot(H * st.delta));
  return st;
}

double update_radius(double radius, const TrustRegionStep& step, double rho, double max_radius) {
  const double len = step.delta.norm();
  if (!(rho >= 0.25)) return 0.25 * len;
  if (rho > 0.75 && step.on_boundary) return std::min(2.0 * radius, max_radius);
  return radius;
}

}  // namespace scoleid::identify
