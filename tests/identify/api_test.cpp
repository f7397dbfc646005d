// The identifier's front door (scoleid/identify.h) and the strategy behind it (run/strategy.h).
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "scoleid/identify.h"
#include "scoleid/identify/fe/modal.h"
#include "scoleid/identify/run/strategy.h"
#include "scoleid/io/validation.h"
#include "scoleid/io/error.h"
#include "scoleid/io/progress.h"

namespace fs = std::filesystem;
using namespace scoleid;

namespace {

// paper-beam-1's record as a lab would hand it over: t, the load, the midspan sensor (synthesised
// on a mesh four times finer than the identifier's, with 20 µm of noise).
io::DataTable measured_table(const io::Scenario& sc) {
  const identify::Measurements m = identify::synthesize(sc, 4 * sc.identification.elements, 1e-8, 1e-3, true);
  return identify::measurement_table(sc, m);
}

io::Scenario noisy_beam() {
  io::Scenario sc = io::load_scenario("paper-beam-1");
  sc.sensors[0].noise_std = 2e-5;
  return sc;
}

}  // namespace

TEST(Api, ATableInMemoryIdentifiesExactlyAsTheSameFile) {
  const io::Scenario sc = noisy_beam();
  const io::DataTable table = measured_table(sc);
  const fs::path dir = fs::temp_directory_path() / "scoleid-api-test";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string csv = (dir / "measured.csv").string();
  io::write_csv(csv, table);
  // The file's values are what the table's become once written at full precision: read them back.
  const io::DataTable reread = io::read_csv(csv);
  const Identification from_file = identify_parameters(sc, DataSource::file(csv), {});
  const Identification from_table = identify_parameters(sc, DataSource::in_memory(reread, csv), {});
  ASSERT_EQ(from_file.names(), from_table.names());
  for (Eigen::Index i = 0; i < from_file.estimate().size(); ++i)
    EXPECT_EQ(from_file.estimate()[i], from_table.estimate()[i]) << from_file.names()[static_cast<std::size_t>(i)];
  EXPECT_EQ(from_file.result().summary.iterations_done, from_table.result().summary.iterations_done);
  EXPECT_TRUE(from_file.converged()) << from_file.verdict();
  EXPECT_EQ(from_file.exit_code(), 0);
  EXPECT_EQ(from_file.verdict(), "");
  // The in-memory problem says where its data came from, as a file's does.
  EXPECT_EQ(from_table.problem().data_source, csv);
  EXPECT_EQ(from_table.problem().columns.sensors, std::vector<std::string>{sc.sensors[0].name});
  fs::remove_all(dir);
}

TEST(Api, TheReportTheJsonAndTheFilesSayTheSame) {
  const io::Scenario sc = noisy_beam();
  const Identification id = identify_parameters(sc, DataSource::in_memory(measured_table(sc)), {});
  const nlohmann::json j = id.to_json();
  EXPECT_EQ(j["converged"].get<bool>(), id.converged());
  ASSERT_EQ(j["parameters"].size(), id.names().size());
  const std::string report = id.FullReport();
  for (std::size_t i = 0; i < id.names().size(); ++i) {
    EXPECT_EQ(j["parameters"][i]["estimate"].get<double>(), id.estimate()[static_cast<Eigen::Index>(i)]);
    EXPECT_NE(report.find(id.names()[i]), std::string::npos) << report;
  }
  EXPECT_NE(report.find(id.result().summary.BriefReport()), std::string::npos) << report;
  const fs::path dir = fs::temp_directory_path() / "scoleid-api-write";
  fs::remove_all(dir);
  id.write(dir.string());
  std::ifstream in(dir / "identify.json");
  const nlohmann::json written = nlohmann::json::parse(in);
  EXPECT_EQ(written["parameters"], j["parameters"]);
  EXPECT_TRUE(fs::exists(dir / "fit.csv"));
  fs::remove_all(dir);
}

TEST(Api, ARunOutOfIterationsSaysSoAndExitsOne) {
  const io::Scenario sc = noisy_beam();
  IdentifyOptions o;
  o.max_iterations = 1;
  o.compute_std = false;
  const Identification id = identify_parameters(sc, DataSource::in_memory(measured_table(sc)), o);
  EXPECT_FALSE(id.converged());
  EXPECT_EQ(id.exit_code(), 1);
  EXPECT_EQ(id.verdict().rfind("did not converge (max_iterations", 0), 0u) << id.verdict();
  EXPECT_FALSE(id.to_json()["converged"].get<bool>());
  // Not assessed is not identifiable: the report says so.
  EXPECT_NE(id.FullReport().find("(not assessed)"), std::string::npos);
}

TEST(Api, BadOptionsAndBadDataAreInputErrorsBeforeAnySolve) {
  const io::Scenario sc = noisy_beam();
  IdentifyOptions o;
  o.max_iterations = -1;
  std::string why;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("max_iterations"), std::string::npos);
  EXPECT_THROW(identify_parameters(sc, DataSource::synthetic(), o), io::InputError);
  io::DataTable t = measured_table(sc);
  t.names[1] = "elsewhere";  // no column for the sensor
  try {
    prepare(sc, DataSource::in_memory(t, "lab table"));
    FAIL() << "a table without the sensor's column was accepted";
  } catch (const io::InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("lab table"), std::string::npos) << m;
    EXPECT_NE(m.find(sc.sensors[0].name), std::string::npos) << m;
  }
}

TEST(Strategy, AutoResolvesByParametersPriorAndProducts) {
  using io::Method;
  const int limit = identify::kExplicitGaussNewtonParameters;
  EXPECT_EQ(identify::resolve_method(Method::Auto, limit, false, true), Method::GaussNewton);
  EXPECT_EQ(identify::resolve_method(Method::Auto, limit + 1, false, true), Method::Lbfgs);
  const int with_prior = identify::kExplicitGaussNewtonWithPrior;
  EXPECT_EQ(identify::resolve_method(Method::Auto, limit + 1, true, true), Method::GaussNewton);
  EXPECT_EQ(identify::resolve_method(Method::Auto, with_prior, true, true), Method::GaussNewton);
  EXPECT_EQ(identify::resolve_method(Method::Auto, with_prior + 1, true, true), Method::GaussNewtonKrylov);
  EXPECT_EQ(identify::resolve_method(Method::Auto, with_prior + 1, true, false), Method::GaussNewton);
  EXPECT_EQ(identify::resolve_method(Method::Auto, limit + 1, true, false), Method::GaussNewton);
  for (Method m : {Method::GaussNewton, Method::GaussNewtonKrylov, Method::Lbfgs, Method::SteepestDescent})
    EXPECT_EQ(identify::resolve_method(m, 64, true, false), m) << "a method given is kept";
}

TEST(Strategy, TheOptimiserOptionsAreTheScenariosAndTheCautiousRestartIsFourTimesSlower) {
  io::IdentificationSpec id;
  id.max_iterations = 17;
  id.gradient_tolerance = 3e-7;
  id.step_tolerance = 2e-4;
  id.continuation_misfit = 0.08;
  const auto oo = identify::optimizer_options(id, io::Method::Lbfgs, 2, std::nullopt);
  EXPECT_EQ(oo.method, io::Method::Lbfgs);
  EXPECT_EQ(oo.max_iterations, 17);
  EXPECT_EQ(oo.gradient_tolerance, 3e-7);
  EXPECT_EQ(oo.step_tolerance, 2e-4);
  EXPECT_TRUE(oo.continuation);
  EXPECT_EQ(oo.continuation_misfit, 0.08);
  EXPECT_EQ(identify::optimizer_options(id, io::Method::Lbfgs, 2, 3).max_iterations, 3);
  EXPECT_DOUBLE_EQ(identify::cautious_continuation(oo, id).continuation_misfit, 0.02);
  id.continuation_misfit = 0.0;  // no continuation in the scenario: the cautious one from the default
  const auto off = identify::optimizer_options(id, io::Method::GaussNewton, 2, std::nullopt);
  EXPECT_FALSE(off.continuation);
  EXPECT_DOUBLE_EQ(identify::cautious_continuation(off, id).continuation_misfit,
                   identify::OptimizerOptions{}.continuation_misfit / 4.0);
  // One weight per estimated parameter: the scenario's door refuses three for two; below it a
  // mismatch is a caller's defect.
  id.steepest_weights = {1.0, 2.0, 3.0};
  io::Scenario sc = io::load_scenario("paper-beam-1");
  sc.identification.estimate = {"EI", "rho_A"};
  sc.identification.steepest_weights = id.steepest_weights;
  try {
    io::validate_scenario(sc);
    FAIL() << "three weights for two parameters were accepted";
  } catch (const io::InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("identification.steepest_weights"), std::string::npos) << m;
    EXPECT_NE(m.find("3 values"), std::string::npos) << m;
  }
  EXPECT_THROW(identify::optimizer_options(id, io::Method::SteepestDescent, 2, std::nullopt), std::logic_error);
}

// A load cell's static offset and inverted polarity, a sensor read at twice its scale: stated as
// conditioning, the estimates are the clean record's (docs/data.md "Conditioning"); what was
// removed is recorded per column.
TEST(Api, ConditioningUndoesAnOffsetAFlippedSignAndAScale) {
  io::Scenario sc = noisy_beam();
  const io::DataTable clean = measured_table(sc);
  io::DataTable raw = clean;
  const int P = raw.find("P"), w = raw.find("w_mid");
  for (double& x : raw.columns[static_cast<std::size_t>(P)]) x = -(x + 23.0);
  for (double& x : raw.columns[static_cast<std::size_t>(w)]) x *= 2.0;
  const Identification ref = identify_parameters(sc, DataSource::in_memory(clean), {});
  // Without the conditioning the record is refused or the fit fails; with it the run is the clean one's.
  const Identification wrong = identify_parameters(sc, DataSource::in_memory(raw), {});
  EXPECT_FALSE(wrong.converged()) << wrong.verdict();
  sc.inputs[0].conditioning.offset = io::Conditioning::Offset::Value;
  sc.inputs[0].conditioning.offset_value = -23.0;
  sc.inputs[0].conditioning.sign = -1.0;
  sc.sensors[0].conditioning.scale = 0.5;
  const Identification fixed = identify_parameters(sc, DataSource::in_memory(raw), {});
  ASSERT_TRUE(fixed.converged()) << fixed.verdict();
  for (Eigen::Index i = 0; i < ref.estimate().size(); ++i)
    EXPECT_NEAR(fixed.estimate()[i] / ref.estimate()[i], 1.0, 1e-9) << ref.names()[static_cast<std::size_t>(i)];
  const auto& src = fixed.problem().columns.sources;
  ASSERT_EQ(src.size(), 2u);
  for (const auto& s : src) {
    EXPECT_TRUE(s.conditioned) << s.name;
    if (s.name == "P") {
      EXPECT_EQ(s.offset_removed, -23.0);
      EXPECT_EQ(s.factor, -1.0);
    } else {
      EXPECT_EQ(s.factor, 0.5);
    }
  }
  for (const auto& j : fixed.to_json()["data_columns"]["sources"])
    if (j["name"] == "P") { EXPECT_EQ(j["conditioning"]["offset_removed"].get<double>(), -23.0) << j.dump(); }
}

// offset: {mean_before: T} removes the mean of the samples before T (a pre-trigger), and a T with
// no sample before it, or none after, is refused naming the field.
TEST(Api, APretriggerOffsetIsTheMeanBeforeItsTime) {
  io::Scenario sc = noisy_beam();
  io::DataTable raw = measured_table(sc);
  const int w = raw.find("w_mid");
  auto& col = raw.columns[static_cast<std::size_t>(w)];
  for (double& x : col) x += 1e-3;
  sc.sensors[0].conditioning.offset = io::Conditioning::Offset::MeanBefore;
  sc.sensors[0].conditioning.offset_value = 0.05;
  double expected = 0.0;
  std::size_t n = 0;
  for (std::size_t k = 0; k < raw.t.size() && raw.t[k] < 0.05; ++k, ++n) expected += col[k];
  expected /= static_cast<double>(n);
  ASSERT_GT(n, 1u);
  const auto p = prepare(sc, DataSource::in_memory(raw));
  ASSERT_EQ(p->columns.sources.size(), 2u);
  const auto& s = p->columns.sources[0].name == "w_mid" ? p->columns.sources[0] : p->columns.sources[1];
  EXPECT_EQ(s.name, "w_mid");
  EXPECT_NEAR(s.offset_removed, expected, 1e-15);
  for (const double T : {0.0, 1e6}) {
    sc.sensors[0].conditioning.offset_value = T;
    std::string msg;
    try {
      prepare(sc, DataSource::in_memory(raw));
    } catch (const io::InputError& e) {
      msg = e.what();
    }
    EXPECT_NE(msg.find("sensors[0].conditioning.offset.mean_before"), std::string::npos) << msg;
  }
  // A run that synthesises its data has no column to condition: refused.
  std::string msg;
  try {
    prepare(sc, DataSource::synthetic());
  } catch (const io::InputError& e) {
    msg = e.what();
  }
  EXPECT_NE(msg.find("sensors[0].conditioning conditions a data column"), std::string::npos) << msg;
}

// A mesh of 1000 degrees of freedom or more: the build takes the starting model's few modes below
// the record's Nyquist frequency from the sparse solver (fe/lowest_modes.h), once however many of its
// steps ask for them (the step's data content and damping bound, the problem's content), and
// with `verbose` says so; without it, it is silent. The data content equals the one from a dense
// solution of every mode; and the dense solution's time, which the fallback announces, is
// estimated within a factor of 10.
TEST(Api, ALargeMeshSolvesTheStartingModelsFewModesSparselyOnceAndSaysSo) {
  io::Scenario sc = noisy_beam();
  sc.beam.zeta = 0.02;
  sc.simulation.duration = 1.0;
  sc.identification.parameterization = "physical";
  sc.identification.estimate = {"EI", "rho_A", "zeta"};
  sc.identification.initial = {{"EI", 19000.0}, {"rho_A", 63.0}, {"zeta", 0.015}};
  sc.identification.elements = 500;
  io::validate_scenario(sc);
  io::DataTable table;
  table.names = {"P", "w_mid"};
  table.columns.resize(2);
  for (int k = 0; k <= 100; ++k) {
    const double t = 0.01 * k;
    table.t.push_back(t);
    table.columns[0].push_back(10.0);
    table.columns[1].push_back(1e-3 * std::sin(2.0 * M_PI * 3.0 * t));
  }
  table.source = "record";
  std::vector<std::string> lines;
  std::unique_ptr<identify::Problem> p;
  {
    io::ProgressSink sink([&](const std::string& l) { lines.push_back(l); });
    p = identify::make_problem(sc, table, "record", nullptr, "", true);
    ASSERT_EQ(p->model().ndof, 1000);
    int sparse = 0, dense = 0;
    for (const auto& l : lines) {
      sparse += l.find("sparse subspace iteration on 1000 degrees of freedom") != std::string::npos;
      dense += l.find("dense eigen-solution") != std::string::npos;
    }
    EXPECT_EQ(sparse, 1);
    EXPECT_EQ(dense, 0);
    lines.clear();
    identify::make_problem(sc, table, "record");
    EXPECT_TRUE(lines.empty()) << lines.front();
  }
  const identify::IdentifierStep alone = identify::identifier_integration(p->scenario, p->model(), *p->params, p->signals);
  EXPECT_EQ(alone.step, p->objective_options.solver.step);
  EXPECT_EQ(alone.dirk_table, p->objective_options.solver.dirk_table);
  const identify::DataContent content = identify::data_content(p->model(), *p->params, p->signals, sc.simulation.duration,
                                                              sc.simulation.sample_interval);
  EXPECT_EQ(content.mode, p->content.mode);
  EXPECT_EQ(content.omega, p->content.omega);
  EXPECT_EQ(content.content_mode, p->content.content_mode);
  EXPECT_GT(p->content.mode, 0);
  {  // against every mode from a dense solution
    Eigen::VectorXd c;
    Eigen::MatrixXd dcdq;
    p->params->coefficients(p->params->initial(), c, dcdq);
    const identify::AssembledModel ops = identify::assemble(p->model(), c);
    const std::vector<double> w = identify::natural_frequencies(ops.M, ops.K);
    std::vector<double> below;
    for (double x : w)
      if (x > identify::rigid_floor(ops.M, ops.K) && x <= p->content.nyquist) below.push_back(x);
    ASSERT_FALSE(below.empty());
    // The pinned beam's fundamental (at the starting EI and rho_A) is among them: "10^-6 of the
    // highest frequency" counted it as a rigid-body mode on this mesh.
    const double fundamental = M_PI * M_PI * std::sqrt(19000.0 / 63.0) / (sc.beam.length * sc.beam.length);
    EXPECT_LT(below.front(), 1e-6 * w.back());
    // Within the rounding bound of any eigen solver on this mesh, ε ω_max² / ω² relative
    // (docs/theory.md §4.4; ω_max² ≈ max K_ii/M_ii): dense and sparse round differently.
    double top = 0.0;
    for (Eigen::Index i = 0; i < ops.M.rows(); ++i) top = std::max(top, ops.K.coeff(i, i) / ops.M.coeff(i, i));
    const auto bound = [&](double omega) { return 10.0 * 2.2e-16 * top / (omega * omega); };
    EXPECT_NEAR(below.front() / fundamental, 1.0, bound(fundamental));
    EXPECT_EQ(p->content.modes_below_nyquist, static_cast<int>(below.size()));
    EXPECT_NEAR(p->content.omega_first / below.front(), 1.0, bound(below.front()));
    const double omega_K = below[static_cast<std::size_t>(p->content.mode - 1)];
    EXPECT_NEAR(p->content.omega / omega_K, 1.0, bound(omega_K));
  }
  // The time the progress line promised, against the solve's own (within a factor of 10: the
  // estimate scales a small solve by n³, and this machine's load varies).
  const auto ops = identify::assemble(p->model(), p->structure->coefficients(sc));
  for (const bool vectors : {false, true}) {
    const auto t0 = std::chrono::steady_clock::now();
    if (vectors) identify::natural_modes(ops.M, ops.K);
    else identify::natural_frequencies(ops.M, ops.K);
    const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double said = identify::dense_eigen_seconds(p->model().ndof, vectors);
    std::printf("  %s of 1000 DOF: estimated %.3g s, took %.3g s\n", vectors ? "modes" : "frequencies", said, took);
    EXPECT_GT(said, 0.1 * took);
    EXPECT_LT(said, 10.0 * took);
  }
}
