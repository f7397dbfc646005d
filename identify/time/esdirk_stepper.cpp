#include "scoleid/identify/time/esdirk_stepper.h"

#include <arkode/arkode_butcher_dirk.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "scoleid/io/interrupt.h"

namespace scoleid::identify {

bool ButcherTable::explicit_first_stage() const {
  if (stages < 1 || c[0] != 0.0) return false;
  for (int j = 0; j < stages; ++j)
    if (a(0, j) != 0.0) return false;
  return true;
}

bool ButcherTable::stiffly_accurate() const {
  if (stages < 1 || c[static_cast<std::size_t>(stages - 1)] != 1.0) return false;
  for (int j = 0; j < stages; ++j)
    if (b[static_cast<std::size_t>(j)] != a(stages - 1, j)) return false;
  return true;
}

ButcherTable ButcherTable::arkode_dirk(int id) {
  const auto tid = id < 0 ? ARKODE_ESDIRK324L2SA_4_2_3 : static_cast<ARKODE_DIRKTableID>(id);
  ARKodeButcherTable B = ARKodeButcherTable_LoadDIRK(tid);
  if (!B) throw std::invalid_argument("unknown ARKODE DIRK table id " + std::to_string(id));
  ButcherTable t;
  t.stages = B->stages;
  const auto s = static_cast<std::size_t>(t.stages);
  t.A.resize(s * s);
  t.b.resize(s);
  t.c.resize(s);
  for (std::size_t i = 0; i < s; ++i) {
    for (std::size_t j = 0; j < s; ++j) t.A[i * s + j] = B->A[i][j];
    t.b[i] = B->b[i];
    t.c[i] = B->c[i];
  }
  ARKodeButcherTable_Free(B);
  for (int i = 0; i < t.stages; ++i)
    for (int j = i + 1; j < t.stages; ++j)
      if (t.a(i, j) != 0.0) throw std::invalid_argument("ARKODE table " + std::to_string(id) + " is not diagonally implicit");
  return t;
}

int ButcherTable::esdirk436_id() { return ARKODE_ESDIRK436L2SA_6_3_4; }

std::string ButcherTable::name(int id) {
  if (id < 0 || id == ARKODE_ESDIRK324L2SA_4_2_3) return "esdirk324l2sa";
  if (id == ARKODE_ESDIRK436L2SA_6_3_4) return "esdirk436l2sa";
  return "arkode-dirk-" + std::to_string(id);
}

std::vector<double> segment_ends(const std::vector<double>& breakpoints, double t0, double t1) {
  std::vector<double> stops;
  for (double b : breakpoints)
    if (b > t0 && b < t1) stops.push_back(b);
  std::sort(stops.begin(), stops.end());
  stops.erase(std::unique(stops.begin(), stops.end()), stops.end());
  stops.push_back(t1);
  return stops;
}

EsdirkStepper::EsdirkStepper(const SparseMatrix& M, const SparseMatrix& D, const SparseMatrix& K, const BandedCholesky& mass,
                             NewtonMatrix& newton, ButcherTable table)
    : M_(M), products_(D, K), mass_(mass), newton_(newton), tab_(std::move(table)) {
  explicit_first_ = tab_.explicit_first_stage();
  stiffly_accurate_ = tab_.stiffly_accurate();
  for (int i = 0; i < tab_.stages; ++i)
    if (tab_.a(i, i) < 0.0) throw std::invalid_argument("EsdirkStepper: negative diagonal coefficient");
}

EsdirkStepper::Result EsdirkStepper::run(double t0, double t1, double h, const std::vector<double>& stops_in,
                                         const Forcing& forcing, int P, const TangentForcing* tangent,
                                         double tangent_end, StepAnchor anchor, const InitialState* initial) const {
  const int n = static_cast<int>(M_.rows());
  Result res;
  res.state = Trajectory(n);
  res.tangents.assign(static_cast<std::size_t>(std::max(P, 0)), Trajectory(n));
  // Recorded points: one per step and two per breakpoint, plus the start.
  if (h > 0.0 && t1 > t0) {
    auto points = [&](double t_end) {
      return static_cast<std::size_t>(std::ceil((std::min(t_end, t1) - t0) / h)) + 3 * stops_in.size() + 4;
    };
    res.state.reserve(points(t1));
    for (auto& tr : res.tangents) tr.reserve(points(tangent_end + h));
  }
  const Sink record = [&](const Point& pt) {
    res.state.push(pt.t, pt.x, pt.v, pt.a);
    const std::size_t stride = static_cast<std::size_t>(n);
    for (int i = 1; i < pt.columns; ++i)
      res.tangents[static_cast<std::size_t>(i - 1)].push(pt.t, pt.x + i * stride, pt.v + i * stride, pt.a + i * stride);
  };
  res.counters = stream(t0, t1, h, stops_in, forcing, record, P, tangent, tangent_end, nullptr,
                        std::numeric_limits<double>::infinity(), anchor, initial);
  return res;
}

// One integration's workspace and its steps: column 0 is the state, columns 1..P the tangents
// (dropped after tangent_end). Stage i of a step solves
//   (M + g D + g² K) A_i = F(t_i) − D ṽ − K (x̃ + g ṽ),  g = h a_ii,
// with x̃ = x + h Σ_j a_ij V_j, ṽ = v + h Σ_j a_ij A_j; then V_i = ṽ + g A_i (docs/theory.md §5.1).
class EsdirkStepper::Sweep {
public:
  Sweep(const EsdirkStepper& st, const Forcing& forcing, const Sink& sink, int P, const TangentForcing* tangent,
        double h, StepperCounters& cnt)
      : st_(st), forcing_(forcing), sink_(sink), tangent_(tangent), P_(P), n_(static_cast<int>(st.M_.rows())),
        s_(st.tab_.stages), m_(1 + P), h_(h), cnt_(cnt) {
    const int n = n_, m = m_;
    x = MatrixXd::Zero(n, m);
    v = MatrixXd::Zero(n, m);
    a.resize(n, m);
    xt.resize(n, m);
    vt.resize(n, m);
    w.resize(n, m);
    Vs.assign(static_cast<std::size_t>(s_), MatrixXd(n, m));
    As.assign(static_cast<std::size_t>(s_), MatrixXd(n, m));
    terms.assign(static_cast<std::size_t>(std::max(s_, 4)), {0.0, 0});
    G.resize(n, std::max(P, 1));
    F.resize(n);
    X0.resize(n);
  }

  bool has_tangents() const { return m_ > 1; }

  // Columns of `init` in place of rest (the rest stay zero); the caller then accelerates.
  void set_initial(const InitialState& init) {
    const auto c = std::min<Eigen::Index>(init.x.cols(), m_);
    if (init.x.rows() != n_ || init.v.rows() != n_ || init.v.cols() != init.x.cols())
      throw std::invalid_argument("EsdirkStepper: the initial state has the wrong shape");
    x.leftCols(c) = init.x.leftCols(c);
    v.leftCols(c) = init.v.leftCols(c);
  }

  void resume(const Start& start) {
    x.col(0) = Eigen::Map<const VectorXd>(start.x, n_);
    v.col(0) = Eigen::Map<const VectorXd>(start.v, n_);
    a.col(0) = Eigen::Map<const VectorXd>(start.a, n_);
    origin = start.origin;
  }

  // Accelerations of every column at the current (x, v), forcing evaluated at tf.
  void accelerate(double tf) {
    F.setZero();
    forcing_(tf, F.data());
    ++cnt_.stage_forcings;
    st_.products_.subtract(v.data(), x.data(), F.data(), a.data(), 1);
    st_.mass_.solve_in_place(a.col(0).data());
    ++cnt_.linear_solves;
    if (m_ > 1) {
      tangent_forcing(tf, x.col(0).data(), v.col(0).data(), a.col(0).data());
      st_.products_.subtract(v.col(1).data(), x.col(1).data(), G.data(), a.col(1).data(), P_);
      st_.mass_.solve_in_place(a.col(1).data(), P_, n_);
      cnt_.linear_solves += P_;
    }
  }

  void record(double t, bool resumable) const {
    Point pt;
    pt.t = t;
    pt.columns = m_;
    pt.x = x.data();
    pt.v = v.data();
    pt.a = a.data();
    pt.origin = origin;
    pt.h = h_;
    pt.resumable = resumable;
    sink_(pt);
  }

  void drop_tangents() {
    m_ = 1;
    for (MatrixXd* A : {&x, &v, &a, &xt, &vt, &w}) A->conservativeResize(n_, 1);
    for (auto& A : Vs) A.conservativeResize(n_, 1);
    for (auto& A : As) A.conservativeResize(n_, 1);
  }

  // One step from tn of length hs.
  void step(double tn, double hs) {
    for (int i = 0; i < s_; ++i) stage(i, tn, hs);
    // x += h Σ_j b_j V_j, v += h Σ_j b_j A_j, accumulated term by term in one pass.
    std::size_t nb = 0;
    for (int j = 0; j < s_; ++j) {
      const double c = hs * st_.tab_.b[static_cast<std::size_t>(j)];
      if (c != 0.0) terms[nb++] = {c, static_cast<std::size_t>(j)};
    }
    if (nb == 4) {
      const auto& [b0, k0] = terms[0];
      const auto& [b1, k1] = terms[1];
      const auto& [b2, k2] = terms[2];
      const auto& [b3, k3] = terms[3];
      x = x + b0 * Vs[k0] + b1 * Vs[k1] + b2 * Vs[k2] + b3 * Vs[k3];
      v = v + b0 * As[k0] + b1 * As[k1] + b2 * As[k2] + b3 * As[k3];
    } else {
      for (std::size_t k = 0; k < nb; ++k) {
        x.noalias() += terms[k].first * Vs[terms[k].second];
        v.noalias() += terms[k].first * As[terms[k].second];
      }
    }
    if (st_.stiffly_accurate_) a = As[static_cast<std::size_t>(s_ - 1)];
    else accelerate(tn + hs);
  }

  double origin = 0.0;  // the step grid's origin: the last breakpoint passed, or t0

private:
  // Tangent forcing of every tangent column from column 0 at (t, x0, v0, a0), into G's columns
  // (less D ṽ + K w, the parts the caller sets up).
  void tangent_forcing(double t, const double* x0, const double* v0, const double* a0) {
    G.setZero();
    (*tangent_)(t, x0, v0, a0, G.data());
  }

  // ṽ and w = x̃ + g ṽ of stage i, each in one pass over all columns (the sums in the order of the
  // terms, as one accumulation would).
  void stage_predictor(int i, double hs, double g) {
    std::size_t nt = 0;
    for (int j = 0; j < i; ++j) {
      const double c = hs * st_.tab_.a(i, j);
      if (c != 0.0) terms[nt++] = {c, static_cast<std::size_t>(j)};
    }
    const auto& [c0, j0] = terms[0];
    const auto& [c1, j1] = terms[1];
    const auto& [c2, j2] = terms[2];
    switch (nt) {
      case 0:
        vt = v;
        w = x + g * vt;
        break;
      case 1:
        vt = v + c0 * As[j0];
        w = x + c0 * Vs[j0] + g * vt;
        break;
      case 2:
        vt = v + c0 * As[j0] + c1 * As[j1];
        w = x + c0 * Vs[j0] + c1 * Vs[j1] + g * vt;
        break;
      case 3:
        vt = v + c0 * As[j0] + c1 * As[j1] + c2 * As[j2];
        w = x + c0 * Vs[j0] + c1 * Vs[j1] + c2 * Vs[j2] + g * vt;
        break;
      default: {
        xt = x;
        vt = v;
        for (std::size_t k = 0; k < nt; ++k) {
          xt.noalias() += terms[k].first * Vs[terms[k].second];
          vt.noalias() += terms[k].first * As[terms[k].second];
        }
        w = xt + g * vt;
      }
    }
  }

  void stage(int i, double tn, double hs) {
    const auto si = static_cast<std::size_t>(i);
    if (i == 0 && st_.explicit_first_) {
      Vs[0] = v;
      As[0] = a;
      return;
    }
    const double g = hs * st_.tab_.a(i, i);
    const double ti = tn + st_.tab_.c[si] * hs;
    const BandedCholesky& S = g > 0.0 ? st_.newton_.factor(g) : st_.mass_;
    stage_predictor(i, hs, g);
    // (M + g D + g² K) A_i = F − D ṽ − K (x̃ + g ṽ);  V_i = ṽ + g A_i;  X_i = x̃ + g ṽ + g² A_i.
    // The right-hand side is formed and solved in A_i itself.
    MatrixXd& Ai = As[si];
    F.setZero();
    forcing_(ti, F.data());
    ++cnt_.stage_forcings;
    st_.products_.subtract(vt.data(), w.data(), F.data(), Ai.data(), 1);
    S.solve_in_place(Ai.col(0).data());
    ++cnt_.linear_solves;
    Vs[si].col(0) = vt.col(0) + g * Ai.col(0);
    if (m_ > 1) {
      X0 = w.col(0) + (g * g) * Ai.col(0);
      tangent_forcing(ti, X0.data(), Vs[si].col(0).data(), Ai.col(0).data());
      st_.products_.subtract(vt.col(1).data(), w.col(1).data(), G.data(), Ai.col(1).data(), P_);
      S.solve_in_place(Ai.col(1).data(), P_, n_);
      cnt_.linear_solves += P_;
      Vs[si].rightCols(P_) = vt.rightCols(P_) + g * Ai.rightCols(P_);
    }
  }

  const EsdirkStepper& st_;
  const Forcing& forcing_;
  const Sink& sink_;
  const TangentForcing* tangent_;
  const int P_, n_, s_;
  int m_;
  const double h_;
  StepperCounters& cnt_;
  MatrixXd x, v, a, xt, vt, w, G;
  std::vector<MatrixXd> Vs, As;
  // The nonzero coefficients of a stage's (or the step's) sum: (h a_ij or h b_j, j).
  std::vector<std::pair<double, std::size_t>> terms;
  VectorXd F, X0;
};

StepperCounters EsdirkStepper::stream(double t0, double t1, double h, const std::vector<double>& stops_in,
                                      const Forcing& forcing, const Sink& sink, int P, const TangentForcing* tangent,
                                      double tangent_end, const Start* start, double until, StepAnchor anchor,
                                      const InitialState* initial) const {
  if (start) {
    if (P != 0) throw std::invalid_argument("EsdirkStepper: a resumed run steps the state only");
    if (initial) throw std::invalid_argument("EsdirkStepper: a resumed run has its own start");
    if (h != start->h) throw std::invalid_argument("EsdirkStepper: a resumed run must keep its step");
    t0 = start->t;
  }
  if (!(h > 0.0)) throw std::invalid_argument("EsdirkStepper: step must be > 0");
  if (!(t1 > t0)) throw std::invalid_argument("EsdirkStepper: t1 must exceed t0");
  if (P < 0 || (P > 0 && !tangent)) throw std::invalid_argument("EsdirkStepper: tangents need their forcing");
  const std::vector<double> stops = segment_ends(stops_in, t0, t1);

  StepperCounters cnt;
  Sweep sw(*this, forcing, sink, P, tangent, h, cnt);
  sw.origin = t0;
  if (start) {
    sw.resume(*start);
  } else {
    if (initial) sw.set_initial(*initial);
    sw.accelerate(t0);
  }
  sw.record(t0, true);
  if (t0 >= until) return cnt;
  bool tangents_on = sw.has_tangents();
  if (tangents_on && t0 >= tangent_end) {
    sw.drop_tangents();
    tangents_on = false;
  }
  double t = t0;
  for (std::size_t seg = 0; seg < stops.size(); ++seg) {
    const double stop = stops[seg];
    const double snap = 1e-12 * std::max(1.0, std::abs(stop));
    // Steps end at origin + k h: a resumed run continues the original run's count.
    long k = std::max(0L, std::lround((t - sw.origin) / h));
    while (t < stop) {
      io::check_interrupt();  // a SIGINT/SIGTERM ends a long solve at the next step (io/interrupt.h)
      double tnext = sw.origin + static_cast<double>(k + 1) * h;
      if (anchor == StepAnchor::End) {
        // Steps end at stop − j h: the first step of the segment takes the remainder (no
        // micro-step: a remainder within `snap` joins the next full step, as the line below does).
        const double j = std::ceil((stop - t - snap) / h) - 1.0;
        tnext = j > 0.0 ? stop - j * h : stop;
      }
      if (tnext > stop - snap) tnext = stop;  // land on the stop (no micro-step)
      sw.step(t, tnext - t);
      t = tnext;
      ++k;
      ++cnt.steps;
      const bool at_break = t == stop && seg + 1 < stops.size();
      if (at_break) sw.accelerate(std::nextafter(t, -std::numeric_limits<double>::infinity()));  // left limit
      sw.record(t, !at_break);
      if (!at_break && t >= until) return cnt;
      if (tangents_on && t >= tangent_end) {
        sw.drop_tangents();
        tangents_on = false;
      }
      if (at_break) {
        sw.accelerate(t);  // right limit: restart from it
        sw.origin = t;
        sw.record(t, true);
        if (t >= until) return cnt;
      }
    }
    sw.origin = t;
  }
  return cnt;
}

}  // namespace scoleid::identify
