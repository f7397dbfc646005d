// Supports and attachments (docs/theory.md §2.5): the exact transfer-matrix frequencies against
// the closed forms they generalise; the FE model's frequencies against them at the Hermite
// element's fourth order; an attachment at the tip against the tip body; the scenario's checks and
// parameter names.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "scoleid/identify/door/scenario_door.h"
#include "scoleid/identify/fe/analytic_beam.h"
#include "scoleid/identify/fe/modal.h"
#include "scoleid/identify/fe/structure.h"
#include "scoleid/io/error.h"
#include "scoleid/io/scenario.h"
#include "scoleid/io/structure_parameters.h"

using namespace scoleid;
namespace an = scoleid::identify::analytic;

namespace {

// A steel strip on a compliant clamp with three attachments (two of them between nodes of every
// mesh below) and a grounded spring-dashpot.
const char* kBench = R"(
name: bench
beam:
  length: 0.5
  left: pinned
  right: free
  rho_A: 0.589
  EI: 11.25
  zeta: 0.002
  supports: {left: {k_theta: 150, c_theta: 0.01}}
  attachments:
    - {name: clamp, location: 0.4, mass: 0.06, inertia: 2.0e-5}
    - {name: acc_tip, location: 0.45, mass: 0.006}
    - {name: acc_mid, location: 0.25, mass: 0.002}
    - {name: spring, location: 0.3, k_w: 40, c_w: 0.05}
inputs: [{name: F, location: 0.4, signal: {type: haversine, amplitude: 1, t0: 0.01, width: 0.002}}]
sensors: [{name: a_tip, kind: acceleration, location: 0.45}]
simulation: {duration: 0.1, sample_interval: 0.001}
)";

std::vector<double> fe_omegas(const io::Scenario& sc, int elements) {
  const auto st = identify::make_structure(sc, elements);
  const auto a = identify::assemble(st->model(), st->coefficients(sc));
  return identify::natural_frequencies(a.M, a.K);
}

double rel(double a, double b) { return std::abs(a / b - 1.0); }

}  // namespace

TEST(PointElements, TransferMatrixMeetsTheClosedForms) {
  io::BeamSpec b;
  b.length = 2.0;
  b.EI = {500.0};
  b.rho_A = 3.0;
  const double L = b.length, EI = b.EI[0], rA = b.rho_A;
  // Clamped–free, and with a tip body (Blevins' equation, analytic_beam.h).
  b.left = io::EndCondition::Clamped;
  b.right = io::EndCondition::Free;
  // Twenty modes (β L up to 61: the unscaled transfer product would have lost them to cancellation).
  auto w = an::point_element_omegas(b, 20);
  auto bl = an::beta_L(an::Support::ClampedFree, 20);
  ASSERT_EQ(w.size(), 20u);
  for (int k = 0; k < 20; ++k) EXPECT_LT(rel(w[k], an::omega(bl[k], L, EI, rA)), 1e-12) << "mode " << k + 1;
  b.tip_mass = 0.7 * rA * L;
  b.tip_inertia = 0.05 * rA * L * L * L;
  w = an::point_element_omegas(b, 4);
  bl = an::beta_L_tip_mass(0.7, 0.05, 4);
  for (int k = 0; k < 4; ++k) EXPECT_LT(rel(w[k], an::omega(bl[k], L, EI, rA)), 1e-12) << "tip body, mode " << k + 1;
  // The same masses as an attachment at L give the same roots.
  io::BeamSpec c = b;
  c.tip_mass = c.tip_inertia = 0.0;
  io::PointElement tip{"tip", L};
  tip.mass = b.tip_mass;
  tip.inertia = b.tip_inertia;
  c.attachments = {tip};
  const auto wc = an::point_element_omegas(c, 4);
  for (int k = 0; k < 4; ++k) EXPECT_LT(rel(wc[k], w[k]), 1e-12);
  // A pinned end with a root spring: between pinned–free (k_θ → 0: 3.9266, 7.0686, ... are the
  // flexible roots, tan βL = tanh βL) and clamped–free (k_θ → ∞).
  io::BeamSpec p;
  p.length = L;
  p.EI = {EI};
  p.rho_A = rA;
  p.left = io::EndCondition::Pinned;
  p.right = io::EndCondition::Free;
  io::PointElement root{"left", 0.0};
  root.k_theta = 1e9 * EI / L;
  p.supports = {root};
  w = an::point_element_omegas(p, 3);
  bl = an::beta_L(an::Support::ClampedFree, 3);
  for (int k = 0; k < 3; ++k) EXPECT_LT(rel(w[k], an::omega(bl[k], L, EI, rA)), 1e-8) << "stiff root, mode " << k + 1;
  // A soft root spring: the first mode is the pin's rigid rotation on the spring, ω² = k_θ / (ρA L³/3).
  p.supports[0].k_theta = 1e-6 * EI / L;
  w = an::point_element_omegas(p, 2);
  EXPECT_LT(rel(w[0], std::sqrt(p.supports[0].k_theta / (rA * L * L * L / 3.0))), 1e-5);
  EXPECT_LT(rel(w[1], an::omega(3.92660231204792, L, EI, rA)), 1e-6);
}

TEST(PointElements, FiniteElementsConvergeToTheExactFrequenciesAtFourthOrder) {
  const io::Scenario sc = io::parse_scenario(kBench, "bench");
  const auto exact = an::point_element_omegas(sc.beam, 4);
  std::printf("  %8s %14s %14s %14s %14s\n", "elements", "mode 1", "mode 2", "mode 3", "mode 4");
  std::vector<std::vector<double>> err;
  for (int ne : {5, 10, 20, 40}) {
    const auto w = fe_omegas(sc, ne);
    err.emplace_back();
    for (int k = 0; k < 4; ++k) err.back().push_back(w[static_cast<std::size_t>(k)] / exact[static_cast<std::size_t>(k)] - 1.0);
    std::printf("  %8d %14.3e %14.3e %14.3e %14.3e\n", ne, err.back()[0], err.back()[1], err.back()[2], err.back()[3]);
  }
  std::printf("  exact [Hz] %.6f %.6f %.6f %.6f\n", exact[0] / (2 * M_PI), exact[1] / (2 * M_PI), exact[2] / (2 * M_PI),
              exact[3] / (2 * M_PI));
  for (int k = 0; k < 4; ++k) {
    SCOPED_TRACE("mode " + std::to_string(k + 1));
    // Upper bounds (Rayleigh–Ritz with a consistent mass: every element's cubic is a trial field),
    // to the dense eigensolver's floor (modal.h; measured -7e-10 for mode 1 at 40 elements).
    for (const auto& e : err) EXPECT_GT(e[static_cast<std::size_t>(k)], -5e-9);
    EXPECT_LT(std::abs(err.back()[static_cast<std::size_t>(k)]), 5e-6);  // measured <= 2.2e-6 (mode 4)
    // Fourth order between 10 and 20 elements (2⁴ = 16; measured 16.0-16.1), above that floor.
    const double rate = std::log2(err[1][static_cast<std::size_t>(k)] / err[2][static_cast<std::size_t>(k)]);
    EXPECT_NEAR(rate, 4.0, 0.3);
  }
}

TEST(PointElements, AnAttachmentAtTheTipIsTheTipBody) {
  io::Scenario a = io::parse_scenario(R"(
beam: {length: 3, left: clamped, right: free, rho_A: 2, EI: 700, tip_mass: 1.5, tip_inertia: 0.2}
)", "tip body");
  io::Scenario b = io::parse_scenario(R"(
beam: {length: 3, left: clamped, right: free, rho_A: 2, EI: 700,
       attachments: [{name: tip, location: 3, mass: 1.5, inertia: 0.2}]}
)", "attachment");
  const auto wa = fe_omegas(a, 12), wb = fe_omegas(b, 12);
  ASSERT_EQ(wa.size(), wb.size());
  for (std::size_t k = 0; k < 6; ++k) EXPECT_LT(rel(wb[k], wa[k]), 1e-12) << "mode " << k + 1;
}

TEST(PointElements, EveryQuantityIsANamedParameter) {
  const io::Scenario sc = io::parse_scenario(kBench, "bench");
  const auto values = io::structure_parameters(sc);
  EXPECT_EQ(values.at("supports.left.k_theta"), 150.0);
  EXPECT_EQ(values.at("supports.left.c_theta"), 0.01);
  EXPECT_EQ(values.at("attachments.clamp.mass"), 0.06);
  EXPECT_EQ(values.at("attachments.clamp.inertia"), 2e-5);
  EXPECT_EQ(values.at("attachments.spring.k_w"), 40.0);
  EXPECT_EQ(values.count("attachments.spring.mass"), 0u);  // only what an element holds
  // Set back by name (a truth.json's true values).
  io::Scenario t = sc;
  io::set_structure_parameters(t, {{"supports.left.k_theta", 99.0}, {"attachments.acc_tip.mass", 0.01}});
  EXPECT_EQ(t.beam.supports[0].k_theta, 99.0);
  EXPECT_EQ(t.beam.attachments[1].mass, 0.01);
  // Estimable: the identifier's parameterisation knows them, the start from identification.initial.
  std::string y = std::string(kBench) +
                  "identification: {estimate: [EI, rho_A, supports.left.k_theta, attachments.clamp.mass],"
                  " initial: {supports.left.k_theta: 100, attachments.clamp.mass: 0.05}, elements: 8}\n";
  const io::Scenario e = io::parse_scenario(y, "estimate");
  const auto st = identify::make_structure(e, 8);
  const auto p = st->parameterize(e);
  ASSERT_EQ(p->names().size(), 4u);
  EXPECT_EQ(p->names()[2], "supports.left.k_theta");
  EXPECT_DOUBLE_EQ(p->initial()[2], 100.0);
  EXPECT_DOUBLE_EQ(p->initial()[3], 0.05);
  EXPECT_DOUBLE_EQ(p->truth()[3], 0.06);
  // The coefficients follow the parameter (∂c/∂q a unit column on its own coefficient).
  identify::VectorXd c;
  identify::MatrixXd dcdq;
  p->coefficients(p->initial(), c, dcdq);
  EXPECT_DOUBLE_EQ(dcdq.col(3).sum(), 1.0);
  EXPECT_DOUBLE_EQ(dcdq.col(3).cwiseAbs().maxCoeff(), 1.0);
}

TEST(PointElements, BadInputNamesTheField) {
  auto refused = [](const std::string& beam_extra, const std::string& field, const std::string& beam_ends = "left: pinned, right: free") {
    const std::string y = "beam: {length: 1, " + beam_ends + ", rho_A: 1, EI: 10, " + beam_extra + "}\n";
    try {
      io::parse_scenario(y, "s.yaml");
      ADD_FAILURE() << "accepted: " << beam_extra;
    } catch (const io::InputError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("s.yaml"), std::string::npos) << m;
      EXPECT_NE(m.find(field), std::string::npos) << m;
    }
  };
  // A spring on what the end holds: a clamped end's slope, a pinned end's displacement.
  refused("supports: {left: {k_theta: 5}}", "beam.supports.left.k_theta", "left: clamped, right: free");
  refused("supports: {left: {k_w: 5}}", "beam.supports.left.k_w");
  refused("attachments: [{name: a, location: 0, k_w: 5}]", "beam.attachments[0].k_w");
  refused("attachments: [{name: a, location: 0, mass: 0.1}]", "beam.attachments[0].mass");  // on the held w(0)
  refused("attachments: [{name: a, location: 1, inertia: 0.1}]", "beam.attachments[0].inertia", "left: pinned, right: clamped");
  refused("supports: {middle: {k_w: 5}}", "beam.supports.middle");
  refused("supports: {left: {mass: 5}}", "beam.supports.left.mass");
  refused("attachments: [{name: a, location: 1.5, mass: 0.1}]", "beam.attachments[0].location");
  refused("attachments: [{name: a, location: 0.5}]", "beam.attachments[0]");
  refused("attachments: [{name: a, location: 0.5, mass: -1}]", "beam.attachments[0].mass");
  refused("attachments: [{location: 0.5, mass: 1}]", "beam.attachments[0].name");
  refused("attachments: [{name: a.b, location: 0.5, mass: 1}]", "beam.attachments[0].name");
  refused("attachments: [{name: a, location: 0.5, mass: 1}, {name: a, location: 0.6, mass: 1}]", "beam.attachments[1].name");
  refused("attachments: [{name: a, location: 0.5, mas: 1}]", "beam.attachments[0].mas");
  // An unknown estimate lists the point elements' names among the known ones.
  try {
    io::Scenario sc = io::parse_scenario(
        "beam: {length: 1, left: pinned, right: free, rho_A: 1, EI: 10, supports: {left: {k_theta: 5}}}\n"
        "identification: {estimate: [EI, supports.left.k_w]}\n",
        "s.yaml");
    identify::check_parameters(*identify::make_structure(sc, 4), sc);
    ADD_FAILURE() << "supports.left.k_w (not held) accepted";
  } catch (const io::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("supports.left.k_theta"), std::string::npos) << e.what();
  }
}

TEST(PointElements, TrueValuesAndCoefficientsComeFromTheScenarioGiven) {
  // The model's mesh built from the scenario; its parameterisation and coefficients asked with the
  // truth's (truth.overrides): the truth's values, not the mesh's.
  const std::string y = std::string(kBench) +
                        "identification: {estimate: [EI, attachments.clamp.mass], elements: 8}\n"
                        "truth:\n  overrides:\n    beam:\n      attachments: [{name: clamp, mass: 0.07}]\n";
  const io::Scenario sc = io::parse_scenario(y, "override");
  const io::Scenario t = io::truth_scenario(sc);
  const auto st = identify::make_structure(sc, 8);
  EXPECT_DOUBLE_EQ(st->parameterize(t)->truth()[1], 0.07);
  EXPECT_DOUBLE_EQ(st->parameterize(sc)->truth()[1], 0.06);
  const auto c = st->coefficients(t), c0 = st->coefficients(sc);
  int changed = 0;
  for (Eigen::Index i = 0; i < c.size(); ++i)
    if (c[i] != c0[i]) {
      ++changed;
      EXPECT_DOUBLE_EQ(c[i], 0.07);
      EXPECT_DOUBLE_EQ(c0[i], 0.06);
    }
  EXPECT_EQ(changed, 1);
}

TEST(PointElements, TruthOverridesReplaceFieldsByName) {
  const std::string y = std::string(kBench) +
                        "truth:\n  overrides:\n    beam:\n      supports: {left: {k_theta: 120}}\n"
                        "      attachments: [{name: clamp, mass: 0.07}]\n";
  const io::Scenario sc = io::parse_scenario(y, "override");
  const io::Scenario t = io::truth_scenario(sc);
  EXPECT_EQ(t.beam.supports[0].k_theta, 120.0);
  EXPECT_EQ(t.beam.supports[0].c_theta, 0.01);
  EXPECT_EQ(t.beam.attachments[0].mass, 0.07);
  EXPECT_EQ(t.beam.attachments[0].location, 0.4);
  EXPECT_EQ(sc.beam.attachments[0].mass, 0.06);
  // The scenario written out and read back is the same scenario.
  EXPECT_TRUE(io::has_truth_overrides(sc));
  try {
    io::truth_scenario(io::parse_scenario(std::string(kBench) +
                                              "truth:\n  overrides:\n    beam:\n      attachments: [{name: nobody, mass: 0.07}]\n",
                                          "override"));
    ADD_FAILURE() << "an override of an attachment the scenario lacks accepted";
  } catch (const io::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("truth.overrides.beam.attachments[0].name"), std::string::npos) << e.what();
  }
}

// A lumped attachment (a mass on a spring, its own degree of freedom): the exact roots against
// their two limits — a coupling spring far stiffer than the beam makes the mass ride on w(s) (an
// attached mass, the ground spring a k_w there); a coupling far softer leaves the bare beam's
// modes and adds the mass's own, ω² = (k_l + k_g)/m_l.
TEST(PointElements, ALumpedAttachmentMeetsItsStiffAndSoftLimits) {
  io::BeamSpec b;
  b.length = 2.0;
  b.EI = {500.0};
  b.rho_A = 3.0;
  b.left = io::EndCondition::Clamped;
  b.right = io::EndCondition::Free;
  const double L = b.length, EI = b.EI[0];
  io::PointElement lumped{"shaker", 1.3};
  lumped.lumped_mass = 0.8;
  lumped.lumped_k_ground = 40.0;
  lumped.lumped_k = 1e10 * EI / (L * L * L);
  io::PointElement rigid{"shaker", 1.3};
  rigid.mass = 0.8;
  rigid.k_w = 40.0;
  io::BeamSpec s = b, r = b;
  s.attachments = {lumped};
  r.attachments = {rigid};
  const auto ws = an::point_element_omegas(s, 4), wr = an::point_element_omegas(r, 4);
  for (int k = 0; k < 4; ++k) EXPECT_LT(rel(ws[static_cast<std::size_t>(k)], wr[static_cast<std::size_t>(k)]), 1e-8) << "stiff, mode " << k + 1;
  // Soft: k_l + k_g = 0.8 · 30² puts the mass's own mode at 30 rad/s, between the bare beam's first
  // two (about 10.2 and 64 rad/s); k_l = 1e-6 of it barely couples.
  s.attachments[0].lumped_k_ground = 0.8 * 900.0 * (1 - 1e-6);
  s.attachments[0].lumped_k = 0.8 * 900.0 * 1e-6;
  const auto soft = an::point_element_omegas(s, 4), bare = an::point_element_omegas(b, 3);
  EXPECT_LT(rel(soft[0], bare[0]), 1e-6);
  EXPECT_LT(rel(soft[1], 30.0), 1e-6);
  EXPECT_LT(rel(soft[2], bare[1]), 1e-6);
  EXPECT_LT(rel(soft[3], bare[2]), 1e-6);
}

// The FE model with a lumped attachment (its DOF after the beam's) against the exact roots: upper
// bounds, within 5e-6 at 40 elements, fourth order in the modes the beam's field carries.
TEST(PointElements, ALumpedAttachmentConvergesAtFourthOrder) {
  std::string y = kBench;
  const std::string at = "    - {name: spring, location: 0.3, k_w: 40, c_w: 0.05}\n";
  y.replace(y.find(at), at.size(),
            at + "    - {name: shaker, location: 0.35, lumped_mass: 0.02, lumped_k: 2000, lumped_c: 0.1, lumped_k_ground: 50}\n");
  const io::Scenario sc = io::parse_scenario(y, "bench");
  const auto exact = an::point_element_omegas(sc.beam, 5);
  ASSERT_EQ(exact.size(), 5u);
  std::printf("  exact [Hz]");
  for (double w : exact) std::printf(" %.6f", w / (2 * M_PI));
  std::printf("\n");
  std::vector<std::vector<double>> err;
  for (int ne : {5, 10, 20, 40}) {
    const auto st = identify::make_structure(sc, ne);
    EXPECT_EQ(st->model().ndof, 2 * ne + 1 + 1) << "the pinned root leaves 2 ne + 1 beam DOFs, and the lumped mass one";
    const auto w = fe_omegas(sc, ne);
    err.emplace_back();
    std::printf("  %3d", ne);
    for (int k = 0; k < 5; ++k) {
      err.back().push_back(w[static_cast<std::size_t>(k)] / exact[static_cast<std::size_t>(k)] - 1.0);
      std::printf(" %12.3e", err.back().back());
    }
    std::printf("\n");
  }
  for (int k = 0; k < 5; ++k) {
    SCOPED_TRACE("mode " + std::to_string(k + 1));
    for (const auto& e : err) EXPECT_GT(e[static_cast<std::size_t>(k)], -5e-9);
    EXPECT_LT(std::abs(err.back()[static_cast<std::size_t>(k)]), 5e-6);
    if (err[1][static_cast<std::size_t>(k)] > 1e-6) { EXPECT_NEAR(std::log2(err[1][static_cast<std::size_t>(k)] / err[2][static_cast<std::size_t>(k)]), 4.0, 0.3); }
  }
  // Its four quantities are named, estimable parameters.
  const auto values = io::structure_parameters(sc);
  EXPECT_EQ(values.at("attachments.shaker.lumped_mass"), 0.02);
  EXPECT_EQ(values.at("attachments.shaker.lumped_k"), 2000.0);
  EXPECT_EQ(values.at("attachments.shaker.lumped_c"), 0.1);
  EXPECT_EQ(values.at("attachments.shaker.lumped_k_ground"), 50.0);
}

// A lumped attachment needs its mass and its spring, and a displacement to ride on.
TEST(PointElements, ALumpedAttachmentIsRefusedWithoutItsMassOrSpringOrOnAHeldEnd) {
  auto refused = [](const std::string& attachment, const std::string& field, const std::string& why) {
    const std::string y = "beam: {length: 1, left: pinned, right: free, rho_A: 1, EI: 10, attachments: [" + attachment + "]}\n";
    try {
      io::parse_scenario(y, "s.yaml");
      ADD_FAILURE() << "accepted: " << attachment;
    } catch (const io::InputError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("s.yaml"), std::string::npos) << m;
      EXPECT_NE(m.find(field), std::string::npos) << m;
      EXPECT_NE(m.find(why), std::string::npos) << m;
    }
  };
  refused("{name: a, location: 0.5, lumped_k: 10}", "beam.attachments[0].lumped_mass", "must be > 0");
  refused("{name: a, location: 0.5, lumped_mass: 0.1, lumped_k_ground: 10}", "beam.attachments[0].lumped_k", "must be > 0");
  refused("{name: a, location: 0, lumped_mass: 0.1, lumped_k: 10}", "beam.attachments[0].lumped_mass", "pinned");
  refused("{name: a, location: 0.5, lumped_mass: -1, lumped_k: 10}", "beam.attachments[0].lumped_mass", ">= 0");
  refused("{name: a, location: 0.5, lumped_mass: 1e-24, lumped_k: 10}", "beam.attachments[0].lumped_mass", "1e-12 and 1e12");
  // Its own frequency four decades above the beam's scale (here √10 rad/s): a rigid mass, and a mode no step follows.
  refused("{name: a, location: 0.5, lumped_mass: 1e-6, lumped_k: 1e9}", "beam.attachments[0].lumped_k", "rides rigidly");
  // A support has no lumped attachment (an attachment at the end has).
  try {
    io::parse_scenario("beam: {length: 1, left: pinned, right: free, rho_A: 1, EI: 10, supports: {left: {lumped_k: 5}}}\n", "s.yaml");
    ADD_FAILURE() << "a support's lumped_k accepted";
  } catch (const io::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("beam.supports.left.lumped_k"), std::string::npos) << e.what();
  }
}

// A force on a lumped attachment's own mass (inputs[].attachment: a shaker's drive on its
// armature) reaches the beam through the stinger: statically the beam carries the whole force at
// the station, w(L) = P L³/(3EI) for a tip station, and the mass sits P/k_l beyond it; a force on
// anything but a lumped attachment, or a moment, is refused naming the field.
TEST(PointElements, AForceOnTheArmatureReachesTheBeamThroughTheStinger) {
  const double L = 0.5, EI = 11.25, P = 0.7, kl = 6000;
  const std::string head = R"(structure: beam
beam: {length: 0.5, left: clamped, right: free, rho_A: 0.58875, EI: 11.25,
       attachments: [{name: shaker, location: 0.5, lumped_mass: 0.02, lumped_k: 6000}, {name: acc, location: 0.3, mass: 0.006}]}
sensors: [{name: w, location: 0.5}]
)";
  const io::Scenario sc = io::parse_scenario(head + "inputs: [{name: F, attachment: shaker, kind: force, signal: {type: step, amplitude: 1, t0: 0}}]\n", "a.yaml");
  EXPECT_DOUBLE_EQ(sc.inputs[0].location, 0.5);
  const auto st = scoleid::identify::make_structure(sc, 8);
  const auto& m = st->model();
  const Eigen::VectorXd c = st->coefficients(sc);
  const Eigen::SparseMatrix<double> K = m.assemble(m.stiffness, c);
  const Eigen::VectorXd b = P * m.inputs[0].vector;
  const Eigen::VectorXd u = Eigen::MatrixXd(K).ldlt().solve(b);
  const double w_tip = m.sensors[0].row.dot(u), x_l = u[m.ndof - 1];
  const double exact = P * L * L * L / (3 * EI);
  std::printf("w(L) %.12g (exact %.12g), lumped mass %.12g (exact %.12g)\n", w_tip, exact, x_l, exact + P / kl);
  EXPECT_NEAR(w_tip, exact, 1e-12 * exact);
  EXPECT_NEAR(x_l, exact + P / kl, 1e-12 * x_l);
  const auto error_of = [&](const std::string& input) {
    try {
      io::parse_scenario(head + input, "a.yaml");
    } catch (const io::InputError& e) {
      return std::string(e.what());
    }
    return std::string("(no InputError)");
  };
  EXPECT_EQ(error_of("inputs: [{name: F, attachment: acc, signal: {type: step, amplitude: 1, t0: 0}}]\n"),
            "a.yaml: inputs[0].attachment must name an attachment of the beam with a lumped_mass (beam.attachments[].name), got 'acc'");
  EXPECT_EQ(error_of("inputs: [{name: F, attachment: shaker, kind: moment, signal: {type: step, amplitude: 1, t0: 0}}]\n"),
            "a.yaml: inputs[0].kind must be 'force' on a lumped attachment (it moves along w only), got 'moment'");
  EXPECT_EQ(error_of("inputs: [{name: F, attachment: shaker, location: 0.4, signal: {type: step, amplitude: 1, t0: 0}}]\n"),
            "a.yaml: inputs[0].location must be the attachment's own station (0.5) or left out, got 0.4");
}
