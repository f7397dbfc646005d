#pragma once
// Scenario inputs applied to a Structure as one Simbody force element.
//
// Each input is f(t) times a fixed direction d_R given in the reference body R (ground for a
// beam, the shuttle frame for SCOLE — so a shuttle moment about its roll axis follows the
// shuttle through a slew):
//   force  at a station P of body B: F_G = f(t) R_GR d_R applied at P (beam: d = +y);
//   moment on body B:                M_G = f(t) R_GR d_R (beam: d = +z);
//   actuatorK force: generalized force f(t) d_x on the x slider and f(t) d_y on the y slider of
//   proof mass K: it pushes the proof mass and reacts on the mast (internal). With a servo lag
//   (scole.actuator_lag τ > 0) f is not the commanded force but its lagged copy (LaggedSignal).
// Time functions come from io::Signal, so the identifier applies bit-identical inputs (truth.csv
// records the commanded force, lagged or not: the identifier's input).
#include <memory>
#include <string>
#include <vector>

#include <Simbody.h>

#include "scoleid/io/scenario.h"
#include "scoleid/model/structure.h"

namespace scoleid::model {

// The force that reaches a proof mass through its servo: the output of the first-order lag
//   τ ḟ + f = g(t),   f(0) = g(0),
// g = f_cmd the commanded force (io::Signal), τ = scole.actuator_lag > 0. g is a known function
// of time, so f is too: it is computed once, at setup, not integrated as a state (the trapezoidal
// rule and the linearisation see q and u only).
//
// Grid: every breakpoint of g in (0, t_end) is a node (g or g' jumps there; f is continuous, ḟ
// jumps, so the integrators still stop there). Between breakpoints, g is replaced on each
// interval [t_k, t_k + H] by the quadratic g_0 + s_1 x + s_2 x² through g(t_k), g(t_k + H/2) and
// g((t_k + H)−) (the left limit), and the lag equation is integrated exactly across it:
//   f(t_k + x) = e f_k + (1 − e) g_0 + τ s_1 I_1(z) + τ² s_2 I_2(z),   z = x/τ, e = exp(−z),
//   I_1 = z − (1 − e),  I_2 = z² − 2 I_1
// (the convolution of the quadratic with the kernel e^{−x/τ}/τ; 1 − e by expm1). The same formula
// evaluates f between nodes, so f is exact for a piecewise-quadratic g at any H/τ: the grid
// resolves g, not τ. H is the whole interval where g is piecewise linear (step, pulse, bang-bang,
// table) and 1/kNodesPerScale of the shortest time scale of the smooth terms active there (a sine's
// or chirp's period at its highest frequency, a haversine's width) otherwise; the quadratic then
// matches g to |g'''| H³/(72√3), 1.6e-8 of a sine's amplitude and 8e-9 of a haversine's, and f,
// g averaged by a positive kernel of unit area, to no worse. Queries beyond t_end (a simulate()
// past simulation.duration) march on from the last node with the same rule.
class LaggedSignal {
public:
  static constexpr int kNodesPerScale = 500;
  static constexpr double kMaxNodes = 1.0e7;   // 80 MB of node values
  // InputError (naming `source` and `field`) when the grid would exceed kMaxNodes.
  LaggedSignal(io::Signal command, double tau, double t_end, const std::string& source = "",
               const std::string& field = "");
  double operator()(double t) const;
  double tau() const { return tau_; }
  std::size_t nodes() const { return f_.size(); }

private:
  struct Segment {
    double a = 0.0, b = 0.0, h = 0.0;  // [a, b] in n equal intervals of h
    std::size_t n = 1, first = 0;      // f_[first + k] = f(a + k h), k = 0..n
  };
  // Segments of [t0, t1], breakpoints of g as their ends.
  std::vector<Segment> segments(double t0, double t1) const;
  // f at t0 + x from f0 = f(t0), g quadratic on [t0, t1] (its left limit at t1 if at_break).
  double advance(double f0, double t0, double t1, bool at_break, double x) const;

  io::Signal g_;
  double tau_;
  std::vector<double> breakpoints_;
  std::vector<Segment> segs_;
  std::vector<double> f_;
};

struct AppliedInput {
  enum class Kind { Force, Moment, Slider };
  Kind kind = Kind::Force;
  io::Signal signal;
  std::shared_ptr<const LaggedSignal> lagged;  // Slider with a servo lag: the force applied
  Station station;              // Force/Moment: body and point
  SimTK::Vec3 d_R{0.0};         // direction in R
  SimTK::MobilizedBodyIndex slider_x, slider_y;  // Slider
};

// Resolves the scenario's inputs on the structure; InputError (naming the field) if one cannot
// be applied (e.g. an actuator on a beam, a force along the mast axis of an actuator).
std::vector<AppliedInput> resolve_inputs(const io::Scenario& scenario, const Structure& structure);

class InputForces : public SimTK::Force::Custom::Implementation {
public:
  InputForces(const SimTK::SimbodyMatterSubsystem& matter, SimTK::MobilizedBodyIndex reference,
              std::vector<AppliedInput> inputs);
  void calcForce(const SimTK::State& state, SimTK::Vector_<SimTK::SpatialVec>& body_forces,
                 SimTK::Vector_<SimTK::Vec3>& particle_forces,
                 SimTK::Vector& mobility_forces) const override;
  SimTK::Real calcPotentialEnergy(const SimTK::State&) const override { return 0.0; }

private:
  const SimTK::SimbodyMatterSubsystem& matter_;
  SimTK::MobilizedBodyIndex reference_;
  std::vector<AppliedInput> inputs_;
};

}  // namespace scoleid::model
