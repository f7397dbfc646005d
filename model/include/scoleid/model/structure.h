#pragma once
// A structure built in Simbody: the multibody system plus the map from the scenario's
// vocabulary (arc position s, "shuttle", "reflector", "actuatorK") to bodies and stations.
//
// Frames (monogram notation): G ground (inertial), R the reference body in which displacements
// are measured (ground for a beam, the shuttle for SCOLE), B a segment body. A station is a
// point fixed on a body, p_BS; p_RS0 is where it sits in R in the undeformed configuration.
#include <memory>
#include <string>
#include <vector>

#include <Simbody.h>

#include "scoleid/io/scenario.h"
#include "scoleid/io/types.h"
#include "scoleid/model/hencky.h"

namespace scoleid::model {

struct ResolvedSensor;  // sensors.h

struct Station {
  SimTK::MobilizedBodyIndex body;
  SimTK::Vec3 p_BS{0.0};   // station on its body
  SimTK::Vec3 p_RS0{0.0};  // undeformed position in the reference body R
};

// One spring-damper on one mobility (a joint rotation): f = -k q - c u.
struct JointSpring {
  SimTK::MobilizedBodyIndex body;
  int which = 0;
  double k = 0.0;
  double c = 0.0;
};

class Structure {
public:
  Structure() : matter_(system_), forces_(system_) {}
  virtual ~Structure() = default;
  Structure(const Structure&) = delete;
  Structure& operator=(const Structure&) = delete;

  SimTK::MultibodySystem& system() { return system_; }
  const SimTK::MultibodySystem& system() const { return system_; }
  SimTK::SimbodyMatterSubsystem& matter() { return matter_; }
  const SimTK::SimbodyMatterSubsystem& matter() const { return matter_; }
  SimTK::GeneralForceSubsystem& forces() { return forces_; }

  // The scenario's structure kind this system builds.
  virtual io::Structure kind() const = 0;
  // A planar chain (a beam): every load and sensor is at site 'beam', at an arc position, and acts
  // in the chain's plane (its direction implied). Otherwise an assembly in space, where each load
  // and sensor names its site and direction (inputs.h, sensors.h).
  virtual bool planar() const = 0;
  // The time constant of the proof-mass actuators' force lag (inputs.h); 0: none, or no actuators.
  virtual double actuator_lag() const { return 0.0; }
  // The body in which displacements are measured (ground or shuttle).
  virtual SimTK::MobilizedBodyIndex reference_body() const = 0;
  // The site a planar structure's loads and sensors name (beam; a frame's: frame).
  virtual io::Site planar_site() const { return io::Site::Beam; }
  // The point at arc position s on the rigid segment that contains it.
  virtual Station station_at(double s) const;
  // Arc position s as a coordinate that is i at segment i's centre, linear between centres
  // (s/h − 1/2 on a uniform chain; a rotation sensor interpolates the bars' angles by it).
  virtual double centre_coordinate(double s) const { return s / (length_ / segments()) - 0.5; }
  // The lumped mass of a beam's attachment (its own body, moving along w), by the attachment's
  // name; an invalid body if there is none.
  virtual Station attachment_station(const std::string& name) const;
  // Named rigid bodies: the shuttle, the reflector; an invalid index if absent.
  virtual Station named_station(io::Site at) const;
  // A spatial structure's station at a site and its `location` (used where the site is a chain:
  // SCOLE's mast), and whether the site is such a chain (a rotation there is interpolated between
  // its bars). By default every site is a named body.
  virtual Station site_station(io::Site at, double location) const { (void)location; return named_station(at); }
  virtual bool chain_site(io::Site at) const { (void)at; return false; }
  // Slider mobilizers of actuator K (1-based) along reference x and y, or invalid.
  virtual SimTK::MobilizedBodyIndex actuator_slider(int k, int axis) const;
  // The proof-mass actuators: their number and their stroke (the plausibility guard's bound on
  // each slider); 0 and 0 when there are none.
  virtual int actuator_count() const { return 0; }
  virtual double actuator_stroke() const { return 0.0; }
  // A strain gauge at se.location (only kinds that read strain, io::reads): the joints around it
  // and their springs, into r (sensors.h). std::logic_error on a kind without strain.
  virtual void resolve_strain(const io::SensorSpec& se, ResolvedSensor& r) const;
  // Names in the truth's messages: segment i (0-based) of the chain, "beam segment 3 of 80 (s =
  // 0.25 to 0.375)"; the body hinged at the tip; the reference body R ("ground", "shuttle").
  virtual std::string segment_name(int i) const;
  virtual std::string chain_name() const { return "beam"; }
  virtual std::string tip_name() const { return "tip body"; }
  virtual std::string reference_name() const { return "ground"; }

  int segments() const { return static_cast<int>(segment_bodies_.size()); }
  double length() const { return length_; }
  const std::vector<SimTK::MobilizedBodyIndex>& segment_bodies() const { return segment_bodies_; }
  // The body hinged at s = L on the free end's half cell (reflector, beam tip body), or invalid.
  SimTK::MobilizedBodyIndex tip_body() const { return tip_body_; }
  const std::vector<JointSpring>& joint_springs() const { return joint_springs_; }

protected:
  SimTK::MultibodySystem system_;
  SimTK::SimbodyMatterSubsystem matter_;
  SimTK::GeneralForceSubsystem forces_;
  double length_ = 0.0;
  SimTK::Vec3 root_R_{0.0};        // s = 0 in R, undeformed
  SimTK::Vec3 axis_B_{1, 0, 0};    // unit tangent of the chain in every segment frame
  SimTK::Vec3 axis_R_{1, 0, 0};    // the same tangent in R, undeformed
  std::vector<SimTK::MobilizedBodyIndex> segment_bodies_;  // segment i spans [i h, (i+1) h]
  SimTK::MobilizedBodyIndex tip_body_;
  std::vector<JointSpring> joint_springs_;
};

}  // namespace scoleid::model
