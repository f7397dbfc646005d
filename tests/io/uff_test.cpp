// Tests of the UFF reader. The expected numbers for the files in tests/data/uff are pyuff 2.5.6's
// reading of the same files (pyuff.UFF(path).read_sets(i), printed with repr), except where a
// comment says otherwise.
#include "scoleid/io/uff.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <numeric>
#include <optional>
#include <stdexcept>

#include "common/cli_support.h"
#include "scoleid/io/error.h"

#ifndef SCOLEID_TEST_DATA_DIR
#error "SCOLEID_TEST_DATA_DIR must name the tests/data directory"
#endif

using namespace scoleid::io;

namespace {

std::string data_path(const std::string& name) { return std::string(SCOLEID_TEST_DATA_DIR) + "/uff/" + name; }

using scoleid::test::slurp;

// The one dataset 58 (or 55) of a file in tests/data/uff that holds just one.
uff::Function only_function(const std::string& name) {
  auto f = uff::read_file(data_path(name));
  if (f.functions.size() != 1) throw std::runtime_error(name + ": expected one function");
  return f.functions[0];
}
uff::Shape only_shape(const std::string& name) {
  auto f = uff::read_file(data_path(name));
  if (f.shapes.size() != 1) throw std::runtime_error(name + ": expected one shape");
  return f.shapes[0];
}

// Samples of a series at given indices; `exact` compares bit for bit, otherwise to 4 ULP.
void expect_samples(const std::vector<double>& v, std::initializer_list<std::pair<std::size_t, double>> want,
                    bool exact = false) {
  for (const auto& [i, value] : want) {
    ASSERT_LT(i, v.size());
    if (exact)
      EXPECT_EQ(v[i], value) << "sample " << i;
    else
      EXPECT_DOUBLE_EQ(v[i], value) << "sample " << i;
  }
}

// Dataset 164 as the file states it: the code, description, temperature mode and the four
// factors (length, force, temperature, temperature offset), each compared exactly.
void expect_units(const std::optional<uff::Units>& u, int code, const std::string& description, int mode,
                  const std::array<double, 4>& factors) {
  ASSERT_TRUE(u);
  EXPECT_EQ(u->code, code);
  EXPECT_EQ(u->description, description);
  EXPECT_EQ(u->temperature_mode, mode);
  EXPECT_EQ((std::array<double, 4>{u->length, u->force, u->temperature, u->temperature_offset}), factors);
}

// A node as dataset 15 or 2411 states it: label, the two coordinate systems, colour and position.
struct NodeRow {
  int id, coordinate_system, displacement_system, color;
  double x, y, z;
};
void expect_node(const uff::Node& n, const NodeRow& want) {
  EXPECT_EQ((std::array<int, 4>{n.id, n.coordinate_system, n.displacement_system, n.color}),
            (std::array<int, 4>{want.id, want.coordinate_system, want.displacement_system, want.color}))
      << "node " << want.id;
  EXPECT_EQ((std::array<double, 3>{n.x, n.y, n.z}), (std::array<double, 3>{want.x, want.y, want.z}))
      << "node " << want.id;
}

// The message of the InputError parsing `bytes` throws; "" when it parses. Anything else fails.
std::string error_of(const std::string& bytes, const std::string& source = "t.uff") {
  try {
    uff::parse(bytes, source);
  } catch (const InputError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not an InputError: " << e.what();
  }
  return "";
}

::testing::AssertionResult Contains(const std::string& text, const std::string& part) {
  if (text.find(part) != std::string::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "'" << text << "'\n  does not contain\n'" << part << "'";
}

std::string replace_once(std::string s, const std::string& from, const std::string& to) {
  const auto at = s.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) s.replace(at, from.size(), to);
  return s;
}

// Each edit of `base` (its first `from` replaced by `to`) is refused with a message holding `message`.
struct Edit {
  std::string from, to, message;
};
void expect_refused(const std::string& base, std::initializer_list<Edit> edits) {
  for (const auto& e : edits) EXPECT_TRUE(Contains(error_of(replace_once(base, e.from, e.to)), e.message)) << e.to;
}

std::string format(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
std::string format(const char* fmt, ...) {
  char buf[512];
  va_list ap;
  va_start(ap, fmt);
  std::vsnprintf(buf, sizeof buf, fmt, ap);
  va_end(ap);
  return buf;
}

// The 11 header lines of a dataset 58 (records 1-11), as the format lays them out.
std::string header58(int ordinate_type, int points, int even, double min, double inc, const std::string& id1 = "NONE",
                     const std::string& entity = "acc", int node = 3, int dir = 3) {
  std::string h = id1 + "\nNONE\nNONE\nNONE\nNONE\n";
  h += format("%5d%10d%5d%10d %-10s%10d%4d %-10s%10d%4d\n", 4, 0, 0, 0, entity.c_str(), node, dir, "force", 1, 3);
  h += format("%10d%10d%10d%13.5e%13.5e%13.5e\n", ordinate_type, points, even, min, inc, 0.0);
  h += format("%10d%5d%5d%5d %-20s %-20s\n", 18, 0, 0, 0, "Frequency", "Hz");
  h += format("%10d%5d%5d%5d %-20s %-20s\n", 12, 0, 0, 0, "Acceleration", "m/s^2");
  h += format("%10d%5d%5d%5d %-20s %-20s\n", 13, 0, 0, 0, "Force", "N");
  h += format("%10d%5d%5d%5d %-20s %-20s\n", 0, 0, 0, 0, "NONE", "NONE");
  return h;
}

std::string binary_line(int order, std::size_t n_bytes) {
  return format("%6d%c%6d%6d%12d%12zu%6d%6d%12d%12d\n", 58, 'b', order, 2, 11, n_bytes, 0, 0, 0, 0);
}

std::string big_endian_double(double v) {
  unsigned char b[8];
  std::memcpy(b, &v, 8);
  const std::uint16_t one = 1;
  unsigned char first = 0;
  std::memcpy(&first, &one, 1);
  if (first == 1) std::reverse(b, b + 8);
  return std::string(reinterpret_cast<const char*>(b), 8);
}

double from_big_endian(const std::string& bytes) {
  unsigned char b[8];
  std::memcpy(b, bytes.data(), 8);
  const std::uint16_t one = 1;
  unsigned char first = 0;
  std::memcpy(&first, &one, 1);
  if (first == 1) std::reverse(b, b + 8);
  double v = 0;
  std::memcpy(&v, b, 8);
  return v;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// pyuff's files: dataset 58 and 58b.

TEST(UffFunctions, SampleAsciiMatchesPyuff) {
  const auto f = uff::read_file(data_path("Sample_UFF58_ascii.uff"));
  ASSERT_EQ(f.datasets, 1u);
  ASSERT_EQ(f.functions.size(), 1u);
  EXPECT_TRUE(f.skipped.empty());
  const auto& g = f.functions[0];
  EXPECT_EQ(g.record, 1u);
  EXPECT_EQ(g.line, 2u);
  EXPECT_FALSE(g.binary);
  EXPECT_EQ(g.value_bytes, 4);
  EXPECT_EQ(g.id1, "Mic 01.0Scalar");
  EXPECT_EQ(g.id3, "18-Apr-16 13:49:58");
  EXPECT_EQ(g.function_type, 1);
  EXPECT_EQ(g.response_entity, "Mic 01");
  EXPECT_EQ(g.response_node, 0);
  EXPECT_EQ(g.response_direction, 1);
  EXPECT_EQ(g.reference_entity, "NONE");
  EXPECT_EQ(g.ordinate_type, 2);
  EXPECT_TRUE(g.even);
  EXPECT_FALSE(g.is_complex());
  EXPECT_EQ(g.points, 79292u);
  EXPECT_EQ(g.abscissa_min, 0.0);
  EXPECT_EQ(g.abscissa_increment, 1.52588e-05);
  EXPECT_EQ(g.abscissa.spec_type, 17);
  EXPECT_EQ(g.abscissa.label, "time");
  EXPECT_EQ(g.ordinate.spec_type, 21);
  EXPECT_EQ(g.ordinate.label, "Pressure");
  EXPECT_EQ(uff::abscissa_unit(g), "s");
  EXPECT_EQ(uff::ordinate_unit(g), "Pa");
  EXPECT_EQ(g.denominator.unit, "NONE");
  ASSERT_EQ(g.x.size(), 79292u);
  ASSERT_EQ(g.re.size(), 79292u);
  EXPECT_TRUE(g.im.empty());
  // pyuff: x[12345] 0.18836988600000001, x[39646] 0.6049503848, x[79291] 1.2098855108
  expect_samples(g.x, {{12345, 0.18836988600000001}, {39646, 0.6049503848}, {79291, 1.2098855108}});
  // pyuff: data[0] -0.0147553, [1] -0.0172957, [12345] 0.000389349, [39646] -0.010217,
  // [79290] 0.000443632, [79291] -0.00431469; sum 5.715039728042097
  expect_samples(g.re, {{0, -0.0147553},
                        {1, -0.0172957},
                        {12345, 0.000389349},
                        {39646, -0.010217},
                        {79290, 0.000443632},
                        {79291, -0.00431469}});
  EXPECT_NEAR(std::accumulate(g.re.begin(), g.re.end(), 0.0), 5.715039728042097, 1e-9);
}

TEST(UffFunctions, SampleBinaryMatchesPyuff) {
  const auto f = uff::read_file(data_path("Sample_UFF58b_bin.uff"));
  ASSERT_EQ(f.datasets, 1u);
  ASSERT_EQ(f.functions.size(), 1u);
  const auto& g = f.functions[0];
  EXPECT_TRUE(g.binary);
  EXPECT_EQ(g.value_bytes, 4);
  EXPECT_EQ(g.id1, "Mic 01.0Scalar");
  EXPECT_EQ(g.points, 79292u);
  EXPECT_EQ(g.abscissa_increment, 1.52588e-05);
  EXPECT_EQ(uff::ordinate_unit(g), "Pa");
  ASSERT_EQ(g.re.size(), 79292u);
  ASSERT_EQ(g.x.size(), 79292u);
  // pyuff (4-byte floats widened to double, so exact): data[0] -0.014755260199308395,
  // [1] -0.017295705154538155, [12345] 0.00038934865733608603, [39646] -0.010216998867690563,
  // [79291] -0.004314688965678215; sum 5.715040058740556
  expect_samples(g.re,
                 {{0, -0.014755260199308395},
                  {1, -0.017295705154538155},
                  {12345, 0.00038934865733608603},
                  {39646, -0.010216998867690563},
                  {79291, -0.004314688965678215}},
                 true);
  EXPECT_DOUBLE_EQ(g.x[79291], 1.2098855108);
  EXPECT_NEAR(std::accumulate(g.re.begin(), g.re.end(), 0.0), 5.715040058740556, 1e-9);
}

TEST(UffFunctions, AsciiAndBinaryCopiesAgreeToThePrintedPrecision) {
  // The two sample files hold the same signal; pyuff's largest relative difference is 4.996e-6
  // (six significant digits in E13.5).
  const auto a = uff::read_file(data_path("Sample_UFF58_ascii.uff")).functions.at(0);
  const auto b = uff::read_file(data_path("Sample_UFF58b_bin.uff")).functions.at(0);
  ASSERT_EQ(a.re.size(), b.re.size());
  EXPECT_EQ(a.x, b.x);
  for (std::size_t i = 0; i < a.re.size(); ++i)
    ASSERT_LE(std::abs(a.re[i] - b.re[i]), 5.0e-6 * std::abs(b.re[i]) + 1e-300) << i;
}

TEST(UffFunctions, EightByteBinaryMatchesPyuff) {
  const auto g = only_function("binary8byte.uff");
  EXPECT_TRUE(g.binary);
  EXPECT_EQ(g.value_bytes, 8);
  EXPECT_EQ(g.ordinate_type, 4);
  EXPECT_EQ(g.points, 250u);
  EXPECT_EQ(g.id1, "NONE");
  EXPECT_EQ(g.response_entity, "sine 5 Hz");
  EXPECT_EQ(g.response_node, 1);
  EXPECT_EQ(g.abscissa.label, "time (s)");
  EXPECT_EQ(g.ordinate.label, "acc (g)");
  EXPECT_EQ(uff::ordinate_unit(g), "g");
  EXPECT_EQ(g.ordinate.spec_type, 12);
  // pyuff: x[37] 0.37, x[249] 2.49; data[1] 0.30901697278022766, [37] -0.80901700258255,
  // [125] 1.0, [249] 0.3090193569660187; sum 6.313748425276373
  expect_samples(g.x, {{37, 0.37}, {249, 2.49}});
  expect_samples(
      g.re, {{0, 0.0}, {1, 0.30901697278022766}, {37, -0.80901700258255}, {125, 1.0}, {249, 0.3090193569660187}}, true);
  EXPECT_NEAR(std::accumulate(g.re.begin(), g.re.end(), 0.0), 6.313748425276373, 1e-12);
  EXPECT_EQ(uff::channel_name(g), "sine 5 Hz:1");  // ID 1 is NONE: entity, node, scalar direction
}

TEST(UffFunctions, ShortLastLineMatchesPyuff) {
  const auto g = only_function("time-history-not-all-columns-filled.uff");
  EXPECT_EQ(g.id1, "1x : m/s\xC2\xB2");
  EXPECT_EQ(g.id2, "UFF58 file created by HBM catman");
  EXPECT_EQ(g.points, 13u);
  EXPECT_EQ(g.abscissa_increment, 5e-05);
  EXPECT_EQ(uff::ordinate_unit(g), "m/s\xC2\xB2");
  EXPECT_EQ(uff::abscissa_unit(g), "s");
  // pyuff's data, all 13 values (the last line holds one)
  const std::vector<double> expected = {-3.81956, -3.56616, -2.98987, -2.62207, -3.22879, -3.63712, -3.9021,
                                        -3.69214, -3.42426, -3.48508, -4.03966, -3.46046, -5.84096};
  ASSERT_EQ(g.re.size(), 13u);
  for (std::size_t i = 0; i < 13; ++i) EXPECT_DOUBLE_EQ(g.re[i], expected[i]) << i;
  EXPECT_DOUBLE_EQ(g.x[12], 0.0006000000000000001);
}

TEST(UffFunctions, ComplexEvenMatchesPyuffAndDecodesLatin1Units) {
  const auto g = only_function("non_ascii_header.uff");
  EXPECT_EQ(g.function_type, 4);
  EXPECT_EQ(uff::function_type_name(g.function_type), "Frequency Response Function");
  EXPECT_EQ(g.ordinate_type, 5);
  EXPECT_TRUE(g.is_complex());
  EXPECT_EQ(g.id5, "H1 : #  2 / #  1");
  // The unit's last byte is 0xB2 (Latin-1 superscript two, not UTF-8): pyuff shows U+FFFD, this
  // reader the character it stands for.
  EXPECT_EQ(uff::ordinate_unit(g), "(1/N)*(m/s\xC2\xB2)");
  EXPECT_EQ(g.ordinate.label, "Frequency Function");
  // pyuff: x 0, 0.195313, ..., 0.9765649999999999; data 0.407994+0j, -0.0599924-0.055326j,
  // 0.025875-0.000230085j, -0.299003+0.317213j, -1.8025+1.55302j, 3.75037+2.93363j
  const std::vector<double> re = {0.407994, -0.0599924, 0.025875, -0.299003, -1.8025, 3.75037};
  const std::vector<double> im = {0.0, -0.055326, -0.000230085, 0.317213, 1.55302, 2.93363};
  ASSERT_EQ(g.re.size(), 6u);
  ASSERT_EQ(g.im.size(), 6u);
  for (std::size_t i = 0; i < 6; ++i) {
    EXPECT_DOUBLE_EQ(g.re[i], re[i]);
    EXPECT_DOUBLE_EQ(g.im[i], im[i]);
  }
  EXPECT_DOUBLE_EQ(g.x[5], 0.9765649999999999);
  EXPECT_EQ(uff::channel_name(g), "ref6_23_Mar");
}

TEST(UffFunctions, ComplexUnevenPsdMatchesPyuff) {
  const auto g = only_function("sample_dataset58_psd.uff");
  EXPECT_EQ(g.function_type, 9);
  EXPECT_EQ(uff::function_type_name(9), "Power Spectral Density");
  EXPECT_EQ(g.ordinate_type, 5);
  EXPECT_FALSE(g.even);
  EXPECT_EQ(g.points, 3201u);
  EXPECT_EQ(g.response_entity, "Pilot 1");
  EXPECT_EQ(uff::abscissa_unit(g), "Hz");
  EXPECT_EQ(uff::ordinate_unit(g), "g\xC2\xB2/Hz");  // 0xB2 in the file, as above
  ASSERT_EQ(g.x.size(), 3201u);
  ASSERT_EQ(g.im.size(), 3201u);
  // pyuff: x[k] = k; data[1] 1.255863e-06, [100] 0.00015045, [1600] 0.0003215418,
  // [3200] 2.634827e-10, all imaginary parts 0; sum of real parts 0.31306925539025443
  expect_samples(g.x, {{0, 0.0}, {1600, 1600.0}, {3200, 3200.0}}, true);
  EXPECT_EQ(g.re[0], 0.0);
  expect_samples(g.re, {{1, 1.255863e-06}, {100, 0.00015045}, {1600, 0.0003215418}, {3200, 2.634827e-10}});
  EXPECT_TRUE(std::all_of(g.im.begin(), g.im.end(), [](double v) { return v == 0.0; }));
  EXPECT_NEAR(std::accumulate(g.re.begin(), g.re.end(), 0.0), 0.31306925539025443, 1e-13);
}

// ---------------------------------------------------------------------------------------------
// pyuff's files: header, units, nodes, skipped datasets.

TEST(UffModel, TestLabHeaderUnitsNodesMatchPyuff) {
  const auto f = uff::read_file(data_path("TestLab_161_164_18_15_82.uff"));
  EXPECT_EQ(f.datasets, 7u);
  ASSERT_TRUE(f.header);
  EXPECT_EQ(f.header->record, 1u);
  EXPECT_EQ(f.header->model_name, "AME_Test");
  EXPECT_EQ(f.header->description, "NONE");
  EXPECT_EQ(f.header->application, "LMS Test.Lab Rev project-15A");
  EXPECT_EQ(f.header->created, "11-Oct-17 09:34:21");
  EXPECT_EQ(f.header->saved, "11-Oct-17 09:34:21");
  EXPECT_EQ(f.header->program, "LMS Test.Lab Rev project-15A");
  EXPECT_EQ(f.header->written, "17-Oct-17 13:50:13");
  EXPECT_EQ(f.header->version, 0);
  expect_units(f.units, 9, "USER_DEFINED", 0, {1.0, 1.0, 1.0, -273.15});  // mode blank; pyuff: -273.15
  EXPECT_EQ(f.units->record, 2u);
  // Dataset 15: pyuff's node_nums, def_cs, disp_cs, color, x, y, z for nodes 1, 7, 21, 36.
  ASSERT_EQ(f.nodes.size(), 36u);
  EXPECT_EQ(f.nodes[0].dataset, 15);
  EXPECT_EQ(f.nodes[0].record, 4u);
  expect_node(f.nodes[0], {1, 0, 1, 8, -2.4, -0.95, 0.0});
  expect_node(f.nodes[6], {7, 0, 7, 8, -1.75, 0.0, 0.1});
  expect_node(f.nodes[20], {21, 0, 21, 8, -1.55, 0.81, 1.4});
  expect_node(f.nodes[35], {36, 0, 36, 8, 1.2, 8.4, 0.0});
  // pyuff's set types: 151, 164, 18, 15, 82, 82, 82 — 18 and 82 are not interpreted here.
  ASSERT_EQ(f.skipped.size(), 4u);
  EXPECT_EQ(f.skipped[0].dataset, 18);
  EXPECT_EQ(f.skipped[0].record, 3u);
  EXPECT_EQ(f.skipped[0].line, 18u);
  for (std::size_t k = 1; k < 4; ++k) {
    EXPECT_EQ(f.skipped[k].dataset, 82);
    EXPECT_EQ(f.skipped[k].record, 4 + k);
  }
  EXPECT_EQ(f.skipped[1].line, 204u);
  EXPECT_TRUE(f.functions.empty());
  EXPECT_TRUE(f.shapes.empty());
}

TEST(UffModel, HeatEngineHeaderUnitsNodes2411MatchPyuff) {
  const auto f = uff::read_file(data_path("heat_engine_housing.uff"));
  EXPECT_EQ(f.datasets, 5u);
  ASSERT_TRUE(f.header);
  EXPECT_EQ(f.header->model_name, "");
  EXPECT_EQ(f.header->created, "");
  EXPECT_EQ(f.header->program, "VKI 453 24-Feb-23 22:10:15");
  EXPECT_EQ(f.header->written, "24-Feb-23 22:10:15");
  expect_units(f.units, 5, "", 2, {1000.0, 1000.0, 1.0, 273.15});  // pyuff: 1000.0, 1000.0, 1.0, 273.15
  ASSERT_EQ(f.nodes.size(), 10u);
  // pyuff: node 1: -171.1755676269531 103.6403427124023 138.48291015625; node 5: -164.6755676269531
  // 96.99696350097656 147.48291015625; node 10: -147.6755676269531 101.9969635009766 147.48291015625
  EXPECT_EQ(f.nodes[0].dataset, 2411);
  expect_node(f.nodes[0], {1, 0, 0, 11, -171.1755676269531, 103.6403427124023, 138.48291015625});
  expect_node(f.nodes[4], {5, 0, 0, 11, -164.6755676269531, 96.99696350097656, 147.48291015625});
  expect_node(f.nodes[9], {10, 0, 0, 11, -147.6755676269531, 101.9969635009766, 147.48291015625});
  ASSERT_EQ(f.skipped.size(), 2u);
  EXPECT_EQ(f.skipped[0].dataset, 2412);
  EXPECT_EQ(f.skipped[0].record, 4u);
  EXPECT_EQ(f.skipped[1].dataset, 2414);
  EXPECT_EQ(f.skipped[1].record, 5u);
}

// ---------------------------------------------------------------------------------------------
// pyuff's files: dataset 55.

TEST(UffShapes, TranslationModesMatchPyuff) {
  const auto f = uff::read_file(data_path("uff55_translation.uff"));
  ASSERT_EQ(f.shapes.size(), 3u);
  const double freq[] = {10.0, 12.0, 13.0};
  // pyuff's r1 (= r2 = r3) at nodes 1, 3, 4 of each mode
  const double v[3][3] = {
      {-1.46518, -0.376396, 0.724863}, {1.82904, -0.500397, 1.98289}, {-0.63467, 1.48845, -0.795555}};
  for (int m = 0; m < 3; ++m) {
    const auto& s = f.shapes[static_cast<std::size_t>(m)];
    EXPECT_EQ(s.record, static_cast<std::size_t>(m + 1));
    EXPECT_EQ(s.model_type, 1);
    EXPECT_EQ(s.analysis_type, 2);
    EXPECT_EQ(s.data_characteristic, 2);
    EXPECT_EQ(s.specific_data_type, 8);
    EXPECT_EQ(s.data_type, 2);
    EXPECT_EQ(s.values_per_node, 3);
    EXPECT_EQ(s.load_case, 1);
    EXPECT_EQ(s.mode_number, m + 1);
    EXPECT_EQ(s.frequency_hz, freq[m]);
    EXPECT_EQ(s.modal_mass, 0.0);
    EXPECT_EQ(s.damping_ratio, 0.0);
    EXPECT_FALSE(s.is_complex());
    EXPECT_TRUE(s.values_im.empty());
    ASSERT_EQ(s.nodes, (std::vector<int>{1, 2, 3, 4}));
    ASSERT_EQ(s.values.size(), 4u);
    const std::size_t at[] = {0, 2, 3};
    for (int k = 0; k < 3; ++k)
      for (int d = 0; d < 3; ++d) EXPECT_DOUBLE_EQ(s.values[at[k]][static_cast<std::size_t>(d)], v[m][k]);
  }
  EXPECT_EQ(f.shapes[1].line, 21u);
}

TEST(UffShapes, SixDofModeMatchesPyuff) {
  const auto s = only_shape("uff55_translation_rotation.uff");
  EXPECT_EQ(s.data_characteristic, 3);
  EXPECT_EQ(s.values_per_node, 6);
  EXPECT_DOUBLE_EQ(s.frequency_hz, 97.013);  // pyuff: 97.013, mode 0, load case 0
  EXPECT_EQ(s.mode_number, 0);
  ASSERT_EQ(s.nodes.size(), 43u);
  // pyuff: node 1 [0.053569, 0.020271, 0.0046623, 0, 0, 0]; node 22 [-0.013853, -0.00077722,
  // -0.010849, 0, 0, 0]; node 43 [0.0027381, 0.61222, -0.81751, 0, 0, 0]
  EXPECT_EQ(s.nodes[0], 1);
  EXPECT_EQ(s.nodes[21], 22);
  EXPECT_EQ(s.nodes[42], 43);
  const std::vector<double> n1 = {0.053569, 0.020271, 0.0046623, 0, 0, 0};
  const std::vector<double> n22 = {-0.013853, -0.00077722, -0.010849, 0, 0, 0};
  const std::vector<double> n43 = {0.0027381, 0.61222, -0.81751, 0, 0, 0};
  for (std::size_t d = 0; d < 6; ++d) {
    EXPECT_DOUBLE_EQ(s.values[0][d], n1[d]);
    EXPECT_DOUBLE_EQ(s.values[21][d], n22[d]);
    EXPECT_DOUBLE_EQ(s.values[42][d], n43[d]);
  }
}

TEST(UffShapes, ComplexEigenvalueModeMatchesPyuff) {
  // Record 10 values touch ("4.111111E+03-3.111111E+03") and the node label 60101 is written
  // 11 wide: fixed widths and blank separation both matter.
  const auto s = only_shape("uff55_sample_test_record10.uff");
  EXPECT_EQ(s.id1, "TESTTEST:Cfg=0:C1:trans:111121");
  EXPECT_EQ(s.id5, "999999         3         8        13");
  EXPECT_EQ(s.analysis_type, 3);
  EXPECT_EQ(s.data_type, 5);
  EXPECT_TRUE(s.is_complex());
  EXPECT_EQ(s.load_case, 0);
  EXPECT_EQ(s.mode_number, 1);
  // pyuff: eig -0.1111111+41.11111j, modal_a 4111.111-3111.111j, modal_b -111111-211111j
  EXPECT_DOUBLE_EQ(s.eigenvalue_re, -0.1111111);
  EXPECT_DOUBLE_EQ(s.eigenvalue_im, 41.11111);
  EXPECT_DOUBLE_EQ(s.modal_a_re, 4111.111);
  EXPECT_DOUBLE_EQ(s.modal_a_im, -3111.111);
  EXPECT_DOUBLE_EQ(s.modal_b_re, -111111);
  EXPECT_DOUBLE_EQ(s.modal_b_im, -211111);
  // Derived here (pyuff gives only the eigenvalue): |lambda| / 2 pi and -Re lambda / |lambda|.
  const double mag = std::hypot(-0.1111111, 41.11111);
  EXPECT_DOUBLE_EQ(s.frequency_hz, mag / (2 * 3.14159265358979323846));
  EXPECT_DOUBLE_EQ(s.damping_ratio, 0.1111111 / mag);
  EXPECT_TRUE(std::isnan(s.modal_mass));
  // pyuff: node 111111: 0j, 0.1111111+0.09111111j, 0.007111111+0.004111111j;
  //        node 60101: 0j, 0j, -0.04111111-0.01111111j
  ASSERT_EQ(s.nodes, (std::vector<int>{111111, 60101}));
  ASSERT_EQ(s.values_im.size(), 2u);
  EXPECT_EQ(s.values[0][0], 0.0);
  EXPECT_DOUBLE_EQ(s.values[0][1], 0.1111111);
  EXPECT_DOUBLE_EQ(s.values_im[0][1], 0.09111111);
  EXPECT_DOUBLE_EQ(s.values[0][2], 0.007111111);
  EXPECT_DOUBLE_EQ(s.values_im[0][2], 0.004111111);
  EXPECT_EQ(s.values[1][1], 0.0);
  EXPECT_DOUBLE_EQ(s.values[1][2], -0.04111111);
  EXPECT_DOUBLE_EQ(s.values_im[1][2], -0.01111111);
}

// ---------------------------------------------------------------------------------------------
// Layouts not covered by the files above (constructed here; values checked against themselves).

TEST(UffFunctions, DoublePrecisionLayouts) {
  // Real double uneven: lines of E13.5, E20.12 pairs; complex double uneven: E13.5, 2E20.12;
  // complex double even: 4E20.12 with a short last line.
  std::string text = "    -1\n    58\n" + header58(4, 3, 0, 0, 0, "real uneven");
  text += format("%13.5e%20.12e%13.5e%20.12e\n%13.5e%20.12e\n", 1.0, 0.1234567890123, 2.0, -2.5, 4.0, 1e-300);
  text += "    -1\n    -1\n    58\n" + header58(6, 2, 0, 0, 0, "complex uneven");
  text += format("%13.5e%20.12e%20.12e\n%13.5e%20.12e%20.12e\n", 1.0, 1.5, -0.5, 3.0, -2.0, 0.25);
  text += "    -1\n    -1\n    58\n" + header58(6, 3, 1, 10.0, 0.5, "complex even");
  text += format("%20.12e%20.12e%20.12e%20.12e\n%20.12e%20.12e\n", 1.0, 2.0, 3.0, 4.0, 5.0, -6.0);
  text += "    -1\n";
  const auto f = uff::parse(text, "t.uff");
  ASSERT_EQ(f.functions.size(), 3u);
  const auto& a = f.functions[0];
  EXPECT_EQ(a.value_bytes, 8);
  EXPECT_EQ(a.x, (std::vector<double>{1.0, 2.0, 4.0}));
  EXPECT_EQ(a.re, (std::vector<double>{0.1234567890123, -2.5, 1e-300}));
  EXPECT_TRUE(a.im.empty());
  const auto& b = f.functions[1];
  EXPECT_EQ(b.x, (std::vector<double>{1.0, 3.0}));
  EXPECT_EQ(b.re, (std::vector<double>{1.5, -2.0}));
  EXPECT_EQ(b.im, (std::vector<double>{-0.5, 0.25}));
  const auto& c = f.functions[2];
  EXPECT_EQ(c.x, (std::vector<double>{10.0, 10.5, 11.0}));
  EXPECT_EQ(c.re, (std::vector<double>{1.0, 3.0, 5.0}));
  EXPECT_EQ(c.im, (std::vector<double>{2.0, 4.0, -6.0}));
  EXPECT_EQ(c.record, 3u);
  EXPECT_EQ(c.line, 34u);  // each earlier dataset spans 16 lines: "-1", "58", 11 header, 2 data, "-1"
}

TEST(UffFunctions, FortranNumbers) {
  // D exponent, fields that touch, an exponent without its letter, a leading plus sign.
  std::string text = "    -1\n    58\n" + header58(2, 4, 1, 0, 1);
  text += std::string("  1.00000D+00") + "-2.500000E-01" + "  3.00000-105" + " +4.00000E+00" + "\n    -1\n";
  const auto g = uff::parse(text, "t.uff").functions.at(0);
  EXPECT_EQ(g.re, (std::vector<double>{1.0, -0.25, 3e-105, 4.0}));
}

TEST(UffFunctions, BinaryBlockMayHoldDelimiterLinesAndIsReadByItsLength) {
  // Big endian, doubles, uneven abscissa: x and y interleaved. Two of the abscissa values are
  // made of the bytes "\n    -1\n" and "\r\n  -1\r\n".
  const std::string x0 = "\n    -1\n", x1 = "\r\n  -1\r\n";
  const std::string block = x0 + big_endian_double(2.5) + x1 + big_endian_double(-1.0);
  std::string text = "    -1\n" + binary_line(2, block.size()) + header58(4, 2, 0, 0, 0, "big");
  text += block + "    -1\n";
  text += "    -1\n    58\n" + header58(2, 1, 1, 0, 1, "after") + "  7.00000E+00\n    -1\n";
  const auto f = uff::parse(text, "t.uff");
  ASSERT_EQ(f.functions.size(), 2u);
  const auto& g = f.functions[0];
  EXPECT_TRUE(g.binary);
  EXPECT_FALSE(g.even);
  EXPECT_EQ(g.x, (std::vector<double>{from_big_endian(x0), from_big_endian(x1)}));
  EXPECT_EQ(g.re, (std::vector<double>{2.5, -1.0}));
  EXPECT_EQ(f.functions[1].record, 2u);
  EXPECT_EQ(f.functions[1].re, (std::vector<double>{7.0}));
}

TEST(UffFunctions, StrayLineBreakBeforeClosingDelimiterIsTolerated) {
  // pyuff's dataset58b_with_wrong_CRLF_before-1.uff is not in the mirror available here; this is
  // the same defect: CR LF between the binary block and the closing "    -1".
  std::string block;
  for (float v : {1.5f, -2.0f, 0.25f}) block.append(reinterpret_cast<const char*>(&v), 4);  // host order
  const std::uint16_t one = 1;
  unsigned char first = 0;
  std::memcpy(&first, &one, 1);
  std::string text = "    -1\r\n" + binary_line(first == 1 ? 1 : 2, block.size()) + header58(2, 3, 1, 0, 0.1);
  text += block + "\r\n    -1\r\n    -1\r\n  2414\r\nsomething\r\n    -1\r\n";
  const auto f = uff::parse(text, "t.uff");
  ASSERT_EQ(f.functions.size(), 1u);
  EXPECT_EQ(f.functions[0].re, (std::vector<double>{1.5, -2.0, 0.25}));
  ASSERT_EQ(f.skipped.size(), 1u);
  EXPECT_EQ(f.skipped[0].dataset, 2414);
  EXPECT_EQ(f.skipped[0].record, 2u);
}

TEST(UffFunctions, BinaryLengthImpliedByPointsWhenTheDeclaredOneIsShort) {
  // pyuff's writer declares num_pts x 8 bytes for complex double data that takes twice as many.
  std::string block;
  for (double v : {1.0, -1.0, 2.0, -2.0, 3.0, -3.0}) block += big_endian_double(v);
  std::string text = "    -1\n" + binary_line(2, 24) + header58(6, 3, 1, 0, 1) + block + "    -1\n";
  const auto g = uff::parse(text, "t.uff").functions.at(0);
  EXPECT_EQ(g.re, (std::vector<double>{1.0, 2.0, 3.0}));
  EXPECT_EQ(g.im, (std::vector<double>{-1.0, -2.0, -3.0}));
}

TEST(UffFunctions, LineEndingsLfCrLfAndCrReadAlike) {
  const std::string lf = slurp(data_path("time-history-not-all-columns-filled.uff"));
  ASSERT_EQ(lf.find('\r'), std::string::npos);
  std::string crlf, cr;
  for (char c : lf) {
    crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
    cr += c == '\n' ? '\r' : c;
  }
  const auto a = uff::parse(lf, "lf.uff").functions.at(0);
  const auto b = uff::parse(crlf, "crlf.uff").functions.at(0);
  const auto c = uff::parse("\xEF\xBB\xBF\n\n" + cr, "cr.uff").functions.at(0);  // also a BOM and blank lines
  EXPECT_EQ(a.re, b.re);
  EXPECT_EQ(a.re, c.re);
  EXPECT_EQ(a.x, c.x);
  EXPECT_EQ(a.id1, c.id1);
  EXPECT_EQ(c.line, 4u);
}

TEST(UffModel, NodesUnitsFreeLayouts) {
  // 15 written with wider columns; 2411 with D exponents; 164 with its factors over two lines
  // (foot and pound-force factors as some writers store them).
  std::string text = "    -1\n    15\n";
  text += format("%10d%10d%10d%10d%15.6e%15.6e%15.6e\n", 7, 1, 2, 3, 1.25, -2.5, 1e-3);
  text += format("%10d%10d%10d%10d%15.6e%15.6e%15.6e\n", 8, 0, 0, 0, 0.0, 0.0, 1e3);
  text += "    -1\n    -1\n  2411\n";
  text += "        11         0         0         5\n   1.2500000000000000D+00  -2.5000000000000000D-01   3.0D+02\n";
  text += "    -1\n    -1\n   164\n         2Foot (pound f)               1\n";
  text += "  3.04800000000000004D-01  4.44822161526049980D+00\n  5.55555555555555980D-01  2.55372222222222510D+02\n";
  text += "    -1\n";
  const auto f = uff::parse(text, "t.uff");
  ASSERT_EQ(f.nodes.size(), 3u);
  expect_node(f.nodes[0], {7, 1, 2, 3, 1.25, -2.5, 1e-3});
  expect_node(f.nodes[1], {8, 0, 0, 0, 0.0, 0.0, 1e3});
  expect_node(f.nodes[2], {11, 0, 0, 5, 1.25, -0.25, 300.0});
  EXPECT_EQ(f.nodes[2].dataset, 2411);
  expect_units(f.units, 2, "Foot (pound f)", 1,
               {0.304800000000000004, 4.44822161526049980, 0.555555555555555980, 255.372222222222510});
  EXPECT_FALSE(f.header);
}

TEST(UffModel, UnknownDatasetsAreListed) {
  const std::string text = "    -1\n  2414b\n\x01\x02 -1 binary\n    -1\n\n    -1\n   777\n  junk\n    -1\n";
  const auto f = uff::parse(text, "t.uff");
  EXPECT_EQ(f.datasets, 2u);
  ASSERT_EQ(f.skipped.size(), 2u);
  EXPECT_EQ(f.skipped[0].dataset, 2414);
  EXPECT_TRUE(f.skipped[0].binary);
  EXPECT_EQ(f.skipped[0].line, 2u);
  EXPECT_EQ(f.skipped[1].dataset, 777);
  EXPECT_FALSE(f.skipped[1].binary);
  EXPECT_EQ(f.skipped[1].record, 2u);
  EXPECT_EQ(f.skipped[1].line, 7u);
}

// ---------------------------------------------------------------------------------------------
// Names.

TEST(UffNames, DirectionsTypesAndUnits) {
  EXPECT_EQ(uff::direction_name(0), "");
  EXPECT_EQ(uff::direction_name(1), "+X");
  EXPECT_EQ(uff::direction_name(-3), "-Z");
  EXPECT_EQ(uff::direction_name(4), "+RX");
  EXPECT_EQ(uff::direction_name(-6), "-RZ");
  EXPECT_EQ(uff::direction_name(7), "?7");
  EXPECT_EQ(uff::function_type_name(0), "General");
  EXPECT_EQ(uff::function_type_name(1), "Time Response");
  EXPECT_EQ(uff::function_type_name(12), "Spectrum");
  EXPECT_EQ(uff::function_type_name(27), "Order Function");
  EXPECT_EQ(uff::function_type_name(28), "Unknown");
  uff::Function f;
  f.ordinate.unit = "none";
  f.abscissa.unit = " s ";
  EXPECT_EQ(uff::ordinate_unit(f), "");
  EXPECT_EQ(uff::abscissa_unit(f), "s");
}

TEST(UffNames, ChannelNamesAreUniqueInFileOrder) {
  uff::File file;
  uff::Function a;
  a.id1 = "NONE";
  a.response_entity = "acc";
  a.response_node = 3;
  a.response_direction = 3;
  EXPECT_EQ(uff::channel_name(a), "acc:3+Z");
  uff::Function b = a;
  b.response_entity = "NONE";
  b.response_direction = -4;
  EXPECT_EQ(uff::channel_name(b), "3-RX");
  uff::Function c;
  c.id1 = "";
  c.response_entity = "";
  c.record = 9;
  EXPECT_EQ(uff::channel_name(c), "function9");
  uff::Function d;
  d.id1 = "acc:3+Z#2";
  file.functions = {a, a, d, a};
  EXPECT_EQ(uff::channel_names(file), (std::vector<std::string>{"acc:3+Z", "acc:3+Z#2", "acc:3+Z#2#2", "acc:3+Z#3"}));
}

TEST(UffNames, LooksLikeUff) {
  EXPECT_TRUE(uff::looks_like_uff("    -1\n    58\n"));
  EXPECT_TRUE(uff::looks_like_uff("\n\r\n    -1   \r\n"));
  EXPECT_TRUE(uff::looks_like_uff("\xEF\xBB\xBF    -1"));
  EXPECT_TRUE(uff::looks_like_uff("-1\n"));
  EXPECT_FALSE(uff::looks_like_uff(""));
  EXPECT_FALSE(uff::looks_like_uff("t,P,w\n0,1,2\n"));
  EXPECT_FALSE(uff::looks_like_uff("    -12\n"));
  EXPECT_FALSE(uff::looks_like_uff("    -1 x\n"));
  EXPECT_FALSE(uff::looks_like_uff("    -"));
}

// ---------------------------------------------------------------------------------------------
// Malformed input: one InputError line naming the file, record, line, field and value.

TEST(UffErrors, EmptyAndMissingFiles) {
  EXPECT_TRUE(Contains(error_of(""), "UFF file 't.uff', line 1: empty"));
  EXPECT_TRUE(Contains(error_of("  \n\n \r\n"), "empty"));
  EXPECT_TRUE(Contains(error_of("hello\n    -1\n"),
                       "UFF file 't.uff', line 1: expected a '    -1' line opening a dataset, got 'hello'"));
  EXPECT_TRUE(Contains(error_of("    -1\n"), "line 1: the '    -1' line must be followed by a dataset number"));
  EXPECT_TRUE(Contains(error_of("    -1\n   5x8\n    -1\n"),
                       "line 2: record 1: dataset number must be a positive integer, got '5x8'"));
  try {
    uff::read_file("/nonexistent/dir/x.uff");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_TRUE(Contains(e.what(), "UFF file '/nonexistent/dir/x.uff': cannot be opened"));
  }
  try {
    uff::read_file(SCOLEID_TEST_DATA_DIR);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_TRUE(Contains(e.what(), "is a directory"));
  }
}

TEST(UffErrors, TruncatedFiles) {
  const std::string ascii = slurp(data_path("Sample_UFF58_ascii.uff"));
  EXPECT_TRUE(Contains(error_of(ascii.substr(0, ascii.size() / 2), "a.uff"),
                       "UFF file 'a.uff', record 1 (dataset 58 at line 2), line 6618: dataset must end with a '    -1' "
                       "line (truncated file?), got the end of the file"));
  const std::string bin = slurp(data_path("Sample_UFF58b_bin.uff"));
  EXPECT_TRUE(Contains(error_of(bin.substr(0, 2000), "b.uff"),
                       "UFF file 'b.uff', record 1 (dataset 58b at line 2), line 2: n_bytes must fit the 1428 bytes "
                       "left in the file, got 317168"));
  EXPECT_TRUE(
      Contains(error_of(bin.substr(0, 300), "b.uff"),
               "record 1 (dataset 58b at line 2), line 10: header must have 11 lines before the binary data, got "
               "the end of the file"));
  // A whole dataset 58 whose closing line is missing, followed by nothing.
  const std::string th = slurp(data_path("time-history-not-all-columns-filled.uff"));
  EXPECT_TRUE(Contains(error_of(th.substr(0, th.rfind("    -1")), "c.uff"), "line 16: dataset must end with"));
}

TEST(UffErrors, NumPtsNotMatchingTheData) {
  const std::string th = slurp(data_path("time-history-not-all-columns-filled.uff"));
  const std::string form = "         2        13         1";
  expect_refused(
      th, {{form, "         2        14         1",
            "UFF file 't.uff', record 1 (dataset 58 at line 2), line 9: num_pts must match the data: 13 "
            "values, 1 per point, got 14"},
           {form, "         2        12         1", "line 16: value 13 is past the 12 values num_pts 12 declares"}});
  // Far more than the data lines could hold: refused before anything is allocated.
  expect_refused(
      th,
      {{form, "         2   4000000         1", "line 9: num_pts must fit the 237 bytes of data lines, got 4000000"},
       {form, "         2  99999999         1", "line 9: num_pts must be between 1 and 5000000, got '99999999'"},
       {form, "         2         0         1", "num_pts must be between 1 and 5000000, got '0'"}});
  // Uneven spacing doubles the values needed.
  EXPECT_TRUE(Contains(error_of(replace_once(th, form, "         2        13         0")),
                       "num_pts must match the data: 13 values, 2 per point, got 13"));
}

TEST(UffErrors, BadValuesAndHeaderFields) {
  const std::string th = slurp(data_path("time-history-not-all-columns-filled.uff"));
  expect_refused(
      th,
      {{"-3.56616E+00", "-3.56x16E+00",
        "UFF file 't.uff', record 1 (dataset 58 at line 2), line 14: value 2 must be a finite number, "
        "got '-3.56x16E+00'"},
       {"-3.56616E+00", "         NaN", "line 14: value 2 must be a finite number, got 'NaN'"},
       {"-3.56616E+00", "1.00000E+999", "line 14: value 2 must be a finite number, got '1.00000E+999'"},
       {"         2        13", "         3        13",
        "line 9: ordinate data type must be 2, 4, 5 or 6 (real/complex, single/double precision), got '3'"},
       {"         2        13", "         x        13", "line 9: ordinate data type must be an integer, got 'x'"},
       {"5.00000E-005", "0.00000E+000", "line 9: abscissa increment must be > 0 for even spacing, got '0.00000E+000'"},
       {"0   0 NONE               0   0", "0   9 NONE               0   0",
        "line 8: response direction must be between -6 and 6, got '9'"},
       {"        17    0", "        ab    0", "line 10: abscissa specific data type must be an integer, got 'ab'"}});
  // A control character is shown escaped: the message stays on one line.
  const std::string e = error_of(replace_once(th, "         2        13", "         \n        13"));
  EXPECT_EQ(e.find('\n'), std::string::npos) << e;
}

TEST(UffErrors, BinaryHeaderAndBlock) {
  const std::string b8 = slurp(data_path("binary8byte.uff"));
  const std::string line = "    58b     1     2          11        2000";
  EXPECT_TRUE(Contains(error_of(replace_once(b8, line, "    58b     1     2          11        9000")),
                       "UFF file 't.uff', record 1 (dataset 58b at line 2), line 2: n_bytes must fit the 2008 bytes "
                       "left in the file, got 9000"));
  // Neither the declared length nor the one num_pts implies ends at the closing line.
  EXPECT_TRUE(Contains(error_of(replace_once(replace_once(b8, line, "    58b     1     2          11        1000"),
                                             "       250         1", "       200         1")),
                       "line 2: n_bytes must end the binary block right before the closing '    -1' line, got 1000"));
  expect_refused(b8, {{line, "    58b     3     2          11        2000",
                       "line 2: byte ordering must be 1 (little endian) or 2 (big endian), got '3'"},
                      {line, "    58b     1     1          11        2000",
                       "line 2: floating-point format must be 2 (IEEE 754)"}});
  EXPECT_TRUE(Contains(error_of(replace_once(b8, line + "     0     0           0           0", "    58b")),
                       "line 2: byte ordering must be an integer, got a blank field"));
  EXPECT_TRUE(
      Contains(error_of(replace_once(b8, "       250         1", "       300         1")),
               "line 9: num_pts must match the binary block of 2000 bytes (8 per value, 1 values per point), got 300"));
  // A NaN in the block.
  std::string nan = b8;
  const std::size_t start = b8.size() - 8 - 2008 + 8 + 8 * 5;  // value 6
  const double q = std::nan("");
  std::memcpy(&nan[start], &q, 8);
  EXPECT_TRUE(Contains(error_of(nan), "binary value 6 must be a finite number, got nan"));
}

TEST(UffErrors, ShapesUnitsNodes) {
  const std::string tr = slurp(data_path("uff55_translation.uff"));
  EXPECT_TRUE(
      Contains(error_of(replace_once(tr, "  1.50162e-01  1.50162e-01  1.50162e-01", "  1.50162e-01  1.50162e-01")),
               "record 1 (dataset 55 at line 2), line 14: node 2 values must number 3, got 2"));
  EXPECT_TRUE(Contains(error_of(replace_once(tr, "         1         2         2         8         2         3",
                                             "         1         2         2         8         3         3")),
                       "line 8: data type must be 2 (real) or 5 (complex), got '3'"));
  EXPECT_TRUE(Contains(error_of(replace_once(tr, "         2         4         1         1",
                                             "        -2         4         1         1")),
                       "line 9: number of integer parameters must be between 0 and 100, got -2"));
  EXPECT_TRUE(Contains(error_of("    -1\n   164\n         1SI\n  1.0  1.0  1.0\n    -1\n"),
                       "record 1 (dataset 164 at line 2), line 4: unit factors must be 4 numbers, got 3"));
  EXPECT_TRUE(Contains(error_of("    -1\n   164\n         1SI\n  1.0  0.0D+00  1.0 0.0\n    -1\n"),
                       "line 4: force factor must not be zero, got '0.0D+00'"));
  EXPECT_TRUE(Contains(error_of("    -1\n    15\n         1         0         0         0  1.0  2.0  x\n    -1\n"),
                       "record 1 (dataset 15 at line 2), line 3: z must be a finite number, got"));
  EXPECT_TRUE(Contains(error_of("    -1\n  2411\n         1         0         0         0\n    -1\n"),
                       "line 3: node 1 must have a coordinates line, got the end of the dataset"));
  EXPECT_TRUE(Contains(error_of("    -1\n   151\nonly\ntwo\n    -1\n"), "line 4: header must have 7 lines, got 2"));
}
