#pragma once
// NI TDMS files (.tdms, the binary format LabVIEW's TDMS functions and DAQmx logging write), read
// as one record of time responses (docs/data.md "TDMS").
//
// Layout: a sequence of segments. Each starts with a 28-byte lead-in: the tag "TDSm", the table of
// contents (a bit mask, always little-endian: metadata 1<<1, new object list 1<<2, raw data 1<<3,
// interleaved 1<<5, big-endian 1<<6, DAQmx raw data 1<<7), the version (4712 or 4713), the offset
// of the next segment and the offset of the raw data, both counted from the end of the lead-in.
// The metadata lists objects by path ("/" the file, "/'group'", "/'group'/'channel'", a quote in
// a name doubled), each with its raw data index (0xFFFFFFFF no data in this segment, 0 the same as
// in the previous segment, else 20 or 28 bytes: data type, dimension 1, number of values, for text
// the total size) and its properties (name, type, value). Metadata is incremental: a segment
// without metadata repeats the previous segment's objects; one without the new-object-list bit
// keeps them and updates or appends the objects it lists. The raw data is one or more chunks, each
// the listed channels' values in list order, contiguous (channel after channel) or interleaved
// (one value of each channel per row), little- or big-endian.
//
// Channels read: int8 ... int64, uint8 ... uint64, float32, float64 (also "with unit"), boolean
// (0/1), timestamps (as a time channel); text channels are left out and noted, as are channels
// without a sample. Properties: unit_string (the column's unit, read by units.h's alias table as
// LVM's Y_Unit_Label), wf_increment and wf_start_offset (the sample times), NI_Scaling_Status and
// NI_Scale[n]_* (linear scales are applied; a chain of them composed).
//
// The record: the channels holding samples, from every group that holds any (a channel name held
// in two groups becomes "group/channel"). Time: the first channel named "Time" or "t" (any case, a
// bracketed unit allowed: "Time [ms]") or of timestamp type (seconds after its first value) becomes
// t, in seconds from its bracketed unit or unit_string; otherwise t_k = wf_start_offset +
// k·wf_increment (in wf_xunit_string, seconds when absent), which every channel must share.
//
// Refused with one line naming the file and the segment (byte offset), object or channel: no
// "TDSm" tag, a version other than 4712/4713, DAQmx raw data, a data type this reader does not
// take (extended, fixed point, complex, unknown) in a channel that holds samples, sizes that
// exceed the file, raw data that is not a whole number of chunks, channels of different lengths
// or sampling (wf_increment, wf_start_offset), no time channel and no wf_increment, a scale that
// is not linear, values that are not finite. A last segment cut short (its next-segment offset
// 0xFFFFFFFFFFFFFFFF or past the end of the file) is read to its last whole chunk; it is refused
// only when nothing at all is complete.
#include <string>

#include "scoleid/io/data_files.h"
#include "scoleid/io/data_source.h"

namespace scoleid::io {

// Whether the bytes start as a TDMS file (the lead-in tag "TDSm").
bool looks_like_tdms(const std::string& head);

DataTable read_tdms(const std::string& path);
// The same on bytes in memory; `source` names them in messages.
DataTable read_tdms_bytes(const std::string& bytes, const std::string& source);
DataFileInfo describe_tdms(const std::string& path);

// The table as one TDMS segment (version 4713, little-endian, contiguous raw data in one chunk):
// the file object, one group "record" and one float64 channel per column, named as the column,
// with unit_string (the column's unit, when it states one). The times are written as
// wf_start_offset (the first time) and wf_increment (wf_samples, wf_xname "Time", wf_xunit_string
// "s" beside them) when t_k = wf_start_offset + k·wf_increment gives every time exactly; otherwise,
// and when a column's name reads as a time channel's, as a float64 channel "Time" (unit_string "s",
// or "t", "Time [s]", "t [s]" when a column takes that name) before the others. read_tdms gives
// back every time and value bit for bit. Written to a temporary file and renamed into place.
// InputError naming the path for a table that fails check_table or whose names or units are not
// UTF-8 text, or whose units begin or end with a blank.
void write_tdms(const DataTable& tab, const std::string& path);

}  // namespace scoleid::io
