#pragma once
// A planar Euler–Bernoulli beam as a Hencky bar chain in Simbody (docs/theory.md §2, §9).
//
//   rho_A w_tt + (c w_sst)_ss + (EI(s) w_ss)_ss = loads,  c = 2 zeta sqrt(rho_A EI),  s in [0, L]
//
// The beam lies along ground x from the origin and deflects along ground y (w > 0 along +y, the
// way a positive force pushes); rotations are about ground z (slope w_s > 0 counter-clockwise).
// n rigid segments of length h = L/n, each carrying mass rho_A h at its centre and rotary
// inertia rho_A h^3/12, are joined by Pin mobilizers with the Hencky joint spring-dampers of
// hencky.h. Ends:
//   left  pinned: Pin to ground, no spring; clamped: Pin to ground with the end spring (2EI/h);
//         free: Planar mobilizer (x, y, rotation) to ground.
//   right pinned: roller, Constraint::PointInPlane (tip stays on y = 0, slides along x);
//         clamped: the same plus an AnchorSpring on the last segment; free: nothing.
// A tip mass sits at s = L; with rotary inertia it is a body on a Pin at s = L carrying the
// end-cell spring 2EI/h (the free-end Hencky treatment, which keeps the tip rotation O(h^2)).
// Valid for small rotations in the sense of the PDE; the chain itself is geometrically exact.
#include "scoleid/io/scenario.h"
#include "scoleid/model/structure.h"

namespace scoleid::model {

class BeamChain : public Structure {
public:
  BeamChain(const io::BeamSpec& beam, int segments);
  std::string kind() const override { return "beam"; }
  SimTK::MobilizedBodyIndex reference_body() const override { return SimTK::GroundIndex; }
  const HenckyLumping& lumping() const { return lumping_; }

private:
  HenckyLumping lumping_;
};

}  // namespace scoleid::model
