#include "scoleid/identify/fe/turned_arm.h"

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace scoleid::identify {

using Eigen::Matrix3d;
using Eigen::Vector3d;

namespace {

// A polynomial in three variables truncated at degree 3: the coefficients of its 20 monomials
// x^a y^b z^c (a + b + c ≤ 3), ordered by degree.
struct Monomials {
  std::array<std::array<int, 3>, 20> exps{};
  int index[4][4][4];
  struct Product {
    int i, j, k;  // monomial i times monomial j is monomial k
  };
  std::vector<Product> products;
  Monomials() {
    for (auto& a : index)
      for (auto& b : a)
        for (int& c : b) c = -1;
    int n = 0;
    for (int d = 0; d <= 3; ++d)
      for (int a = d; a >= 0; --a)
        for (int b = d - a; b >= 0; --b) {
          exps[static_cast<std::size_t>(n)] = {a, b, d - a - b};
          index[a][b][d - a - b] = n++;
        }
    for (int i = 0; i < 20; ++i)
      for (int j = 0; j < 20; ++j) {
        const auto &x = exps[static_cast<std::size_t>(i)], &y = exps[static_cast<std::size_t>(j)];
        if (x[0] + x[1] + x[2] + y[0] + y[1] + y[2] <= 3) products.push_back({i, j, index[x[0] + y[0]][x[1] + y[1]][x[2] + y[2]]});
      }
  }
};

const Monomials& monomials() {
  static const Monomials m;
  return m;
}

struct Jet {
  std::array<double, 20> c{};
  static Jet constant(double v) {
    Jet j;
    j.c[0] = v;
    return j;
  }
  static Jet variable(double v, int k) {
    Jet j = constant(v);
    j.c[static_cast<std::size_t>(1 + k)] = 1.0;
    return j;
  }
};

Jet operator+(Jet a, const Jet& b) {
  for (std::size_t i = 0; i < 20; ++i) a.c[i] += b.c[i];
  return a;
}
Jet operator-(Jet a, const Jet& b) {
  for (std::size_t i = 0; i < 20; ++i) a.c[i] -= b.c[i];
  return a;
}
Jet operator*(double s, Jet a) {
  for (double& v : a.c) v *= s;
  return a;
}
Jet operator*(const Jet& a, const Jet& b) {
  Jet r;
  for (const auto& p : monomials().products)
    r.c[static_cast<std::size_t>(p.k)] += a.c[static_cast<std::size_t>(p.i)] * b.c[static_cast<std::size_t>(p.j)];
  return r;
}

// f(x) from f and its first three derivatives at x's value: f + f' δ + f'' δ²/2 + f''' δ³/6, δ = x − x₀.
Jet compose(const Jet& x, double f0, double f1, double f2, double f3) {
  Jet d = x;
  d.c[0] = 0.0;
  const Jet d2 = d * d, d3 = d2 * d;
  return Jet::constant(f0) + f1 * d + (0.5 * f2) * d2 + (f3 / 6.0) * d3;
}
Jet sqrt(const Jet& x) {
  const double v = x.c[0], s = std::sqrt(v);
  return compose(x, s, 0.5 / s, -0.25 / (v * s), 0.375 / (v * v * s));
}
Jet reciprocal(const Jet& x) {
  const double v = x.c[0];
  return compose(x, 1.0 / v, -1.0 / (v * v), 2.0 / (v * v * v), -6.0 / (v * v * v * v));
}
}  // namespace

TurnedRotation turned_rotation(const Vector3d& theta, bool third) {
  const double s2 = theta[0] * theta[0] + theta[1] * theta[1];
  if (!(s2 < 1.0))
    throw std::domain_error("turned_arm: the end's tilt reaches 90 deg (|theta_perp|^2 = " + std::to_string(s2) + ")");
  // R = T(x, y) Z(ψ) separates: ∂_x^a ∂_y^b ∂_ψ^c R = (∂_x^a ∂_y^b T)(∂_ψ^c Z). T by a polynomial in
  // (x, y) truncated at degree 3; with c = √(1 − x² − y²), k = 1/(1 + c) ([a]×² = a aᵀ − |a|² I),
  //   T = [1 − k y²   k x y     y ]
  //       [k x y      1 − k x²  −x]
  //       [−y         x         c ],
  // and Z^(n) = [ẑ]×ⁿ Z.
  const Jet x = Jet::variable(theta[0], 0), y = Jet::variable(theta[1], 1);
  const Jet one = Jet::constant(1.0), zero = Jet::constant(0.0);
  const Jet c = sqrt(one - (x * x + y * y)), k = reciprocal(one + c);
  const Jet kx = k * x, kxy = kx * y;
  const Jet T[3][3] = {{one - k * y * y, kxy, y}, {kxy, one - kx * x, zero - x}, {zero - y, x, c}};
  const Monomials& M = monomials();
  Matrix3d Td[4][4];  // Td[a][b] = ∂_x^a ∂_y^b T, a + b ≤ 3
  const double fact[4] = {1.0, 1.0, 2.0, 6.0};
  for (int ea = 0; ea <= 3; ++ea)
    for (int eb = 0; ea + eb <= 3; ++eb)
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          Td[ea][eb](i, j) = fact[ea] * fact[eb] * T[i][j].c[static_cast<std::size_t>(M.index[ea][eb][0])];
  const double cz = std::cos(theta[2]), sz = std::sin(theta[2]);
  Matrix3d Zd[4];
  Zd[0] << cz, -sz, 0.0, sz, cz, 0.0, 0.0, 0.0, 1.0;
  Matrix3d Ez = Matrix3d::Zero();
  Ez(0, 1) = -1.0;
  Ez(1, 0) = 1.0;
  for (int n = 1; n <= 3; ++n) Zd[n] = Ez * Zd[n - 1];
  // The derivative along the variables listed (0 = x, 1 = y, 2 = ψ).
  auto D = [&](std::initializer_list<std::size_t> vars) {
    int cnt[3] = {0, 0, 0};
    for (std::size_t v : vars) ++cnt[v];
    return Matrix3d(Td[cnt[0]][cnt[1]] * Zd[cnt[2]]);
  };
  TurnedRotation R;
  R.has_third = third;
  if (!third)
    for (auto& a : R.d3)
      for (auto& b : a)
        for (auto& m : b) m.setZero();
  R.value = D({});
  for (std::size_t p = 0; p < 3; ++p) {
    R.d1[p] = D({p});
    for (std::size_t q = p; q < 3; ++q) {
      R.d2[p][q] = R.d2[q][p] = D({p, q});
      for (std::size_t s = q; third && s < 3; ++s) {
        const Matrix3d d = D({p, q, s});
        R.d3[p][q][s] = R.d3[p][s][q] = R.d3[q][p][s] = R.d3[q][s][p] = R.d3[s][p][q] = R.d3[s][q][p] = d;
      }
    }
  }
  return R;
}

TurnedArm TurnedRotation::arm(const Vector3d& r) const {
  TurnedArm out;
  out.has_third = has_third;
  if (!has_third)
    for (auto& a : out.d3)
      for (auto& m : a) m.setZero();
  out.value = value * r;
  for (std::size_t p = 0; p < 3; ++p) {
    out.d1.col(static_cast<Eigen::Index>(p)) = d1[p] * r;
    for (std::size_t q = 0; q < 3; ++q) {
      const Vector3d v2 = d2[p][q] * r;
      for (std::size_t i = 0; i < 3; ++i) out.d2[i](static_cast<Eigen::Index>(p), static_cast<Eigen::Index>(q)) = v2[static_cast<Eigen::Index>(i)];
      for (std::size_t s = 0; has_third && s < 3; ++s) {
        const Vector3d v3 = d3[p][q][s] * r;
        for (std::size_t i = 0; i < 3; ++i)
          out.d3[i][p](static_cast<Eigen::Index>(q), static_cast<Eigen::Index>(s)) = v3[static_cast<Eigen::Index>(i)];
      }
    }
  }
  return out;
}

TurnedArm turned_arm(const Vector3d& theta, const Vector3d& arm) { return turned_rotation(theta).arm(arm); }

Vector3d TurnedArm::second(const Vector3d& a, const Vector3d& b) const {
  return {a.dot(d2[0] * b), a.dot(d2[1] * b), a.dot(d2[2] * b)};
}

Vector3d TurnedArm::second_t(const Vector3d& b, const Vector3d& w) const {
  return w[0] * (d2[0] * b) + w[1] * (d2[1] * b) + w[2] * (d2[2] * b);
}

Vector3d TurnedArm::third_t(const Vector3d& a, const Vector3d& w) const {
  Vector3d g = Vector3d::Zero();
  for (std::size_t i = 0; i < 3; ++i)
    for (std::size_t k = 0; k < 3; ++k) g[static_cast<Eigen::Index>(k)] += w[static_cast<Eigen::Index>(i)] * a.dot(d3[i][k] * a);
  return g;
}

}  // namespace scoleid::identify
