#pragma once
// The planar frame of docs/theory.md §2.6 as Hencky bar chains in Simbody (§9).
//
// The frame stands along ground x (heights s, from the origin) and sways along ground y; every
// rotation is about ground z. Column c of every storey stands at y = c·bay. Storey k's columns
// are chains of m rigid bars of length h_k/m (hencky.h: mass ρA·h at the centre, rotary inertia
// ρA h³/12, joint springs EI_k/h between bars and 2EI_k/h at both clamped ends; Kelvin–Voigt
// joint dampers τ times the springs; square-root damping the bars' torques −D_i ω_i, as on a
// beam). The first column of a storey is a tree: its foot on a Pin to the floor below (the ground
// for storey 1), its head carrying the floor block k on a Pin (both with the clamped-end spring).
// Every other column's foot is a Pin to the floor below with its spring; its head is closed onto
// the floor block by two Constraint::PointInPlane (the column's end point stays on the floor's
// point along the floor's x and y: a loop closure) and the clamped-end spring between head bar
// and floor (a torque pair on the two bodies' angles). The floor block carries its mass at the
// middle of the columns' span, with the rotary inertia of a block `columns·bay` wide.
// The chains are inextensible and geometrically exact: the frame's own small-rotation linear
// model (§2.6) is the limit this converges to, O(1/m²).
#include <vector>

#include "scoleid/io/scenario.h"
#include "scoleid/model/structure.h"

namespace scoleid::model {

class FrameSystem : public Structure {
public:
  // `segments` along the whole height; each storey gets its share, at least 2.
  FrameSystem(const io::FrameSpec& frame, int segments);
  io::Structure kind() const override { return io::Structure::Frame; }
  bool planar() const override { return true; }
  io::Site planar_site() const override { return io::Site::Frame; }
  SimTK::MobilizedBodyIndex reference_body() const override { return SimTK::GroundIndex; }
  // The point at height s of the first column.
  Station station_at(double s) const override;
  double centre_coordinate(double s) const override;
  std::string segment_name(int i) const override;
  const std::vector<SimTK::MobilizedBodyIndex>& floors() const { return floors_; }

private:
  std::vector<double> base_;          // storey k's foot height, k = 0..n
  std::vector<int> storey_segments_;  // bars per column in storey k
  std::vector<SimTK::MobilizedBodyIndex> floors_;
};

// The truth's frame (truth_run.cpp's registry row).
std::unique_ptr<Structure> make_frame_system(const io::Scenario& sc, int segments);

}  // namespace scoleid::model
