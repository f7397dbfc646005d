#pragma once
// Scenario inputs applied to a Structure as one Simbody force element.
//
// Each input is f(t) times a fixed direction d_R given in the reference body R (ground for a
// beam, the shuttle frame for SCOLE — so a shuttle moment about its roll axis follows the
// shuttle through a slew):
//   force  at a station P of body B: F_G = f(t) R_GR d_R applied at P (beam: d = +y);
//   moment on body B:                M_G = f(t) R_GR d_R (beam: d = +z);
//   actuatorK force: generalized force f(t) d_x on the x slider and f(t) d_y on the y slider of
//   proof mass K: it pushes the proof mass and reacts on the mast (internal).
// Time functions come from io::Signal, so the identifier applies bit-identical inputs.
#include <string>
#include <vector>

#include <Simbody.h>

#include "scoleid/io/scenario.h"
#include "scoleid/model/structure.h"

namespace scoleid::model {

struct AppliedInput {
  enum class Kind { Force, Moment, Slider };
  Kind kind = Kind::Force;
  io::Signal signal;
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
