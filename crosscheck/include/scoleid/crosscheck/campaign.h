#pragma once
// A campaign (docs/theory.md §11.6): many truth + identification runs described by one file —
// scenarios × a parameter grid × noise seeds — whose results are stored one file per case and
// summarised in one report. The runs are independent; campaign_runner.h executes them serially or
// over MPI ranks, and the report depends only on the stored cases, never on who ran them.
//
// A campaign file (YAML):
//   campaign:    name (letters, digits, - and _)
//   description: one line: what the campaign measures
//   scenarios:   [name | file, ...]   built-in scenarios, or files relative to the campaign file
//   overlay:     YAML merged onto every scenario (maps merge key by key, anything else replaces)
//   grid:        {dotted.path: [v1, v2, ...], ...}  the cartesian product, last path fastest; each
//                value set at its path (e.g. truth.segments, truth.overrides.scole.zeta)
//   noise:       {relative: r, seeds: K, seed: s0}  optional: K noisy identifications per point,
//                Gaussian noise of r × each sensor's RMS added to the point's noise-free truth,
//                draw j of point p seeded s0 + 1000003 p + j, the level stated to the identifier
// A point is one scenario at one grid value; every point has a noise-free truth (generated once,
// shared by its cases) and the cases: a noise-free identification ("ref") and, with noise, its K
// noisy ones.
#include <cstddef>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "scoleid/io/scenario.h"

namespace scoleid::crosscheck {

struct CampaignPoint {
  std::string id;       // "p000", "p001", ...
  std::string label;    // "paper-scole-1 truth.segments=20"
  std::string yaml;     // the point's scenario, overlays applied
  std::string key;      // fingerprint of `yaml` (16 hex digits): stored results carry it
  io::Scenario scenario;
};

struct CampaignCase {
  std::string id;       // "p000-ref", "p000-s0007"
  std::size_t point = 0;
  int seed = -1;        // -1: the noise-free identification; else the draw index
  std::string key;      // fingerprint of the point, the draw and the noise settings
};

struct Campaign {
  std::string path, name, description;
  std::vector<std::string> scenarios;
  std::string overlay;
  std::vector<std::pair<std::string, std::vector<std::string>>> grid;  // path → value YAML texts
  double noise_relative = 0.0;
  int seeds = 0;
  unsigned noise_seed = 1;
  std::vector<CampaignPoint> points;
  std::vector<CampaignCase> cases;  // point by point, "ref" first
};

// Reads and checks a campaign file, builds and validates every point's scenario: one
// io::InputError line naming the file, the field and the value.
Campaign load_campaign(const std::string& path);

// The noise seed of case `c` (meaningless for the noise-free case).
unsigned case_noise_seed(const Campaign& c, const CampaignCase& k);

// The report over the stored results (`results[k]` the JSON of case k): report.md, cases.csv,
// points.csv, histogram.csv, histogram.gp and campaign.json, file name → contents. A pure
// function of the results: the same cases give the same bytes, whoever ran them.
std::map<std::string, std::string> campaign_report(const Campaign& c, const std::vector<nlohmann::json>& results);

}  // namespace scoleid::crosscheck
