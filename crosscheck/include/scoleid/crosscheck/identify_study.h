#pragma once
// Identification on the Simbody truth, with the chain's lumping bias extrapolated away
// (docs/theory.md §11.3).
//
// The identifier (the scenario's own settings) is run on the truth at n, 2n, 4n segments. If
// the estimates' error against the truth's values is the chain's lumping, it falls as n^−2 and the
// Richardson extrapolation
//     q∞ = q(4n) + (q(4n) − q(2n)) / 3
// removes it; what remains is the identifier's own discretisation and time-integration bias plus
// any physics the two models do not share. Beside it the inverse crime: the same identification on
// FE data synthesised on a finer mesh (identify/run/problem.h), which has no lumping at all.
// Per parameter and level the reported std and uncertainty interval are the identifier's;
// `covered` says whether estimate ± 2 std contains the truth's value — on noise-free truth data a
// std computed from the residual describes the fit, not the model error, and this column shows
// it — and `interval_covered` whether the reported interval (docs/theory.md §8.2) does.
#include <limits>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "scoleid/crosscheck/table.h"
#include "scoleid/crosscheck/truth_levels.h"
#include "scoleid/io/scenario.h"

namespace scoleid::crosscheck {

struct IdentifyStudyOptions {
  int segments = 0;        // first level; 0 = the scenario's truth.segments
  int levels = 3;          // n, 2n, 4n
  bool with_noise = false; // keep the scenario's sensor noise in the truths (default: noise-free)
  bool fe_on_fe = true;    // also identify from synthetic FE data
  bool progress = false;
  bool IsValid(std::string* why) const;
};

struct ParameterStudy {
  static constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  std::string name;
  double truth = nan;
  std::vector<double> estimate, std, half_width;   // per level
  std::vector<char> flagged;                       // per level: assessed and not identifiable
  double extrapolated = nan;           // Richardson, p = 2, two finest levels
  double rate = nan;                   // observed order of the estimates (three finest levels)
  double fe_on_fe = nan, fe_on_fe_std = nan;
  double error(std::size_t level) const { return estimate[level] / truth - 1.0; }
  double extrapolated_error() const { return extrapolated / truth - 1.0; }
  double fe_on_fe_error() const { return fe_on_fe / truth - 1.0; }
  // |estimate − truth| <= 2 std at the level (false when no std was reported).
  bool covered(std::size_t level) const;
  // |estimate − truth| <= the interval's half-width (false when none was reported).
  bool interval_covered(std::size_t level) const;
};

struct LevelRun {
  int segments = 0;        // 0 for the FE-on-FE run
  bool converged = false;
  int iterations = 0;                // the chosen attempt's
  int iterations_all_attempts = 0;   // every attempt's, with coarse-to-fine levels
  std::string termination;
  double seconds = 0.0;
};

struct IdentifyStudy {
  std::string scenario, data_kind;
  std::string model = "linear";   // the identifier's (identification.model)
  std::vector<int> segments;
  std::vector<ParameterStudy> parameters;
  std::vector<LevelRun> runs;     // per level
  LevelRun fe_run;
  std::vector<TruthLevel> truths;
  double seconds = 0.0;
  bool all_converged() const;
};

// `reuse`: truths already run for this scenario at these levels (e.g. by the trajectories verb,
// noise-free); empty = run them into `truth_root`.
IdentifyStudy identify_study(const io::Scenario& scenario, const IdentifyStudyOptions& options,
                             const std::string& truth_root, const std::vector<TruthLevel>& reuse = {});

Table identify_table(const IdentifyStudy& s);
nlohmann::json to_json(const IdentifyStudy& s);

}  // namespace scoleid::crosscheck
