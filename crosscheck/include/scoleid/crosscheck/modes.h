#pragma once
// Natural modes of the Simbody chain and of the finite-element model side by side
// (docs/theory.md §11.1).
//
// Both models are built from io::truth_scenario(scenario) — the structure the truth simulates —
// so that any difference is discretisation (or physics one side lacks), never a parameter.
//   chain  linearised at rest with n, 2n, 4n segments (model/linearisation.h undamped_modes):
//          frequencies converge as n^−2 (the Hencky lumping, docs/theory.md §9.1) and are
//          Richardson-extrapolated with p = 2 from the two finest levels;
//   FE     K φ = ω² M φ on N, 2N, 4N elements (cubic Hermite bending: frequencies as N^−4);
//   analytic  the Euler–Bernoulli frequency equation where one applies (uniform beams with the
//          supports of identify/fe/analytic_beam.h, a cantilever with a tip mass); none for SCOLE,
//          whose offset reflector couples both bending planes and torsion.
// Frequencies are the undamped ones. The modal damping ratio of each mode is reported beside them
// on the coarsest level of each side: the chain's from the eigenvalues of its linearised state
// Jacobian (dampers included), the FE's from the quadratic eigenproblem with D, each matched to
// the undamped mode nearest in frequency.
//
// Mode shapes are compared at shape stations along the structure (beam: the transverse
// displacement at 2·count + 2 equally spaced interior points; SCOLE: the displacements along x and
// y and the torsion rotation at as many mast stations, the rotation scaled by L so that all rows
// carry length units), read by each side's own sensor code. MAC_ij = (φ_iᵀ ψ_j)² / (|φ_i|² |ψ_j|²)
// between chain mode i and FE mode j, on the coarsest levels (n and N).
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <nlohmann/json.hpp>

#include "scoleid/crosscheck/table.h"

#include "scoleid/io/modal_data.h"
#include "scoleid/io/scenario.h"

namespace scoleid::crosscheck {

struct ModesOptions {
  int segments = 0;   // chain n; 0 = the scenario's truth.segments
  int elements = 0;   // FE N; 0 = the scenario's identification.elements
  int count = 10;     // flexible modes compared
  int levels = 3;     // resolutions per side: n, 2n, 4n (at least 1; rates need 3)
  bool IsValid(std::string* why) const;
};

struct ModeComparison {
  int index = 0;                   // flexible mode number, from 1
  std::vector<double> chain_hz;    // per level (n, 2n, 4n, ...)
  std::vector<double> fe_hz;       // per level (N, 2N, ...)
  double chain_rate = std::numeric_limits<double>::quiet_NaN();  // observed order in n
  double fe_rate = std::numeric_limits<double>::quiet_NaN();     // observed order in N
  double chain_extrapolated = std::numeric_limits<double>::quiet_NaN();
  double analytic_hz = std::numeric_limits<double>::quiet_NaN();
  double mac = std::numeric_limits<double>::quiet_NaN();         // chain i vs FE i (levels n, N)
  int best_fe = 0;                 // the FE mode (from 1) with the largest MAC against chain mode i
  double chain_zeta = std::numeric_limits<double>::quiet_NaN();  // damping ratio, chain level n
  double fe_zeta = std::numeric_limits<double>::quiet_NaN();     // damping ratio, FE level N
  // Relative differences: chain(n) − FE(N), extrapolated chain − finest FE.
  double raw_difference() const { return chain_hz.front() / fe_hz.front() - 1.0; }
  double extrapolated_difference() const { return chain_extrapolated / fe_hz.back() - 1.0; }
};

struct ModesReport {
  std::string scenario, structure;
  bool truth_overrides = false;
  std::vector<int> segments, elements;   // per level
  std::vector<ModeComparison> modes;
  Eigen::MatrixXd mac;                   // chain modes × FE modes (levels n and N)
  std::vector<std::string> stations;     // the shape vector's rows
  std::string analytic;                  // what the analytic column is, or "" for none
  double seconds = 0.0;
};

// io::InputError for a scenario either side cannot represent.
ModesReport compare_modes(const io::Scenario& scenario, const ModesOptions& options);

// The Simbody chain's first `count` flexible modes as measured modes (io/modal_data.h, the file
// scole-identify takes beside or instead of time records; docs/theory.md §6.6): frequencies of the
// chain at `segments` (the truth's resolution) and its shapes at the scenario's displacement,
// rotation and line-of-sight sensors. Each value's stated std is the chain's own lumping error,
// estimated from the same chain at 2·segments (mode i at n against the mode at 2n of largest MAC):
// frequencies converge as n⁻² (docs/theory.md §9.1), so f(n) − f(∞) ≈ (4/3)(f(n) − f(2n)); a
// shape's std is (4/3) the RMS difference of the unit shapes at n and 2n. A mode that no station
// sees is left out (its label is skipped). Floors of 1e-7 (relative frequency) and 1e-6 (shape) keep a converged mode
// from claiming exactness. io::InputError when the scenario has no such sensor.
io::ModalData chain_modal_data(const io::Scenario& scenario, int segments, int count);

// The frequency table (one row per mode), the MAC matrix, and everything as JSON.
Table modes_table(const ModesReport& r);
Table mac_table(const ModesReport& r);
nlohmann::json to_json(const ModesReport& r);

// MAC between the columns of A and B (rows: the same outputs).
Eigen::MatrixXd mac_matrix(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B);

}  // namespace scoleid::crosscheck
