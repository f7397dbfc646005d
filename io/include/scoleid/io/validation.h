#pragma once
// One validation pass before any work: what a scenario (after any command-line override) must
// satisfy beyond the per-field checks of the parser — names that need no quoting anywhere and are
// unique across inputs and sensors, every derived count within limits.h, text that is UTF-8.
// All failures are io::InputError naming the source, the field and the value.
#include <string>

#include "scoleid/io/scenario.h"

namespace scoleid::io {

// [A-Za-z0-9_][A-Za-z0-9_.-]*, at most limits::kMaxNameLength characters, not "t" (the time
// column of every data file).
bool valid_name(const std::string& name);
void check_name(const std::string& source, const std::string& field, const std::string& name);

// Byte offset of the first byte that is not part of well-formed UTF-8 (RFC 3629: no overlong
// forms, no surrogates, nothing above U+10FFFF), or std::string::npos.
std::size_t first_invalid_utf8(const std::string& text);
// InputError "<what>: byte N (line L) is not valid UTF-8" unless the text is well-formed.
void check_utf8(const std::string& text, const std::string& what);
// Text in UTF-8 as it is; other text read as Windows-1252 (LabVIEW's code page on Windows:
// LVM and TDMS names and units) into UTF-8.
std::string windows1252_to_utf8(const std::string& text);

// A number read from a scenario: finite, and 0 or of magnitude in
// [limits::kMinMagnitude, limits::kMaxMagnitude].
void check_magnitude(const std::string& source, const std::string& field, double v);

// floor(duration / interval) + 1, computed without overflow (may be huge or inf).
double sample_count(double duration, double interval);

// The cross-field checks and count limits (names unique across inputs and sensors; samples,
// values per record, segments, elements, steps of a fixed identifier step). parse_scenario
// calls it; a program that overrides fields from its command line calls it again.
// Then every input's and sensor's site, kind, station and direction are ones the structure's
// models read (the kind's own checks: KindTable::check in its io file), so the finite-element
// models and the Simbody truth below take them as given.
void validate_scenario(const Scenario& scenario);

// A station `loc` at a site with one (has_station): on the structure, [0, length]. InputError
// naming `source` (default the scenario's), `field` and the value.
void check_location(const Scenario& sc, const std::string& field, Site at, double loc, const std::string& source = "");
// A sensor kind the structure's models read (types.h, reads); InputError naming the structures
// that read it.
void check_sensor_kind(const Scenario& sc, const std::string& field, SensorKind kind);

// The finite-element models follow what the Simbody truth follows except a SCOLE actuator's
// servo lag (truth.overrides.scole.actuator_lag). A run that needs the FE model to reproduce
// truth_sc (its synthesis, trajectories at the truth's physics) refuses such a lag: InputError
// naming source, the field and the value, `why` after the field's "is a servo lag of the Simbody
// truth only: ".
void check_fe_reproduces_truth(const std::string& source, const Scenario& truth_sc, const std::string& why);

// A message as one line: line breaks and other control characters shown as \n, \t, \xNN (C1
// controls, U+0085 among them, as \uNNNN), and
// a message over about 640 characters cut in the middle (its first 400 and last 160 kept, at UTF-8
// boundaries, with the count left out). Every program prints its errors through this (a library's
// multi-line text, a path holding a newline, a 50 MB name echoed back).
std::string one_line(const std::string& message);
// `value` itself when it is at most keep + 40 characters long, else its first `keep` characters (at
// a UTF-8 boundary) and "... (N characters)": for echoing a user's value in a message.
std::string shorten(const std::string& value, std::size_t keep = 80);

}  // namespace scoleid::io
