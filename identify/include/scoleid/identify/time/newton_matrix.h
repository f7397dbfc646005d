#pragma once
// The Newton matrix of an implicit stage of  M ẍ + D ẋ + K x = F:
//
//     S(γ) = M + γ D + γ² K,        γ = h·a_ii  (step times the stage's diagonal coefficient)
//
// In first-order form y = (x, v) the stage system (I − γJ) y = r, J = [0 I; −M⁻¹K −M⁻¹D],
// reduces to one solve with S(γ) (second_order_solver.h, esdirk_stepper.h). S(γ) is symmetric
// positive definite when M is and D, K are positive semidefinite, and banded (with a dense border
// of a few rigid-body DOFs) in the FE DOF order, so it is factored by banded Cholesky, written
// straight into band and border from the common sparsity pattern of M, D and K.
//
// A fixed-step integrator needs one factorisation per distinct γ: the regular step, and the
// shortened steps that land on forcing breakpoints. The last few are kept, so a solve that
// alternates between them never refactors.
#include <vector>

#include "scoleid/identify/time/banded_cholesky.h"
#include "scoleid/identify/fe/structural_model.h"

namespace scoleid::identify {

class NewtonMatrix {
public:
  // M, D, K must share one compressed sparsity pattern (values aligned entry by entry);
  // `shape` (BandedCholesky::shape of that pattern) holds every entry. The matrices are referenced,
  // not copied.
  NewtonMatrix(const SparseMatrix& M, const SparseMatrix& D, const SparseMatrix& K, BandedCholesky::Shape shape);

  // The Cholesky factor of S(γ); throws std::runtime_error if S(γ) is not positive definite.
  const BandedCholesky& factor(double gamma);
  long factorizations() const { return factorizations_; }

private:
  static constexpr std::size_t kCache = 4;
  struct Entry {
    double gamma = 0.0;
    long last_use = -1;
    BandedCholesky chol;
  };
  const SparseMatrix &M_, &D_, &K_;
  int n_ = 0;
  BandedCholesky::Shape shape_;
  std::vector<long> lower_slot_;  // per stored nonzero: its storage offset, or −1 (upper triangle)
  std::vector<Entry> cache_;
  long uses_ = 0, factorizations_ = 0;
};

}  // namespace scoleid::identify
