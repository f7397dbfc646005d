#pragma once
// A record's columns read for the scenario's sensors and inputs (docs/data.md §2; the door's,
// record_door.h): each matched by its `column`, its name, or its name with a unit in the header;
// converted from the unit its file, its column_unit or truth.json states into the scenario's;
// conditioned (sign, scale, offset, detrend); a sensor's refused when one sample stands over a
// thousand times the RMS of the others (a spike); an input's read between samples as its
// interpolation says, with the force window on an impact. What was done is recorded in
// p.columns (ColumnUse). io::InputError naming the file, column, field and value.
#include <string>

#include "scoleid/identify/run/problem.h"
#include "scoleid/io/data_source.h"

namespace scoleid::identify {

// p.data (t, z, names) from the table's sensor columns, p.signals[i] from input i's column where
// its signal_from takes one, and p.columns; `csv` names the file in messages.
void measurements_from_table(Problem& p, const io::DataTable& table, const std::string& csv);

}  // namespace scoleid::identify
