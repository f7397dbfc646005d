#pragma once
// Sensor read-outs of a Structure (docs/theory.md §9.4), all measured in the reference body R (ground for
// a beam, the shuttle for SCOLE) along the sensor's unit direction d_R:
//   displacement   (p_RP - p_RP0) . d          P the station, p_RP0 its undeformed position
//                  (beam: w(s) along +y)
//   rotation       theta_RB . d                theta the rotation vector (angle * axis) of the
//                  body B relative to R (beam: the slope w_s, about +z). A segment's rotation
//                  is the continuum's at its centre to O(h^2), so a station's rotation is
//                  interpolated linearly between the two nearest segment centres (between the
//                  last centre and the tip body, which carries the end cell, near a free end
//                  with one; the end segment's alone within h/2 of an end otherwise).
//   velocity       (d/dt in R of p_RP) . d     (beam: w_t)
//   acceleration   a_GP expressed in R, . d    inertial, as an accelerometer reads it (no
//                  gravity in orbit; beam: w_tt)
//   line_of_sight  the angle, about d, through which the line from the mast root to the point
//                  (the feed-to-reflector line) has turned in R: (u0 x u) . d, u unit vectors.
//   strain         (beams) −offset · M(s) / EI(s): the bending moment at joint j of the chain is
//                  its spring's k_j φ_j (φ_j the relative rotation of the bodies it joins, the
//                  clamped end's against ground; pinned and free ends carry none), k_j φ_j =
//                  EI w_ss(s_j) to O(h²) (hencky.h), and M is linear between the two joints
//                  around s (exact for point loads between them).
//   relative_displacement  (beams) the displacement read-out at `location` less the one at
//                  `reference`: a transducer between two stations, w(s) − w(s_ref).
// Shuttle sensors ("at: shuttle") measure the shuttle itself in ground: CM displacement and the
// attitude rotation vector relative to its initial orientation.
// d need not be an axis: every read-out is linear in d (a projection onto it, or the rotation
// vector's component along it), so a misaligned sensor (truth.overrides.sensors direction) reads
// d_x y_x + d_y y_y + d_z y_z of the axis read-outs.
// The truth's sensor errors (truth.overrides.sensors bias, drift) are not part of the read-out
// (which stays the ideal, noise-free quantity): run_truth adds sensor_error() to it, before noise.
// Every read-out needs the state realized to Stage::Acceleration (for acceleration) or Velocity.
#include <string>
#include <vector>

#include <Simbody.h>

#include "scoleid/io/scenario.h"
#include "scoleid/model/structure.h"

namespace scoleid::model {

struct ResolvedSensor {
  io::SensorKind kind = io::SensorKind::Displacement;
  Station station;
  SimTK::MobilizedBodyIndex second;      // rotation: (1 - w) rot(station.body) + w rot(second)
  double weight = 0.0;
  SimTK::Vec3 d_R{0.0};
  SimTK::MobilizedBodyIndex reference;   // R
  SimTK::Vec3 root_R{0.0};               // for line_of_sight
  // strain: the two joints around s, each M = k (θ(b) − θ(a)) (an invalid body: ground, θ = 0),
  // M(s) = (1 − weight) M_0 + weight M_1, and the read-out scale · M(s), scale = −offset / EI(s).
  struct Joint {
    SimTK::MobilizedBodyIndex a, b;
    double k = 0.0;
  };
  Joint joints[2];
  double scale = 0.0;
  Station apart;  // relative_displacement: the station at `reference`, read like `station`, subtracted
};

std::vector<ResolvedSensor> resolve_sensors(const io::Scenario& scenario, const Structure& structure);

// Sensor value in the given state (realized to Acceleration when any sensor is an
// accelerometer, else Velocity).
double read_sensor(const SimTK::SimbodyMatterSubsystem& matter, const SimTK::State& state,
                   const ResolvedSensor& sensor);

// The truth's error of sensor `s` at time t, in its unit: bias + drift·t (io::SensorSpec).
inline double sensor_error(const io::SensorSpec& s, double t) { return s.bias + s.drift * t; }

}  // namespace scoleid::model
