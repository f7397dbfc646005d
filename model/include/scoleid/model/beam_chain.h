#pragma once
// A planar Euler–Bernoulli beam as a Hencky bar chain in Simbody (docs/theory.md §2, §9).
//
//   rho_A w_tt - (d(s) w_st)_s + (c_kv w_sst)_ss + (EI(s) w_ss)_ss = loads,  s in [0, L]
//   d(s) = 2 zeta sqrt(rho_A EI(s))   square-root (Chen–Russell) damping, zeta dimensionless
//   c_kv                              Kelvin–Voigt coefficient, one value for the whole beam
//
// The beam lies along ground x from the origin and deflects along ground y (w > 0 along +y, the
// way a positive force pushes); rotations are about ground z (slope w_s > 0 counter-clockwise).
// n rigid segments of length h = L/n, each carrying mass rho_A h at its centre and rotary
// inertia rho_A h^3/12, are joined by Pin mobilizers with the Hencky joint spring-dampers of
// hencky.h (joint springs from EI, joint dampers from c_kv). Chen–Russell damping: the dissipation
// 1/2 integral d w_st^2 ds, with each bar's slope its rotation angle theta_i, is 1/2 D_i omega_i^2
// per bar, D_i = integral of d(s) over the bar (exact for piecewise EI: the bar's share of each
// section it overlaps); each bar gets the torque -D_i omega_i about ground z (omega_i its absolute
// angular velocity; the beam is grounded), an AnchorSpring with k = 0. A tip body is not a bar
// and gets none. The lumping error of both laws is O(h^2) (docs/theory.md §9.2). Ends:
//   left  pinned: Pin to ground, no spring; clamped: Pin to ground with the end spring (2EI/h);
//         free: Planar mobilizer (x, y, rotation) to ground.
//   right pinned: roller, Constraint::PointInPlane (tip stays on y = 0, slides along x);
//         clamped: the same plus an AnchorSpring on the last segment; free: nothing.
// A tip mass sits at s = L; with rotary inertia it is a body on a Pin at s = L carrying the
// end-cell spring 2EI/h (the free-end Hencky treatment, which keeps the tip rotation O(h^2)).
// Point elements (supports and attachments, docs/theory.md §2.5) ride on the bar holding their
// station: a mass at its point of the bar, a rotary inertia added to the bar's; a grounded
// translational spring-dashpot a PointSpring at that point (joint_forces.h). A rotational one at an
// end acts in series with the end cell's joint spring (the Pin's spring at the left end, an
// AnchorSpring on the last bar or on the tip body at the right); at an interior station it is an
// AnchorSpring on its bar, whose angle is the bar's mean slope (O(h), where the element's own
// rotation is the slope at its station).
// Valid for small rotations in the sense of the PDE; the chain itself is geometrically exact.
#include <map>
#include <memory>
#include <string>

#include "scoleid/io/scenario.h"
#include "scoleid/model/structure.h"

namespace scoleid::model {

// The rotational springs of the point elements at an end (0: s = 0, 1: s = L), summed, and the
// joint stiffness they make in series with the end cell's k0 (0 when there are none).
double end_rotational_spring(const io::BeamSpec& beam, int end);
double end_series_stiffness(const io::BeamSpec& beam, int end, double k0);

class BeamChain : public Structure {
public:
  BeamChain(const io::BeamSpec& beam, int segments);
  io::Structure kind() const override { return io::Structure::Beam; }
  bool planar() const override { return true; }
  SimTK::MobilizedBodyIndex reference_body() const override { return SimTK::GroundIndex; }
  const HenckyLumping& lumping() const { return lumping_; }
  Station attachment_station(const std::string& name) const override;
  void resolve_strain(const io::SensorSpec& se, ResolvedSensor& r) const override;

private:
  io::BeamSpec beam_;
  HenckyLumping lumping_;
  std::map<std::string, Station> lumped_;  // each lumped attachment's mass (its Slider body)
};

// The truth's beam (truth_run.cpp's registry row).
std::unique_ptr<Structure> make_beam_chain(const io::Scenario& sc, int segments);

}  // namespace scoleid::model
