#pragma once
// Reader for the Universal File Format (UFF, also called UNV): the exchange format of test and
// analysis programs for measured functions, geometry and mode shapes.
//
// A file is a sequence of datasets. Each one is framed by two delimiter lines whose only content
// is "-1" (written "    -1", right-aligned in six columns, possibly blank-padded to 80); the line
// after the opening delimiter holds the dataset number (right-aligned in six columns), followed by
// 'b' when the dataset carries binary data. Blank lines between datasets are allowed; anything
// else is not. Lines may end in LF, CR LF or CR. Records are fixed-format Fortran: fields are
// counted in characters (a UTF-8 sequence is one character; a byte that is not UTF-8 is read as
// Latin-1, or as U+FFFD in 0x80-0x9F), numbers may use a D exponent (1.0D+03) or none at all
// (1.0-105), and adjacent numeric fields may touch ("1.0E+00-2.0E+00"). A line of numbers is
// read as its blank-separated tokens when every token is a number (and, for a record of fixed
// fields, there is one token per field: writers that use wider columns); otherwise at the fixed
// widths, which also separates numbers that touch and keeps blank fields in place.
//
// Supported datasets ("(n)" after a field: its width in characters):
//   151  Header. 7 lines: model name; description; application that created the database;
//        date (10) time (10) version (10) sub-version (10) file type (10) of creation;
//        date (10) time (10) of the last save; program that wrote the file; date (10) time (10)
//        the file was written.
//   164  Units. Line 1: units code (10), description (20), temperature mode (10; 1 absolute,
//        2 relative). Then four numbers, free format over one or more lines: length, force and
//        temperature factors and the temperature offset. The SDRL definition: a value in file
//        units divided by the factor gives SI (mm: length 1000). Some writers store the inverse
//        (foot: 3.048D-01); the factors are reported as written.
//   15   Nodes. One line per node: label, definition coordinate system, displacement coordinate
//        system, colour (4 x 10), x y z (3 x 13).
//   2411 Nodes, double precision. Two lines per node: label, export coordinate system,
//        displacement coordinate system, colour (4 x 10); then x y z (3 x 25, often D exponents).
//   55   Data at nodes (mode shapes, operating shapes). Lines 1-5: ID lines. Line 6 (6 x 10):
//        model type, analysis type, data characteristic (1 scalar, 2 3-DOF translation,
//        3 6-DOF translation and rotation, 4 symmetric tensor, 5 general tensor), specific data
//        type, data type (2 real, 5 complex), number of values per node NDV. Record 7 (10 wide,
//        8 a line): the count NINT of integer parameters, the count NRVAL of real parameters, then
//        the NINT integers (load case; mode, time step or frequency step number). Record 8 (13
//        wide, 6 a line): the NRVAL reals, by analysis type: 2 normal mode: frequency [Hz], modal
//        mass, viscous damping ratio, hysteretic damping ratio; 3 and 7 complex eigenvalue:
//        eigenvalue (re, im), modal A (re, im), modal B (re, im); 4 transient: time; 5 frequency
//        response: frequency [Hz]; 0, 1, 6: one value. Then per node: a line with the node label
//        (10), and NDV values (2 x NDV for complex data, real and imaginary parts interleaved),
//        13 wide, 6 a line.
//   58   Function at nodal DOF, ASCII. Lines 1-5: ID lines (ID 1 usually names the function).
//        Line 6: function type (5), function id (10), version (5), load case (10), response
//        entity (1 blank + 10), node (10), direction (4), reference entity (1 + 10), node (10),
//        direction (4). Line 7: ordinate data type (10; 2 real single, 4 real double, 5 complex
//        single, 6 complex double), number of points (10), abscissa spacing (10; 0 uneven,
//        1 even), abscissa minimum (13), increment (13), z-axis value (13). Lines 8-11, for the
//        abscissa, the ordinate (numerator), the ordinate denominator and the z axis: specific
//        data type (10), length, force and temperature unit exponents (3 x 5), axis label
//        (1 + 20), axis units label (1 + 20). Then the values: single precision 13 wide, 6 a
//        line; double precision 20 wide, 4 a line; an uneven abscissa interleaves x with each
//        ordinate (x y, or x re im), x being 13 wide (double: lines of 13 20 13 20, or 13 20 20).
//        The last line may be short.
//   58b  Function, binary. As 58, but the dataset-number line also holds: byte ordering (1 little
//        endian, 2 big endian), floating-point format (2 IEEE 754), number of ASCII header lines
//        (11), number of bytes of binary data, and four unused fields. Right after the 11th
//        header line's line break come exactly that many bytes: IEEE floats of 4 bytes (ordinate
//        types 2, 5) or 8 bytes (4, 6), in the same order as the ASCII values (an uneven
//        abscissa is interleaved at the same width, as pyuff reads it). The closing "    -1"
//        follows the block directly; stray CR/LF bytes before it are tolerated. The block may
//        contain any bytes, including "-1" and line breaks, so it is skipped by its length. When
//        the declared length is not followed by the closing line but the length implied by the
//        number of points is, the latter is used (some writers declare num_pts x 8 for complex).
//   Any other dataset is skipped (its number and position are listed in File::skipped).
//
// Every malformed input throws InputError with one line naming the file, the record (the
// dataset's 1-based index and the line of its dataset number), the line and field, and the
// offending value. No function may hold more than limits::kMaxSamples values per column, and a
// declared size the file cannot hold is refused before anything is allocated.
#include <cstddef>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace scoleid::io {
struct DataTable;  // data_files.h
}  // namespace scoleid::io

namespace scoleid::io::uff {

// One dataset 58 or 58b.
struct Function {
  std::size_t record = 0;  // 1-based index of the dataset in the file
  std::size_t line = 0;    // line number (1-based) of its dataset-number line
  bool binary = false;
  int value_bytes = 4;                  // precision of the values: 4 (single) or 8 (double)
  std::string id1, id2, id3, id4, id5;  // trimmed
  int function_type = 0;                // see function_type_name
  int function_id = 0, version = 0, load_case = 0;
  // Direction: 0 scalar, +-1..+-3 X Y Z translation, +-4..+-6 X Y Z rotation.
  std::string response_entity;
  int response_node = 0, response_direction = 0;
  std::string reference_entity;
  int reference_node = 0, reference_direction = 0;
  int ordinate_type = 2;                            // 2 real single, 4 real double, 5 complex single, 6 complex double
  bool even = true;                                 // even abscissa spacing (x computed), else x read from the data
  double abscissa_min = 0, abscissa_increment = 0;  // as written (0 for uneven spacing)
  std::size_t points = 0;
  double z_axis_value = 0;
  struct Axis {
    int spec_type = 0;  // specific data type: 17 time, 18 frequency, 8 displacement, 12 acceleration, ...
    int length_exp = 0, force_exp = 0, temperature_exp = 0;
    std::string label, unit;  // trimmed, as written ("NONE" when unused)
  };
  Axis abscissa, ordinate, denominator, z_axis;
  std::vector<double> x;       // abscissa values (even spacing: min + k * increment)
  std::vector<double> re, im;  // ordinate; im is empty when the ordinate is real
  bool is_complex() const { return ordinate_type == 5 || ordinate_type == 6; }
};

// Dataset 164.
struct Units {
  std::size_t record = 0, line = 0;
  int code = 0;  // 1 SI, 2 BG, 3 MG, 4 BA, 5 MM, 6 CM, 7 IN, 8 GM, 9 user defined, 10 MN
  std::string description;
  int temperature_mode = 0;                                               // 1 absolute, 2 relative, 0 not given
  double length = 1, force = 1, temperature = 1, temperature_offset = 0;  // as written
};

// Dataset 151.
struct Header {
  std::size_t record = 0, line = 0;
  std::string model_name, description, application;
  std::string created;                              // "<date> <time>" as written (either may be empty)
  int version = 0, sub_version = 0, file_type = 0;  // file type: 0 universal, 1 archive, 2 other
  std::string saved, program, written;
};

// One node of dataset 15 or 2411.
struct Node {
  int id = 0;
  int coordinate_system = 0;  // definition (15) or export (2411) coordinate system
  int displacement_system = 0;
  int color = 0;
  double x = 0, y = 0, z = 0;
  int dataset = 15;  // 15 or 2411
  std::size_t record = 0;
};

// One dataset 55.
struct Shape {
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  std::size_t record = 0, line = 0;
  std::string id1, id2, id3, id4, id5;
  int model_type = 0;               // 0 unknown, 1 structural, 2 heat transfer, 3 fluid flow
  int analysis_type = 0;            // 0 unknown, 1 static, 2 normal mode, 3 complex eigenvalue (1st order),
                                    // 4 transient, 5 frequency response, 6 buckling, 7 complex eigenvalue (2nd order)
  int data_characteristic = 0;      // 1 scalar, 2 3-DOF translation, 3 6-DOF, 4/5 tensors
  int specific_data_type = 0;       // 8 displacement, 11 velocity, 12 acceleration, ...
  int data_type = 2;                // 2 (or 4) real, 5 (or 6) complex
  int values_per_node = 0;          // NDV
  std::vector<int> int_parameters;  // record 7 after its two counts
  std::vector<double> real_parameters;  // record 8
  int load_case = 0;
  int mode_number = 0;  // the second integer: mode, time step or frequency step number
  // Interpreted from record 8 where the analysis type gives them, else NaN. For complex
  // eigenvalues (types 3, 7) the frequency is |lambda| / (2 pi) and the damping ratio
  // -Re(lambda) / |lambda|, lambda = eigenvalue in rad/s.
  double frequency_hz = kNaN, modal_mass = kNaN, damping_ratio = kNaN, hysteretic_damping = kNaN;
  double eigenvalue_re = kNaN, eigenvalue_im = kNaN;
  double modal_a_re = kNaN, modal_a_im = kNaN, modal_b_re = kNaN, modal_b_im = kNaN;
  std::vector<int> nodes;
  std::vector<std::vector<double>> values;     // per node, NDV values (real parts)
  std::vector<std::vector<double>> values_im;  // per node, NDV imaginary parts; empty when real
  bool is_complex() const { return data_type == 5 || data_type == 6; }
};

// A dataset this reader does not interpret.
struct Skipped {
  int dataset = 0;
  bool binary = false;
  std::size_t record = 0, line = 0;
};

struct File {
  std::string source;
  std::optional<Header> header;  // the first dataset 151
  std::optional<Units> units;    // the first dataset 164
  std::vector<Node> nodes;       // datasets 15 and 2411, in file order
  std::vector<Function> functions;
  std::vector<Shape> shapes;
  std::vector<Skipped> skipped;
  std::size_t datasets = 0;  // number of datasets in the file
};

// InputError on a missing or unreadable file, and on any malformed content.
File read_file(const std::string& path);
// The same on the whole file's bytes; `source` names it in messages.
File parse(const std::string& bytes, const std::string& source);
// True when the text starts (after an optional UTF-8 byte-order mark and blank lines) with a
// "-1" delimiter line. `first_bytes` may be any prefix of a file.
bool looks_like_uff(const std::string& first_bytes);

// Writes a record (a table of time responses on one time grid) as a Universal File: a header
// (dataset 151), then per column one dataset 58b — function type 1 (time response), response node
// = the column's 1-based index, scalar; ID line 1 the column's name; ordinate real double
// (type 4), little-endian IEEE 754; abscissa time in s (specific type 17); ordinate units label
// the column's unit, its specific data type from the unit's quantity (12 acceleration,
// 11 velocity, 8 displacement, 13 force, 3 strain, else 0). The abscissa is even (minimum and
// increment in the 13-character header fields) when x_k = minimum + k·increment read back from
// those fields gives every time exactly, else uneven with each time interleaved before its value
// in double precision. read_file gives back every name, unit, time and value bit for bit.
// Written to a temporary file and renamed into place. InputError naming the path for a table that
// fails check_table or that the format cannot hold: a name that is not printable UTF-8 of 1..80
// bytes without a blank at either end (ID line 1), or is NONE in any case, or ends in '#<number>' (the
// reader's mark of a repeated name); a unit over 20 bytes (the axis units label).
void write_file(const DataTable& tab, const std::string& path);

// "General", "Time Response", "Frequency Response Function", ... ("Unknown" outside 0..27).
std::string function_type_name(int type);
// "+X", "-Z", "+RX", "" for 0 (scalar), "?<n>" outside -6..6.
std::string direction_name(int direction);
// ID line 1 when it is neither empty nor NONE; else "<entity>:<node><direction>" (e.g.
// "acc:3+Z"), "<node><direction>" when the entity is empty or NONE, or "function<record>" when
// there is nothing at all.
std::string channel_name(const Function& f);
// channel_name of every function, made unique in file order: "name", "name#2", "name#3", ...
std::vector<std::string> channel_names(const File& file);
// The axis units label when it is neither empty nor NONE; else "" (unknown).
std::string ordinate_unit(const Function& f);
std::string abscissa_unit(const Function& f);

}  // namespace scoleid::io::uff
