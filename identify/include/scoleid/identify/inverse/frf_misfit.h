#pragma once
// The misfit between measured frequency response functions (io/frf_data.h) and the FE model's
// (docs/theory.md §6.10).
//
// Model. For the input i (load vector b = γ_i(c) b_i) and harmonic motion u(t) = Re(U e^{iωt}),
// the equation of motion M ü + D u̇ + K u = b f becomes the complex symmetric system
//   Z(ω) U = b,   Z(ω) = K − ω² M + iω D,
// and sensor s (row C_s on the o_s-th derivative of u) reads H_s(ω) = (iω)^{o_s} C_s Z(ω)⁻¹ b: the
// receptance, mobility or accelerance per unit input. One sparse complex factorisation per line.
// Data made under an exponential window e^{−at} (io/frf_data.h decay a > 0, an impact record) are
// the FRF at the complex frequency s = a + iω: Z(s) = K + s² M + s D and H_s = s^{o_s} C_s Z(s)⁻¹ b,
// with iω → s everywhere below (Z(s) stays complex symmetric, so the adjoint is unchanged).
//
// Misfit. Per line k and channel s, Δ_ks = H_s(ω_k; q) − Ĥ_ks, weighted by the measured value's
// variance σ²_ks = E|Ĥ − H|² (its real and imaginary parts each carry σ²/2, independent):
//   r = (√2 Re Δ / σ, √2 Im Δ / σ) per value,   J = ½ Σ r² = Σ |Δ_ks|² / σ²_ks,
// N = 2 · lines · channels real residuals; at the true parameters 2J is χ² with N degrees of freedom,
// and the Gauss–Newton matrix JᵀJ of these residuals is the data's Fisher information.
//
// Gradient, one adjoint solve per line. With Z_j = ∂Z/∂c_j = K_j − ω² M_j + iω D_j and b_j = ∂b/∂c_j,
//   ∂H_s/∂c_j = (iω)^{o_s} C_s Z⁻¹ (b_j − Z_j U)
//   ∂J/∂c_j   = 2 Re Σ_s a_s ∂H_s/∂c_j = 2 Re λᵀ (b_j − Z_j U),   a_s = conj(Δ_s)(iω)^{o_s}/σ_s²,
//   Z λ = Σ_s a_s C_sᵀ   (Z is symmetric, Zᵀ = Z: the adjoint system is the state's own matrix),
// chained to the parameters through ∂c/∂q. The Jacobian (Gauss–Newton) takes one adjoint per
// channel, λ_s = Z⁻¹ C_sᵀ, on the same factorisation: ∂H_s/∂c_j = (iω)^{o_s} λ_sᵀ (b_j − Z_j U).
// Lines are split between two threads.
//
// Frequency continuation. The horizon (misfit.h) is a frequency: the fit takes the lines up to it,
// and the optimiser's continuation (optimizers.h) lengthens it as the fit of the lines below
// improves — the analogue of the time record's: far from the solution a model peak sits beside the
// measured one and the cost between them has a valley at every peak slipped past, so the lowest
// peaks are fitted first. data_start() and data_end() are the lowest and highest line. The misfit
// profile at line i is, averaged over the channels, the weighted misfit of the lines up to it beyond
// its noise's expected share, relative to their weighted signal:
//   m_i = mean_s max(0, Σ_{k<=i} |Δ_ks|²/σ²_ks − (i + 1)) / Σ_{k<=i} |Ĥ_ks|²/σ²_ks.
#include <complex>
#include <vector>

#include "scoleid/identify/fe/structural_model.h"
#include "scoleid/identify/inverse/misfit.h"
#include "scoleid/identify/inverse/parameterization.h"
#include "scoleid/io/frf_data.h"

namespace scoleid::identify {

using ComplexMatrix = Eigen::MatrixXcd;

struct FrfMisfitOptions {
  int threads = 2;  // lines evaluated side by side (1: this thread only)
};

struct FrfMisfitCounters {
  long evaluations = 0;      // passes over the lines
  long factorisations = 0;   // complex sparse LU, one per line and pass
};

class FrfMisfit final : public Misfit {
public:
  // `sensors[s]`: the model sensor of data.channels[s]; `input`: the model input the FRFs are per
  // unit of. Checked by the caller at the door (run/frf_run.cpp); a mismatch here is a logic_error.
  FrfMisfit(const StructuralModel& model, const Parameterization& params, io::FrfData data, std::vector<int> sensors,
            int input, FrfMisfitOptions options = {});

  int size() const override { return params_.size(); }
  double horizon() const override { return data_.f_hz[static_cast<std::size_t>(active_ - 1)]; }
  double data_start() const override { return data_.f_hz.front(); }
  double data_end() const override { return data_.f_hz.back(); }
  void set_horizon(double f) override;
  long data_points() const override { return 2L * active_ * static_cast<long>(data_.channels.size()); }

  double cost(const VectorXd& q) override;
  double cost_and_gradient(const VectorXd& q, VectorXd& gradient) override;  // adjoint per line
  double gauss_newton(const VectorXd& q, VectorXd& gradient, MatrixXd& H, MisfitProfile* profile = nullptr) override;
  MisfitProfile misfit_profile(const VectorXd& q) override;
  VectorXd gauss_newton_product(const VectorXd& q, const VectorXd& v) override;  // Jᵀ(J v) from the Jacobian
  bool has_matrix_free_products() const override { return false; }

  // The weighted residuals r of the lines up to the horizon at q and J; with `jacobian`, ∂r/∂q
  // (rows × P). Rows line-major: value (k, s) holds rows 2(k·S + s) (real) and 2(k·S + s) + 1 (imaginary).
  double residuals(const VectorXd& q, VectorXd& r, MatrixXd* jacobian = nullptr);
  // The model's FRFs at q (every line × channels).
  ComplexMatrix predict(const VectorXd& q);

  const io::FrfData& data() const { return data_; }
  const std::vector<int>& sensors() const { return sensors_; }
  int input() const { return input_; }
  const FrfMisfitCounters& counters() const { return counters_; }

private:
  enum class Need { Cost, Gradient, Jacobian };
  struct Evaluation {
    VectorXd q;
    int active = 0;  // lines with derivatives and in J
    Need need = Need::Cost;
    double J = 0.0;
    VectorXd r, gradient;  // r over every line; J, the gradient and the Jacobian over the active ones
    MatrixXd jacobian;
    ComplexMatrix H;
  };
  const Evaluation& evaluate(const VectorXd& q, Need need);
  // Lines [k0, k1) into e (their rows of r and the Jacobian, H) and their gradient share into g.
  void evaluate_lines(const VectorXd& c, const MatrixXd& dcdq, Need need, int k0, int k1, Evaluation& e,
                      VectorXd& g_c) const;
  MisfitProfile profile_of(const Evaluation& e) const;

  const StructuralModel& model_;
  const Parameterization& params_;
  io::FrfData data_;
  std::vector<int> sensors_;
  int input_ = 0;
  FrfMisfitOptions options_;
  std::vector<double> orders_;  // o_s per channel
  int active_ = 0;              // lines up to the horizon
  Evaluation last_;
  bool have_last_ = false;
  FrfMisfitCounters counters_;
};

}  // namespace scoleid::identify
