// Several experiments with one parameter vector (identify/inverse/joint_misfit.h,
// identify/run/experiments.h; docs/theory.md §6.5).
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "scoleid/identify/fe/modal.h"
#include "scoleid/identify/fe/structure.h"
#include "scoleid/identify/inverse/joint_misfit.h"
#include "scoleid/identify/door/experiments_door.h"
#include "scoleid/identify/door/run_door.h"
#include "scoleid/identify/run/experiments.h"
#include "scoleid/identify/run/identify_run.h"
#include "scoleid/io/scenario.h"
#include "scoleid/io/error.h"
#include "test_support.h"

namespace scoleid::identify {
namespace {

using test_support::Case;
using test_support::make_case;

// Two experiments on one simply supported beam: a step at 3 m seen at 7 m over 4 s, and a
// haversine at 6 m seen at 2 m and 5 m over 3 s (different inputs, sensors and record lengths).
std::string beam_run(const std::string& load, const std::string& sensors, double duration) {
  return R"(name: beam-run
structure: beam
beam: {length: 10, left: pinned, right: pinned, rho_A: 67, EI: 23000, zeta: 0}
inputs:
  - )" + load + R"(
sensors:
)" + sensors + "simulation: {duration: " + std::to_string(duration) + R"(, sample_interval: 0.01, seed: 1}
identification:
  parameterization: physical
  estimate: [EI, rho_A]
  initial: {EI: 21000, rho_A: 63}
  elements: 10
)";
}

struct TwoBeamRuns {
  Case a, b;
  TwoBeamRuns()
      : a(make_case(beam_run("{name: P, at: beam, kind: force, location: 3, unit: N, signal: {type: step, amplitude: 10, t0: 0}}",
                             "  - {name: w7, at: beam, kind: displacement, location: 7, unit: m}\n", 4.0),
                    false)),
        b(make_case(beam_run("{name: F, at: beam, kind: force, location: 6, unit: N, signal: {type: haversine, amplitude: 10, t0: 0, width: 0.2}}",
                             "  - {name: w2, at: beam, kind: displacement, location: 2, unit: m}\n"
                             "  - {name: w5, at: beam, kind: displacement, location: 5, unit: m}\n",
                             3.0),
                    false)) {}
};

TEST(JointMisfit, SumsTheExperimentsBitForBitOnAnyNumberOfThreads) {
  TwoBeamRuns r;
  const VectorXd q = r.a.p->params->initial();
  VectorXd ga, gb;
  MatrixXd Ha, Hb;
  const double Ja = r.a.obj->gauss_newton(q, ga, Ha), Jb = r.b.obj->gauss_newton(q, gb, Hb);
  for (int threads : {1, 2}) {
    JointMisfit joint({{"a", r.a.obj.get()}, {"b", r.b.obj.get()}}, JointMisfitOptions{threads});
    EXPECT_EQ(joint.threads(), threads);
    VectorXd g;
    MatrixXd H;
    const double J = joint.gauss_newton(q, g, H);
    EXPECT_EQ(J, Ja + Jb);
    EXPECT_TRUE(g == ga + gb);
    EXPECT_TRUE(H == Ha + Hb);
    EXPECT_EQ(joint.last_costs()[0], Ja);
    EXPECT_EQ(joint.last_costs()[1], Jb);
    // The costate gradient: the sum of the runs' costate gradients, bit for bit, and within the
    // integrators' agreement of the sensitivity gradient (docs/theory.md §6).
    VectorXd gc, gca, gcb;
    const double Jc = joint.cost_and_gradient(q, gc);
    EXPECT_EQ(Jc, r.a.obj->cost_and_gradient(q, gca) + r.b.obj->cost_and_gradient(q, gcb));
    EXPECT_TRUE(gc == gca + gcb);
    EXPECT_NEAR(Jc, J, 1e-10 * J);
    EXPECT_LT((gc - g).norm(), 1e-4 * g.norm());
    EXPECT_EQ(joint.data_points(), r.a.obj->data_points() + r.b.obj->data_points());
  }
}

TEST(JointMisfit, HorizonIsTheSameFractionOfEveryRecord) {
  TwoBeamRuns r;
  JointMisfit joint({{"a", r.a.obj.get()}, {"b", r.b.obj.get()}});
  EXPECT_EQ(joint.data_start(), 0.0);
  EXPECT_EQ(joint.data_end(), 1.0);
  joint.set_horizon(0.5);
  EXPECT_NEAR(r.a.obj->horizon(), r.a.obj->data_start() + 0.5 * (r.a.obj->data_end() - r.a.obj->data_start()), 0.011);
  EXPECT_NEAR(r.b.obj->horizon(), r.b.obj->data_start() + 0.5 * (r.b.obj->data_end() - r.b.obj->data_start()), 0.011);
  EXPECT_LT(r.a.obj->horizon(), 2.1);
  EXPECT_GT(r.b.obj->horizon(), 1.4);
  // The joint profile at each fraction is the worse of the two runs' profiles there.
  const VectorXd q = r.a.p->params->initial();
  joint.set_horizon(1.0);
  const auto pj = joint.misfit_profile(q);
  const auto pa = r.a.obj->misfit_profile(q), pb = r.b.obj->misfit_profile(q);
  ASSERT_FALSE(pj.t.empty());
  EXPECT_DOUBLE_EQ(pj.t.back(), 1.0);
  EXPECT_DOUBLE_EQ(pj.misfit.back(), std::max(pa.misfit.back(), pb.misfit.back()));
  for (std::size_t i = 1; i < pj.t.size(); ++i) EXPECT_GT(pj.t[i], pj.t[i - 1]);
}

TEST(JointMisfit, TwoRunsRecoverTheBeamAndTheIterationTableIsTheSameOnOneOrTwoThreads) {
  TwoBeamRuns r;
  OptimizerOptions oo;
  oo.method = scoleid::io::Method::GaussNewton;
  std::vector<OptimizerSummary> s;
  for (int threads : {1, 2}) {
    r.a.obj->reset_counters();
    JointMisfit joint({{"a", r.a.obj.get()}, {"b", r.b.obj.get()}}, JointMisfitOptions{threads});
    s.push_back(minimize(joint, r.a.p->params->initial(), oo));
  }
  ASSERT_TRUE(s[0].converged()) << s[0].message;
  ASSERT_EQ(s[0].iterations.size(), s[1].iterations.size());
  for (std::size_t k = 0; k < s[0].iterations.size(); ++k) {
    EXPECT_EQ(s[0].iterations[k].cost, s[1].iterations[k].cost);
    EXPECT_TRUE(s[0].iterations[k].q == s[1].iterations[k].q);
  }
  const double err = test_support::max_rel_error(*r.a.p, s[0].q);
  std::printf("two beam runs: %d iterations, max relative error %.3e\n", s[0].iterations_done, err);
  EXPECT_LT(err, 1e-3);
}

#ifndef SCOLEID_SOURCE_DIR
#error "SCOLEID_SOURCE_DIR must be defined"
#endif
const std::string kTwoRuns = std::string(SCOLEID_SOURCE_DIR) + "/identify/examples/two-runs/";

// The issue's example: a reflector pulse read at the mast tip and a shuttle moment read at mid-mast
// (FE data with stated noise). The moment run alone leaves rho_I_psi unidentifiable; together they
// determine every parameter, each std below either run's alone.
TEST(Experiments, TwoScoleRunsTogetherIdentifyWhatOneAloneCannot) {
  // The moment run alone, as scole-identify -s would run it.
  {
    auto sc = io::load_scenario(kTwoRuns + "shuttle-moment.yaml");
    auto p = make_problem(sc, std::nullopt);
    RunOptions ro;
    ro.verbose = false;
    const RunResult alone = run_identification(*p, ro);
    const auto& n = alone.names;
    const auto i = static_cast<std::size_t>(std::find(n.begin(), n.end(), "rho_I_psi") - n.begin());
    ASSERT_LT(i, n.size());
    EXPECT_FALSE(alone.ident.identifiable[i]) << "the moment run alone determines rho_I_psi";
  }
  const ExperimentsSpec spec = load_experiments(kTwoRuns + "experiments.yaml");
  auto ep = make_experiments(spec);
  ExperimentsOptions eo;
  eo.verbose = false;
  const ExperimentsResult r = run_experiments(*ep, eo);
  ASSERT_TRUE(r.converged()) << r.summary.message;
  EXPECT_EQ(r.weighting, "likelihood");
  ASSERT_EQ(r.experiments.size(), 2u);
  std::printf("%-10s %12s %12s %12s %12s %12s\n", "parameter", "rel.error", "joint std", "std pulse", "std moment", "error/std");
  for (std::size_t i = 0; i < r.names.size(); ++i) {
    const auto e = static_cast<Eigen::Index>(i);
    const double truth = r.truth.at(r.names[i]);
    const double sj = r.ident.std[e], sa = r.experiments[0].alone.std[e], sb = r.experiments[1].alone.std[e];
    std::printf("%-10s %12.3e %12.3e %12.3e %12.3e %12.2f\n", r.names[i].c_str(), r.estimate[e] / truth - 1, sj, sa, sb,
                std::abs(r.estimate[e] - truth) / sj);
    EXPECT_TRUE(r.ident.identifiable[i]) << r.names[i] << ": " << r.ident.reason[i];
    EXPECT_LT(sj, sa) << r.names[i];
    EXPECT_LT(sj, sb) << r.names[i];
    EXPECT_LT(std::abs(r.estimate[e] - truth), 3.5 * sj) << r.names[i];
  }
  double share = 0;
  for (const auto& x : r.experiments) {
    EXPECT_TRUE(x.explains_data) << x.name << ": " << x.fit_message;
    EXPECT_GT(x.share, 0.0);
    share += x.share;
    EXPECT_EQ(x.residual_rms.size(), 2u);
  }
  EXPECT_NEAR(share, 1.0, 1e-12);
}

// A scratch directory with an experiments file and its scenarios.
struct Scratch {
  std::filesystem::path dir;
  Scratch() {
    dir = std::filesystem::temp_directory_path() / ("scoleid-experiments-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
  }
  ~Scratch() { std::filesystem::remove_all(dir); }
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(dir / name) << text;
    return (dir / name).string();
  }
};

// Measured modes of the scenario's structure at its true values, from the FE model on `elements`
// elements: the first `count` flexible frequencies and the shapes at its displacement sensors.
io::ModalData fe_modal_data(const io::Scenario& sc, int elements, int count, double rel_f_std, double shape_std) {
  const auto st = make_structure(sc, elements);
  const auto ops = assemble(st->model(), st->coefficients(sc));
  const NaturalModes nm = natural_modes(ops.M, ops.K);
  io::ModalData d;
  d.source = "fe-modes";
  std::vector<Eigen::RowVectorXd> rows;
  for (const auto& s : st->model().sensors)
    if (s.order == 0) {
      d.stations.push_back(s.name);
      rows.push_back(s.row);
    }
  for (Eigen::Index k = 0; k < nm.omega.size() && static_cast<int>(d.modes.size()) < count; ++k) {
    if (!(nm.omega[k] > nm.floor)) continue;
    io::ModalData::Mode m;
    m.label = static_cast<int>(d.modes.size()) + 1;
    m.frequency_hz = nm.omega[k] / (2.0 * M_PI);
    m.frequency_std_hz = rel_f_std * m.frequency_hz;
    for (const auto& r : rows) m.shape.push_back(r.dot(nm.vectors.col(k)));
    m.shape_std = shape_std;
    d.modes.push_back(m);
  }
  return d;
}

// Modal data beside a time-domain run (docs/theory.md §6.6): weighted by the likelihood on one
// scale, the joint fit converges, both experiments explain their data, and the modes sharpen what
// the run determines.
TEST(Experiments, ModesBesideATimeRunShareOneScale) {
  Scratch s;
  std::string run = beam_run("{name: P, at: beam, kind: force, location: 3, unit: N, signal: {type: step, amplitude: 10, t0: 0}}",
                             "  - {name: w7, at: beam, kind: displacement, location: 7, unit: m, noise_std: 1.0e-5}\n"
                             "  - {name: w4, at: beam, kind: displacement, location: 4, unit: m, noise_std: 1.0e-5}\n",
                             2.0);
  s.write("a.yaml", run);
  const io::Scenario sc = io::load_scenario((s.dir / "a.yaml").string());
  // Frequencies stated to 2e-3: above the identifier's discretisation error of mode 4 (1.7e-3 on
  // 10 elements; below, see the end).
  io::write_modal_data((s.dir / "m.csv").string(), fe_modal_data(sc, 4 * sc.identification.elements, 4, 2e-3, 1e-3));
  const std::string f = s.write("e.yaml", "experiments: e\nruns:\n  - {name: a, scenario: a.yaml}\nmodes: {file: m.csv}\n");
  auto ep = make_experiments(load_experiments(f));
  ExperimentsOptions eo;
  eo.verbose = false;
  const ExperimentsResult r = run_experiments(*ep, eo);
  for (const auto& x : r.experiments)
    std::printf("%-6s share %.3f, %ld values: %s\n", x.name.c_str(), x.share, x.data_values, x.fit_message.c_str());
  ASSERT_TRUE(r.converged()) << r.summary.message;
  EXPECT_EQ(r.weighting, "likelihood");
  ASSERT_EQ(r.experiments.size(), 2u);
  EXPECT_EQ(r.experiments[1].kind, "modal");
  for (const auto& x : r.experiments) {
    EXPECT_TRUE(x.explains_data) << x.name << ": " << x.fit_message;
    // On one scale: the noisy run's misfit is about half its number of values (½χ² of white
    // noise); the noise-free modes' is below theirs.
    EXPECT_LT(x.cost, 1.5 * 0.5 * static_cast<double>(x.data_values)) << x.name;
    if (x.kind == "time") {
      EXPECT_GT(x.cost, 0.5 * 0.5 * static_cast<double>(x.data_values)) << x.name;
    }
  }
  for (std::size_t i = 0; i < r.names.size(); ++i) {
    const auto e = static_cast<Eigen::Index>(i);
    EXPECT_LT(r.ident.std[e], r.experiments[0].alone.std[e]) << r.names[i];
    EXPECT_LT(std::abs(r.estimate[e] / r.truth.at(r.names[i]) - 1.0), 1e-3) << r.names[i];
  }
  // The same modes stated to 1e-4, finer than the identifier's model can represent them: the fit
  // does not explain them, and the run says so.
  io::write_modal_data((s.dir / "m.csv").string(), fe_modal_data(sc, 4 * sc.identification.elements, 4, 1e-4, 1e-3));
  auto tight = make_experiments(load_experiments(f));
  const ExperimentsResult rt = run_experiments(*tight, eo);
  std::printf("modes stated to 1e-4: %s\n", rt.experiments[1].fit_message.c_str());
  EXPECT_FALSE(rt.experiments[1].explains_data);
  EXPECT_FALSE(rt.converged());
}

std::string input_error(const std::function<void()>& f) {
  try {
    f();
  } catch (const io::InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

// The modes as a modal-test program exports them: one dataset 55 per mode (normal mode, 3 values
// per node, E13.5), the station k at node k + 1 along Z.
std::string uff55(const io::ModalData& d) {
  std::string s;
  char buf[160];
  for (const auto& m : d.modes) {
    s += "    -1\n    55\nmodes\nNONE\nNONE\nNONE\nNONE\n";
    std::snprintf(buf, sizeof buf, "%10d%10d%10d%10d%10d%10d\n", 1, 2, 2, 8, 2, 3);
    s += buf;
    std::snprintf(buf, sizeof buf, "%10d%10d%10d%10d\n", 2, 4, 1, m.label);
    s += buf;
    std::snprintf(buf, sizeof buf, "%13.5e%13.5e%13.5e%13.5e\n", m.frequency_hz, 1.0, 0.0, 0.0);
    s += buf;
    for (std::size_t k = 0; k < m.shape.size(); ++k) {
      std::snprintf(buf, sizeof buf, "%10zu\n%13.5e%13.5e%13.5e\n", k + 1, 0.0, 0.0, m.shape[k]);
      s += buf;
    }
    s += "    -1\n";
  }
  return s;
}

// The same modes from a Universal File (frequencies and shapes to 6 digits, deviations and
// stations stated in the experiments file) identify what the CSV does, to well within a std.
TEST(Experiments, ModesFromAUniversalFileIdentifyAsFromTheCsv) {
  Scratch s;
  s.write("a.yaml", beam_run("{name: P, at: beam, kind: force, location: 3, unit: N, signal: {type: step, amplitude: 10, t0: 0}}",
                             "  - {name: w7, at: beam, kind: displacement, location: 7, unit: m, noise_std: 1.0e-5}\n"
                             "  - {name: w4, at: beam, kind: displacement, location: 4, unit: m, noise_std: 1.0e-5}\n",
                             2.0));
  const io::Scenario sc = io::load_scenario((s.dir / "a.yaml").string());
  const io::ModalData d = fe_modal_data(sc, 4 * sc.identification.elements, 4, 2e-3, 1e-3);
  io::write_modal_data((s.dir / "m.csv").string(), d);
  s.write("m.uff", uff55(d));
  const std::string fc = s.write("c.yaml", "experiments: c\nmodes: {file: m.csv, scenario: a.yaml}\n");
  const std::string fu = s.write("u.yaml", "experiments: u\nmodes: {file: m.uff, scenario: a.yaml, frequency_std: 2.0e-3, shape_std: 1.0e-3,\n"
                                           "        stations: {" + d.stations[0] + ": 1+Z, " + d.stations[1] + ": 2+Z}}\n");
  ExperimentsOptions eo;
  eo.verbose = false;
  auto ec = make_experiments(load_experiments(fc));
  auto eu = make_experiments(load_experiments(fu));
  ASSERT_EQ(eu->modes->modes.size(), d.modes.size());
  for (std::size_t m = 0; m < d.modes.size(); ++m)
    EXPECT_NEAR(eu->modes->modes[m].frequency_std_hz, d.modes[m].frequency_std_hz, 1e-5 * d.modes[m].frequency_std_hz);
  const ExperimentsResult rc = run_experiments(*ec, eo);
  const ExperimentsResult ru = run_experiments(*eu, eo);
  ASSERT_TRUE(rc.converged()) << rc.summary.message;
  ASSERT_TRUE(ru.converged()) << ru.summary.message;
  // Modes alone fix EI/rho_A (frequencies ~ sqrt(EI/rho_A); shapes carry no scale): that ratio
  // agrees to the files' 6 digits, far inside the frequencies' stated 2e-3.
  const double ratio_c = rc.estimate[0] / rc.estimate[1], ratio_u = ru.estimate[0] / ru.estimate[1];
  std::printf("EI/rho_A: csv %.10g, uff %.10g, relative difference %.2e\n", ratio_c, ratio_u, ratio_u / ratio_c - 1.0);
  EXPECT_NEAR(ratio_u / ratio_c, 1.0, 1e-4);
  EXPECT_NEAR(ratio_c / (23000.0 / 67.0), 1.0, 2e-3);
  // A CSV with a Universal File's fields is refused (it states its own deviations).
  const std::string bad = s.write("b.yaml", "experiments: b\nmodes: {file: m.csv, scenario: a.yaml, frequency_std: 0.01}\n");
  EXPECT_NE(input_error([&] { make_experiments(load_experiments(bad)); }).find("describe a Universal File's modes"), std::string::npos);
}


TEST(Experiments, BadInputIsOneLineNamingFileFieldAndValue) {
  Scratch s;
  s.write("a.yaml", beam_run("{name: P, at: beam, kind: force, location: 3, unit: N, signal: {type: step, amplitude: 10, t0: 0}}",
                             "  - {name: w7, at: beam, kind: displacement, location: 7, unit: m}\n", 1.0));
  // A data file that lacks the run's sensor column.
  s.write("a.csv", "t,P,w_other\n0,10,0\n0.01,10,1e-6\n0.02,10,2e-6\n");
  const std::string f1 = s.write("e1.yaml", "experiments: e1\nruns:\n  - {name: a, scenario: a.yaml, data: a.csv}\n");
  const std::string m1 = input_error([&] { make_experiments(load_experiments(f1)); });
  std::printf("%s\n", m1.c_str());
  EXPECT_NE(m1.find("a.csv"), std::string::npos) << m1;
  EXPECT_NE(m1.find("w7"), std::string::npos) << m1;

  const std::string f2 = s.write("e2.yaml", "experiments: e2\nruns:\n  - {name: a, scenario: a.yaml}\n  - {name: a, scenario: a.yaml}\n");
  const std::string m2 = input_error([&] { load_experiments(f2); });
  EXPECT_NE(m2.find("runs[1].name"), std::string::npos) << m2;

  const std::string f3 = s.write("e3.yaml", "experiments: e3\nrun:\n  - {name: a, scenario: a.yaml}\n");
  const std::string m3 = input_error([&] { load_experiments(f3); });
  EXPECT_NE(m3.find("run"), std::string::npos) << m3;
  EXPECT_NE(m3.find("e3.yaml"), std::string::npos) << m3;

  // Runs that estimate different parameters.
  std::string other = beam_run("{name: P, at: beam, kind: force, location: 3, unit: N, signal: {type: step, amplitude: 10, t0: 0}}",
                               "  - {name: w7, at: beam, kind: displacement, location: 7, unit: m}\n", 1.0);
  other.replace(other.find("estimate: [EI, rho_A]"), 21, "estimate: [EI]");
  s.write("b.yaml", other);
  const std::string f4 = s.write("e4.yaml", "experiments: e4\nruns:\n  - {name: a, scenario: a.yaml}\n  - {name: b, scenario: b.yaml}\n");
  const std::string m4 = input_error([&] { make_experiments(load_experiments(f4)); });
  EXPECT_NE(m4.find("runs[1]"), std::string::npos) << m4;

  const std::string m5 = input_error([&] { load_experiments((s.dir / "missing.yaml").string()); });
  EXPECT_NE(m5.find("missing.yaml"), std::string::npos) << m5;

  // A run on the nonlinear SCOLE model: joint runs are linear only.
  s.write("n.yaml", R"(structure: scole
inputs:
  - {name: M, at: shuttle, kind: moment, direction: x, signal: {type: bangbang, amplitude: 1000, t0: 0, width: 1}}
sensors:
  - {name: tip, at: mast, location: 130, direction: y}
simulation: {duration: 1, sample_interval: 0.02}
identification:
  estimate: [EI]
  elements: 2
  model: nonlinear
)");
  const std::string f6 = s.write("e6.yaml", "experiments: e6\nruns:\n  - {name: n, scenario: n.yaml}\n");
  const std::string m6 = input_error([&] { make_experiments(load_experiments(f6)); });
  EXPECT_NE(m6.find("identification.model"), std::string::npos) << m6;
  EXPECT_NE(m6.find("e6.yaml"), std::string::npos) << m6;
  for (const std::string& m : {m1, m2, m3, m4, m5, m6}) EXPECT_EQ(m.find('\n'), std::string::npos) << m;
}

// Frequency-domain runs in a joint run (identification.domain: frequency; docs/theory.md §6.5,
// §6.10), on the clamped strip of tests/data/scenarios/frf_run_test/multisine.yaml (FE-synthetic,
// 16 elements, the identifier 8):
//   - one such run alone is the frequency-domain run: the same estimate to a hundredth of its std
//     and the same std (the same misfit, ½χ² of the FRFs' variances, and Fisher information);
//   - two runs (the multisine read at the tip and mid-span; a second multisine, another band and
//     another accelerometer): every parameter within 1 % of the truth, at the two runs' estimates
//     combined by their Fisher informations, each experiment explaining its data, each joint std
//     below either run's alone;
//   - a time run without stated noise beside a frequency-domain run is refused (no common scale).
std::string strip_run(const std::string& name, const std::string& signal, const std::string& sensors, int seed) {
  return "name: " + name + R"(
structure: beam
units: SI
beam:
  length: 0.5
  left: clamped
  right: free
  rho_A: 0.58875
  EI: 11.25
  zeta: 0.05
  attachments:
    - {name: shaker, location: 0.40, mass: 0.060}
inputs:
  - {name: F, at: beam, kind: force, location: 0.40, unit: N, signal: )" + signal + R"(}
sensors:
)" + sensors + "simulation: {duration: 12, sample_interval: 0.0009765625, record_start: 4, seed: " + std::to_string(seed) + R"(}
identification:
  estimate: [EI, rho_A, zeta]
  initial: {EI: 13.5, rho_A: 0.47, zeta: 0.06}
  elements: 8
  domain: frequency
  frf: {estimator: auto, segment: 0, overlap: 0.5, window: hann}
)";
}

TEST(Experiments, FrequencyDomainRunsJoinAsTheirOwnChiSquare) {
  Scratch s;
  const std::string a = s.write("a.yaml", strip_run("strip-a", "{type: multisine, amplitude: 0.5, period: 1, f0: 1, f1: 120}",
                                                    "  - {name: acc_tip, at: beam, kind: acceleration, location: 0.45, unit: m/s^2, noise_std: 0.02}\n"
                                                    "  - {name: acc_mid, at: beam, kind: acceleration, location: 0.25, unit: m/s^2, noise_std: 0.02}\n",
                                                    2));
  s.write("b.yaml", strip_run("strip-b", "{type: multisine, amplitude: 0.3, period: 1, f0: 2, f1: 90}",
                              "  - {name: acc_35, at: beam, kind: acceleration, location: 0.35, unit: m/s^2, noise_std: 0.03}\n", 5));
  ExperimentsOptions eo;
  eo.verbose = false;

  // One run alone: the frequency-domain run's estimate and std.
  auto single = make_problem(io::load_scenario(a), std::nullopt);
  RunOptions ro;
  ro.verbose = false;
  const RunResult rs = run_identification(*single, ro);
  ASSERT_TRUE(rs.converged()) << rs.summary.message << " / " << rs.fit.message;
  auto one = make_experiments(load_experiments(s.write("one.yaml", "experiments: one\nruns:\n  - {name: a, scenario: a.yaml}\n")));
  const ExperimentsResult r1 = run_experiments(*one, eo);
  ASSERT_TRUE(r1.converged()) << r1.summary.message;
  EXPECT_EQ(r1.weighting, "likelihood");
  ASSERT_EQ(r1.experiments.size(), 1u);
  EXPECT_EQ(r1.experiments[0].kind, "frf");
  EXPECT_GT(r1.experiments[0].factorisations, 0);
  EXPECT_EQ(r1.experiments[0].explains_data, rs.fit.explains_data) << r1.experiments[0].fit_message;
  for (std::size_t i = 0; i < r1.names.size(); ++i) {
    const auto e = static_cast<Eigen::Index>(i);
    std::printf("%-6s joint of one %.9g  frequency-domain run %.9g  std %.3g / %.3g\n", r1.names[i].c_str(), r1.estimate[e],
                rs.estimate[e], r1.ident.std[e], rs.ident.std[e]);
    EXPECT_LE(std::abs(r1.estimate[e] - rs.estimate[e]), 0.01 * rs.ident.std[e]) << r1.names[i];
    EXPECT_NEAR(r1.ident.std[e] / rs.ident.std[e], 1.0, 1e-3) << r1.names[i];
  }

  // Two runs together.
  auto two = make_experiments(load_experiments(
      s.write("two.yaml", "experiments: two\nruns:\n  - {name: a, scenario: a.yaml}\n  - {name: b, scenario: b.yaml}\n")));
  const ExperimentsResult r2 = run_experiments(*two, eo);
  for (const auto& x : r2.experiments)
    std::printf("%-3s %s, share %.3f, %ld values: %s\n", x.name.c_str(), x.kind.c_str(), x.share, x.data_values, x.fit_message.c_str());
  ASSERT_TRUE(r2.converged()) << r2.summary.message;
  ASSERT_EQ(r2.experiments.size(), 2u);
  for (const auto& x : r2.experiments) {
    EXPECT_EQ(x.kind, "frf");
    EXPECT_TRUE(x.explains_data) << x.name << ": " << x.fit_message;
  }
  // The sum of the two ½χ²: its minimum is, to the misfits' quadratic approximation, the two runs'
  // estimates combined with their Fisher informations as weights. Each run's estimate carries its
  // own discretisation bias (8 elements against data made on 16: 5e-4 to 1e-3, beyond the noise's
  // std), which the combination weighs as the joint fit does.
  auto b_alone = make_problem(io::load_scenario((s.dir / "b.yaml").string()), std::nullopt);
  const RunResult rb = run_identification(*b_alone, ro);
  ASSERT_TRUE(rb.converged()) << rb.summary.message << " / " << rb.fit.message;
  const Eigen::MatrixXd Fa = rs.ident.covariance.inverse(), Fb = rb.ident.covariance.inverse();
  const Eigen::VectorXd combined = (Fa + Fb).ldlt().solve(Fa * rs.estimate + Fb * rb.estimate);
  for (std::size_t i = 0; i < r2.names.size(); ++i) {
    const auto e = static_cast<Eigen::Index>(i);
    const double truth = r2.truth.at(r2.names[i]);
    std::printf("%-6s joint %.7g (%+.2e)  a %.7g  b %.7g  combined %.7g  std joint %.3g, a alone %.3g, b alone %.3g\n", r2.names[i].c_str(),
                r2.estimate[e], r2.estimate[e] / truth - 1.0, rs.estimate[e], rb.estimate[e], combined[e], r2.ident.std[e],
                r2.experiments[0].alone.std[e], r2.experiments[1].alone.std[e]);
    EXPECT_TRUE(r2.ident.identifiable[i]) << r2.names[i];
    EXPECT_LT(std::abs(r2.estimate[e] / truth - 1.0), 1e-2) << r2.names[i];
    EXPECT_LE(std::abs(r2.estimate[e] - combined[e]), 0.1 * std::abs(rs.estimate[e] - rb.estimate[e]) + r2.ident.std[e]) << r2.names[i];
    EXPECT_LT(r2.ident.std[e], r2.experiments[0].alone.std[e]) << r2.names[i];
    EXPECT_LT(r2.ident.std[e], r2.experiments[1].alone.std[e]) << r2.names[i];
  }
  const nlohmann::json j = r2.to_json();
  EXPECT_EQ(j["per_experiment"][0]["kind"], "frf");
  EXPECT_TRUE(j["per_experiment"][0]["solves"].contains("factorisations"));
  EXPECT_TRUE(j["identifiability"]["interval"].is_string());

  // A time run whose noise is not stated beside them: refused, naming the run and its sensor.
  std::string time_run = strip_run("strip-t", "{type: multisine, amplitude: 0.5, period: 1, f0: 1, f1: 120}",
                                   "  - {name: acc_t, at: beam, kind: acceleration, location: 0.45, unit: m/s^2}\n", 7);
  time_run.replace(time_run.find("  domain: frequency\n"), 20, "");
  time_run.replace(time_run.find("  frf: {"), time_run.find("\n", time_run.find("  frf: {")) + 1 - time_run.find("  frf: {"), "");
  s.write("t.yaml", time_run);
  const std::string m = input_error([&] {
    make_experiments(load_experiments(s.write("mixed.yaml", "experiments: mixed\nruns:\n  - {name: a, scenario: a.yaml}\n  - {name: t, scenario: t.yaml}\n")));
  });
  std::printf("%s\n", m.c_str());
  EXPECT_NE(m.find("runs[1] (t)"), std::string::npos) << m;
  EXPECT_NE(m.find("frequency-domain"), std::string::npos) << m;
  EXPECT_NE(m.find("acc_t"), std::string::npos) << m;
  EXPECT_EQ(m.find('\n'), std::string::npos) << m;
}

// The joint run's method at its door: gauss-newton-krylov needs every run's matrix-free products,
// which an accelerometer's run does not offer; refused naming the run before any joint solve,
// while two displacement runs pass.
TEST(Experiments, TheKrylovMethodIsRefusedAtTheDoorForARunWithAnAccelerometer) {
  Scratch s;
  const std::string load = "{name: P, at: beam, kind: force, location: 3, unit: N, signal: {type: step, amplitude: 10, t0: 0}}";
  s.write("d.yaml", beam_run(load, "  - {name: w7, at: beam, kind: displacement, location: 7, unit: m}\n", 0.5));
  s.write("a.yaml", beam_run(load, "  - {name: a7, at: beam, kind: acceleration, location: 7, unit: m/s^2}\n", 0.5));
  ExperimentsOptions eo;
  eo.method = io::Method::GaussNewtonKrylov;
  const auto mixed = make_experiments(load_experiments(
      s.write("mixed.yaml", "experiments: mixed\nruns:\n  - {name: disp, scenario: d.yaml}\n  - {name: acc, scenario: a.yaml}\n")));
  const std::string m = input_error([&] { check_experiments_run(*mixed, eo); });
  EXPECT_NE(m.find("mixed.yaml"), std::string::npos) << m;
  EXPECT_NE(m.find("runs[1] (acc)"), std::string::npos) << m;
  EXPECT_NE(m.find("velocity and acceleration sensors"), std::string::npos) << m;
  EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  EXPECT_NE(input_error([&] { run_experiments(*mixed, eo); }).find("runs[1] (acc)"), std::string::npos);
  const auto disp = make_experiments(load_experiments(
      s.write("disp.yaml", "experiments: disp\nruns:\n  - {name: one, scenario: d.yaml}\n  - {name: two, scenario: d.yaml}\n")));
  EXPECT_NO_THROW(check_experiments_run(*disp, eo));
  eo.method = io::Method::GaussNewton;
  EXPECT_NO_THROW(check_experiments_run(*mixed, eo));
}

}  // namespace
}  // namespace scoleid::identify
