#pragma once
// Joint spring-dampers of a lumped chain, as one Simbody force element.
//
// Each JointSpring acts on one mobility (a joint rotation q with speed u = qdot, as for Pin and
// Gimbal mobilizers): generalized force f = -k q - c u, potential energy 1/2 k q^2. Mobility
// forces are internal: they act equally and oppositely on the two bodies of the joint, so they
// conserve the system's linear and angular momentum. A PointSpring ties a body's station to
// ground along y, or to another body's station (a lumped attachment's mass on its spring). An AnchorSpring ties a planar body's
// absolute rotation about ground z to zero (a clamped end that is not the chain's root):
// torque -k theta - c omega_z on the body. A RelativeDamper damps a body's angular velocity
// relative to a reference body, per axis of the reference frame: torque -R_GR diag(c) R_GR^T
// (omega_B - omega_R) on the body and its opposite on the reference (a torque pair: momentum
// conserved; docs/theory.md §9.3 uses it for the mast's square-root damping).
#include <mutex>
#include <vector>

#include <Simbody.h>

#include "scoleid/model/structure.h"

namespace scoleid::model {

struct AnchorSpring {
  SimTK::MobilizedBodyIndex body;
  double k = 0.0;
  double c = 0.0;
};

// A translational spring-dashpot from a body's station to ground along ground y (a planar
// structure's grounded spring at a point, docs/theory.md §2.5): force (0, -k y - c v_y, 0) at the
// station, y and v_y its ground position and velocity along y; potential energy 1/2 k y^2. With
// `other` valid, y and v_y are taken relative to the other body's station (ground y of the one
// less the other's), and the opposite force acts there: a spring-dashpot between two bodies along y.
struct PointSpring {
  SimTK::MobilizedBodyIndex body;
  SimTK::Vec3 station{0.0};  // in the body's frame
  double k = 0.0;
  double c = 0.0;
  SimTK::MobilizedBodyIndex other;  // invalid: ground
  SimTK::Vec3 other_station{0.0};
};

// A rotational spring-dashpot between two planar bodies: torque −k (θ_B − θ_O) − c (ω_B − ω_O)
// about ground z on `body` and its opposite on `other` (θ each body's angle about ground z): a
// clamped joint that closes a loop (a frame's column head in its floor block).
struct RelativeSpring {
  SimTK::MobilizedBodyIndex body, other;
  double k = 0.0;
  double c = 0.0;
};

struct RelativeDamper {
  SimTK::MobilizedBodyIndex body, reference;
  SimTK::Vec3 c{0.0};  // about the reference frame's x, y, z axes
};

class JointForces : public SimTK::Force::Custom::Implementation {
public:
  JointForces(const SimTK::SimbodyMatterSubsystem& matter, std::vector<JointSpring> joints,
              std::vector<AnchorSpring> anchors, std::vector<RelativeDamper> relative = {},
              std::vector<PointSpring> points = {}, std::vector<RelativeSpring> relative_springs = {});
  void calcForce(const SimTK::State& state, SimTK::Vector_<SimTK::SpatialVec>& body_forces,
                 SimTK::Vector_<SimTK::Vec3>& particle_forces,
                 SimTK::Vector& mobility_forces) const override;
  SimTK::Real calcPotentialEnergy(const SimTK::State& state) const override;

private:
  // Each joint's q and u as places in the matter subsystem's q and u vectors, found once from the
  // first state (the topology fixes them): a mobilizer looked up per joint per evaluation costs
  // more than the spring it carries.
  void index_joints(const SimTK::State& state) const;
  mutable std::once_flag indexed_;
  mutable std::vector<int> q_at_, u_at_;

  const SimTK::SimbodyMatterSubsystem& matter_;
  std::vector<JointSpring> joints_;
  std::vector<AnchorSpring> anchors_;
  std::vector<RelativeDamper> relative_;
  std::vector<PointSpring> points_;
  std::vector<RelativeSpring> relative_springs_;
};

}  // namespace scoleid::model
