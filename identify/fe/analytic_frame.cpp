#include "scoleid/identify/fe/analytic_frame.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace scoleid::identify::analytic {

namespace {
// The d-th derivative of the Krylov functions [S, T, U, V](βx): each derivative maps S→βV, T→βS,
// U→βT, V→βU, so it is β^d times function (i + 3d) mod 4.
Eigen::RowVector4d krylov(double beta, double x, int d) {
  const double z = beta * x;
  double f[4] = {0, 0, 0, 0};
  double term = 1.0;  // z^j / j!
  for (int j = 0; j < 400; ++j) {
    f[j % 4] += term;
    term *= z / (j + 1);
    if (j > 8 && term < 1e-30 * f[0]) break;
  }
  Eigen::RowVector4d r;
  for (int i = 0; i < 4; ++i) r[i] = std::pow(beta, d) * f[(i + 3 * d) % 4];
  return r;
}
}  // namespace

Eigen::Matrix2d column_dynamic_stiffness(double EI, double rho_A, double h, double omega) {
  const double beta = std::pow(rho_A * omega * omega / EI, 0.25);
  Eigen::Matrix4d A;
  A << krylov(beta, 0, 0), krylov(beta, 0, 1), krylov(beta, h, 0), krylov(beta, h, 1);
  const Eigen::FullPivLU<Eigen::Matrix4d> lu(A);
  Eigen::Matrix2d K;
  for (int j = 0; j < 2; ++j) {
    Eigen::Vector4d rhs = Eigen::Vector4d::Zero();
    rhs[2 * j] = 1.0;
    const Eigen::Vector4d a = lu.solve(rhs);
    K(0, j) = EI * krylov(beta, 0, 3).dot(a);
    K(1, j) = -EI * krylov(beta, h, 3).dot(a);
  }
  return K;
}

namespace {
// The floors' dynamic stiffness Σ_storeys columns × (column dynamic stiffness) − ω² diag(m),
// symmetrised (the column's is symmetric but for rounding).
Eigen::MatrixXd floors_dynamic_stiffness(const io::FrameSpec& f, double omega) {
  const int n = f.storeys();
  Eigen::MatrixXd D = Eigen::MatrixXd::Zero(n, n);
  for (int k = 0; k < n; ++k) {
    const auto i = static_cast<std::size_t>(k);
    const Eigen::Matrix2d K = f.columns * column_dynamic_stiffness(f.EI[i], f.rho_A, f.heights[i], omega);
    D(k, k) += K(1, 1) - omega * omega * f.floor_mass[i];
    if (k > 0) {
      D(k - 1, k - 1) += K(0, 0);
      D(k - 1, k) += 0.5 * (K(0, 1) + K(1, 0));
      D(k, k - 1) += 0.5 * (K(0, 1) + K(1, 0));
    }
  }
  return D;
}
}  // namespace

double frame_determinant(const io::FrameSpec& f, double omega) { return floors_dynamic_stiffness(f, omega).determinant(); }

int frame_modes_below(const io::FrameSpec& f, double omega) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(floors_dynamic_stiffness(f, omega), Eigen::EigenvaluesOnly);
  return static_cast<int>((es.eigenvalues().array() < 0.0).count());
}

std::vector<double> frame_omegas(const io::FrameSpec& f, int count) {
  // Below the first column pole the count of D(ω)'s negative eigenvalues is the number of the
  // frame's frequencies below ω (Wittrick–Williams, with no clamped-column modes to add): the k-th
  // frequency is where the count reaches k, found by bisection.
  double pole = std::numeric_limits<double>::infinity();
  for (int k = 0; k < f.storeys(); ++k) {
    const auto i = static_cast<std::size_t>(k);
    pole = std::min(pole, std::pow(4.730040744862704 / f.heights[i], 2) * std::sqrt(f.EI[i] / f.rho_A));
  }
  const double top = pole * (1.0 - 1e-9);
  const int available = std::min(count, frame_modes_below(f, top));
  std::vector<double> out;
  for (int k = 1; k <= available; ++k) {
    double lo = out.empty() ? 0.0 : out.back(), hi = top;
    for (int it = 0; it < 200 && hi - lo > 1e-15 * hi; ++it) {
      const double mid = 0.5 * (lo + hi);
      if (frame_modes_below(f, mid) >= k) hi = mid;
      else lo = mid;
    }
    out.push_back(0.5 * (lo + hi));
  }
  return out;
}

}  // namespace scoleid::identify::analytic
