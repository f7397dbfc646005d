#pragma once
// The identifier's front door for a record (docs/theory.md §10.1b): a data table resolved against
// the scenario into the problem's measurements, inputs and noise levels, everything that can be
// wrong with the pair refused here, before the identification's first solve —
//   - the time column: on a stated data.sample_rate's grid (or the uniform grid its writing
//     rounds to), at least 3 samples, the first at t >= 0; data.window holding 3 or more;
//   - truth.json beside it: the same columns, structure, quantities, sites and units;
//   - each sensor's and input's column (record_columns.h): found, its unit convertible into the
//     scenario's, its conditioning possible, no lone spike;
//   - the identifier's step against the scenario and the record (check_identifier_step,
//     check_record_span), identification.band against the record (check_band), the record's
//     levels against the stated noise (check_record_levels).
// Below the door, run/ takes the record as valid.
#include <map>
#include <string>

#include "scoleid/identify/run/problem.h"
#include "scoleid/io/data_source.h"

namespace scoleid::identify {

// The record `table` (`source` names it in messages) and the truth metadata beside it (`meta`,
// named `meta_source`; may be null) read into p: the time grid (p.columns.time), p.data, the
// inputs read from columns (p.signals), p.columns, the window, noise levels from truth.json or the
// record's quiet start (p.noise_std, p.noise_origin). Returns truth.json's true parameters (empty
// without one). io::InputError naming the file, column or field and the value.
std::map<std::string, double> read_record(Problem& p, const io::DataTable& table, const std::string& source,
                                          const io::TruthMeta* meta, const std::string& meta_source);

// The identifier's step h for the scenario, refused before any solve when the run cannot afford
// or trust it: a stated identification.time_step that does not resolve the modes the data contain
// (ω_K h > 1: the L-stable step would damp them away and the fit absorb that into the
// parameters), a scenario signal the step cannot resolve (a pulse shorter than h, a sine at or
// above 1/(2h)), trajectory storage beyond io::limits (state, costate and a block of
// sensitivities; with `synthetic`, the synthetic data's finer mesh and step h/4 as well).
// `content` is data_content's for the scenario at the starting values.
void check_identifier_step(const io::Scenario& sc, const StructuralModel& model, const Parameterization& params,
                           const std::vector<io::Signal>& signals, const DataContent& content, double h, bool synthetic);
// A measured record's span in steps of h within io::limits::kMaxSteps.
void check_record_span(const Problem& p, double h);

// identification.band against the record: uniformly sampled times, the top edge below the
// data's Nyquist frequency, every sensor's noise level known (the band's chi-square is drawn from
// it). Nothing to check without a band.
void check_band(const Problem& p);

// The record's levels: some sensor moves (a record of zeros determines nothing), no stated noise
// level over three times a sensor's RMS (a wrong unit or a typo, which would pass any fit test),
// and a synthetic record whose noise does not bury every sensor's signal. `csv` names a measured
// record (null: synthetic).
void check_record_levels(const Problem& p, const std::string* csv);

}  // namespace scoleid::identify
