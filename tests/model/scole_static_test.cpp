// Static check of the SCOLE mast (docs/theory.md §3): a steady force F along shuttle x at the reflector
// CM, offset r = (r_x, r_y) from the mast tip, loads the cantilever mast with a tip shear F and a
// tip torque T = (r x F)_z = -r_y F. Analytic cantilever, small deflection:
//   mast tip       u_x = F L^3 / (3 EI_pitch),                      u_y = 0
//   reflector CM   u_x = F L^3 / (3 EI_pitch) + F r_y^2 L / GJ,       u_y = -F r_x r_y L / GJ
//   tip torsion    psi = -r_y F L / GJ
//   at s (mid-mast rotation sensors, interpolated between segment centres):
//                  rotation about y = -F (L s - s^2 / 2) / EI_pitch (x deflection turns -y),
//                  torsion psi(s) = -r_y F s / GJ
// F is small (0.1 lb) so that the geometric nonlinearity, O(F^2), stays below 1e-5 relative.
// The shuttle is made 1e6 times heavier so that it stands for the clamp (the inertial relief of
// the free-floating system, (m_mast + m_4)/M, drops to 4e-9). The chain's static tip deflection
// is the trapezoidal rule for the unit-load integral, relative error 1/(2 n^2): second order, as
// the frequencies in hencky_test.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "scoleid/io/scenario.h"
#include "scoleid/model/linearisation.h"
#include "scoleid/model/scole_system.h"
#include "scoleid/model/sensors.h"
#include "scoleid/model/truth_run.h"

using namespace scoleid;
using namespace scoleid::model;

namespace {

const char* kStatic = R"(name: static-scole
structure: scole
scole:
  shuttle: {mass: 6.366e9, Ixx: 9.05443e11, Iyy: 6.7891e12, Izz: 7.086601e12}
inputs:
  - {name: F, at: reflector, kind: force, direction: x, unit: lb, signal: {type: step, amplitude: 0.1}}
sensors:
  - {name: tip_x, at: mast, kind: displacement, location: 130, direction: x}
  - {name: tip_y, at: mast, kind: displacement, location: 130, direction: y}
  - {name: refl_x, at: reflector, kind: displacement, direction: x}
  - {name: refl_y, at: reflector, kind: displacement, direction: y}
  - {name: psi, at: reflector, kind: rotation, direction: z}
  - {name: slope_mid, at: mast, kind: rotation, location: 65, direction: y}
  - {name: psi_mid, at: mast, kind: rotation, location: 65, direction: z}
)";

}  // namespace

TEST(ScoleStatic, SteadyReflectorForceGivesCantileverDeflection) {
  const auto sc = io::parse_scenario(kStatic, "test");
  const auto& c = sc.scole;
  const double F = 0.1, L = c.length, rx = c.reflector_rx, ry = c.reflector_ry;
  const double bend = F * L * L * L / (3 * c.EI_pitch);
  const double sm = 65.0;
  const double expect[7] = {bend, 0.0, bend + F * ry * ry * L / c.GJ, -F * rx * ry * L / c.GJ, -ry * F * L / c.GJ,
                            -F * (L * sm - sm * sm / 2) / c.EI_pitch, -ry * F * sm / c.GJ};

  std::vector<double> errs;
  for (int n : {10, 20, 40}) {
    const auto st = prepare_structure(sc, n);
    SimTK::State s = st->system().getDefaultState();
    s.setTime(1.0);
    // Solve over the mast and reflector rotations (the shuttle's motion and the unsprung proof
    // masses are left out: they carry no static load).
    std::vector<int> mob;
    const auto& scole = static_cast<const ScoleSystem&>(*st);
    std::vector<SimTK::MobilizedBodyIndex> bodies = st->segment_bodies();
    bodies.push_back(scole.reflector());
    st->system().realize(s, SimTK::Stage::Model);
    for (auto b : bodies) {
      const auto& mb = st->matter().getMobilizedBody(b);
      for (int k = 0; k < mb.getNumU(s); ++k) mob.push_back(static_cast<int>(mb.getFirstUIndex(s)) + k);
    }
    const double residual = solve_static_equilibrium(st->system(), s, mob, 30, 1e-12);
    EXPECT_LT(residual, 1e-9) << "n = " << n;
    st->system().realize(s, SimTK::Stage::Acceleration);
    const auto sensors = resolve_sensors(sc, *st);
    double err = 0.0;
    std::printf("n = %2d:", n);
    for (std::size_t i = 0; i < sensors.size(); ++i) {
      const double v = read_sensor(st->matter(), s, sensors[i]);
      std::printf("  %s %.6e (analytic %.6e)", sc.sensors[i].name.c_str(), v, expect[i]);
      const double scale = i >= 4 ? std::abs(expect[i]) : bend;
      err = std::max(err, std::abs(v - expect[i]) / scale);
    }
    std::printf("\n        max relative error %.3e\n", err);
    errs.push_back(err);
  }
  const double rate = std::log2(errs[1] / errs[2]);
  std::printf("rate (20 -> 40) = %.2f\n", rate);
  EXPECT_NEAR(rate, 2.0, 0.2);
  EXPECT_LT(errs[2], 5e-3);   // the frequency tolerance of hencky_test at n = 40
}
