#pragma once
// LabVIEW Measurement files (.lvm, the text format NI's "Write To Measurement File" writes), read
// as one record of time responses (docs/data.md "LabVIEW").
//
// Layout: a file header (first line "LabVIEW Measurement"; tags Separator Tab|Comma,
// Decimal_Separator . or ",", X_Columns No|One|Multi, ...; ends at ***End_of_Header***), then a
// segment header (Channels, Samples, Y_Unit_Label, X_Dimension, X0, Delta_X, one value per channel
// in the channel's own column; ends at ***End_of_Header***), the column-name row (X_Value, the
// channel names, Comment) and the data rows, each channel i in column i+1 (X_Columns No or One) or
// 2i+1 (Multi, its x in column 2i), an optional comment after the last.
//
// Time: X_Columns One reads the x column (irregular x is refused by the time checks, naming the
// line); Multi reads each channel's x column, which must agree with the first's; No computes
// t_k = X0 + k·Delta_X of the first channel. A decimated file may keep its original Delta_X: with
// an x column the x column rules and a Delta_X that disagrees with it is noted (describe_lvm).
// Units from Y_Unit_Label (DAQ labels such as "Newtons", "Pounds" are read by units.h's alias
// table). Names in Windows-1252 (LabVIEW's code page on Windows) are read into UTF-8.
//
// Refused with one line naming the file and line: a second segment header (a file of several
// writes with headers), channels of different lengths, an x dimension other than time, a comma
// as both separator and decimal mark, cells that are not numbers or not finite.
#include <string>

#include "scoleid/io/data_files.h"
#include "scoleid/io/data_source.h"

namespace scoleid::io {

// Whether the text starts as an LVM file ("LabVIEW Measurement" as the first field).
bool looks_like_lvm(const std::string& head);

DataTable read_lvm(const std::string& path);
// The same on text in memory; `source` names it in messages.
DataTable read_lvm_text(const std::string& text, const std::string& source);
DataFileInfo describe_lvm(const std::string& path);

// The table as LabVIEW's "Write To Measurement File" writes one segment: file header (Writer and
// Reader_Version 2, Separator Tab, Decimal_Separator '.', Multi_Headings No, X_Columns One,
// Time_Pref Relative, the write's Date and Time), segment header (Channels; per channel Samples,
// Date, Time, Y_Unit_Label = the column's unit, X_Dimension Time, X0 = the first time, Delta_X =
// the mean step), the row X_Value, names, Comment, then one row per sample: the time in seconds
// and each value, 17 significant digits, so read_lvm gives back every time and value bit for bit.
// Written to a temporary file and renamed into place. InputError naming the path for a table that
// fails check_table or that the format cannot hold: a name or unit with a tab, line break or other
// control character, with a blank at either end (cells are read trimmed), or not UTF-8, and a
// column named X_Value.
void write_lvm(const DataTable& tab, const std::string& path);

}  // namespace scoleid::io
