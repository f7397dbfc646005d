// LabVIEW Measurement files (io/lvm.h): real files written by LabVIEW (tests/data/lvm, MIT, from
// ladisk/lvm_read) read into the values, names, units and times they hold; the layouts the reader
// does not take refused with the file and line.
#include "scoleid/io/lvm.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>

#include "scoleid/io/data_source.h"
#include "scoleid/io/frf_record.h"
#include "scoleid/io/time_grid.h"
#include "common/test_data.h"
#include "scoleid/io/error.h"
#include "common/scratch.h"
#include "scoleid/io/units.h"

namespace fs = std::filesystem;
using namespace scoleid::io;

namespace {
const fs::path kData = fs::path(SCOLEID_TEST_DATA_DIR) / "lvm";

const auto& error_of = scoleid::test::input_error_of;

fs::path write_lvm(const std::string& name, const std::string& text) {
  const fs::path d = scoleid::test::scratch_root() / "lvm";
  fs::create_directories(d);
  std::ofstream(d / name, std::ios::binary) << text;
  return d / name;
}

// A small file in LabVIEW's layout: `sep` between fields, `dec` as the decimal mark.
std::string small_lvm(const std::string& sep, const std::string& dec, const std::string& x_columns, const std::string& dim = "Time") {
  const std::string h = "LabVIEW Measurement" + sep + "\nWriter_Version" + sep + "2\nSeparator" + sep +
                        (sep == "\t" ? "Tab" : "Comma") + "\nDecimal_Separator" + sep + dec + "\nX_Columns" + sep + x_columns +
                        "\n***End_of_Header***" + sep + "\n" + sep + "\nChannels" + sep + "2" + sep + "\nSamples" + sep + "3" + sep +
                        "3\nY_Unit_Label" + sep + "Pounds" + sep + "Gs\nX_Dimension" + sep + dim + sep + dim + "\nX0" + sep + "0" +
                        sep + "0\nDelta_X" + sep + "0" + dec + "5" + sep + "0" + dec + "5\n***End_of_Header***" + sep + sep + "\n" +
                        "X_Value" + sep + "F" + sep + "a" + sep + "Comment\n";
  std::string rows;
  for (int k = 0; k < 3; ++k)
    rows += (x_columns == "No" ? "" : std::to_string(k) + dec + "5") + sep + std::to_string(k + 1) + dec + "25" + sep +
            "-" + std::to_string(k) + "\n";
  return h + rows;
}
}  // namespace

TEST(Lvm, XColumnsNoWithADecimalCommaReadsValuesUnitsAndTimesFromX0AndDeltaX) {
  const fs::path f = kData / "short.lvm";
  ASSERT_TRUE(is_lvm_file(f.string()));
  const DataTable t = read_data(f.string());
  ASSERT_EQ(t.names, (std::vector<std::string>{"Excitation (Trigger)", "Response (Trigger)"}));
  EXPECT_EQ(t.units, (std::vector<std::string>{"Newtons", "m/s^2"}));
  ASSERT_EQ(t.t.size(), 10u);
  for (std::size_t k = 0; k < 10; ++k) EXPECT_DOUBLE_EQ(t.t[k], 3.90625e-5 * static_cast<double>(k));
  EXPECT_EQ(t.columns[0][0], 0.914018);
  EXPECT_EQ(t.columns[1][0], 1.204792);
  EXPECT_EQ(t.columns[1][9], 1.212775);
  // "Newtons" is a unit of force by the DAQ alias table.
  EXPECT_EQ(units::conversion(t.units[0], "N", units::Quantity::Force).scale, 1.0);
}

TEST(Lvm, XColumnsMultiReadsEachChannelsOwnXAndXColumnsOneTheSharedOne) {
  const DataTable m = read_data((kData / "multi_time_column.lvm").string());
  ASSERT_EQ(m.names, (std::vector<std::string>{"Voltage", "Acceleration"}));
  EXPECT_EQ(m.units, (std::vector<std::string>{"Volts", "g"}));
  ASSERT_EQ(m.t.size(), 3u);
  EXPECT_EQ(m.t[1], 1.953125e-5);
  EXPECT_EQ(m.columns[1][2], 0.467541);
  // X_Columns One, irregular x, comments on every row, names in Windows-1252 read into UTF-8.
  const DataTable c = read_data((kData / "with_comments.lvm").string());
  ASSERT_EQ(c.names.size(), 3u);
  EXPECT_EQ(c.names[0], "Press\xC3\xA3o ABS. (MPa)");
  EXPECT_EQ(c.names[1], "Temperatura (\xC2\xB0" "C)");
  EXPECT_EQ(c.t[1], 0.328878);
  EXPECT_EQ(c.t.size(), 9u);
  // A file of two writes without headers between them: 16384 rows on one grid.
  const DataTable l = read_data((kData / "long_single_header_multi_ch.lvm").string());
  EXPECT_EQ(l.t.size(), 16384u);
  EXPECT_EQ(l.units, (std::vector<std::string>{"g", "m/s^2", "m/s^2"}));
  // Channels that hold no sample are left out, and say so.
  const DataFileInfo e = describe_data((kData / "with_empty_fields.lvm").string());
  EXPECT_EQ(e.format, "lvm");
  EXPECT_EQ(e.channels.size(), 3u);
}

TEST(Lvm, ChannelsOfDifferentLengthsAreRefusedNamingOne) {
  const std::string m = error_of([] { read_data((kData / "uneven_comments.lvm").string()); });
  EXPECT_NE(m.find("samples, the file 16 rows: the channels of one record share one time grid"), std::string::npos) << m;
}

TEST(Lvm, CommaSeparatedTabSeparatedAndDecimalCommasReadAlike) {
  const DataTable a = read_data(write_lvm("a.lvm", small_lvm("\t", ".", "One")).string());
  const DataTable b = read_data(write_lvm("b.lvm", small_lvm(",", ".", "One")).string());
  const DataTable c = read_data(write_lvm("c.lvm", small_lvm("\t", ",", "One")).string());
  const DataTable d = read_data(write_lvm("d.lvm", small_lvm("\t", ",", "No")).string());
  for (const DataTable* x : {&b, &c}) {
    EXPECT_EQ(x->t, a.t);
    EXPECT_EQ(x->columns, a.columns);
  }
  EXPECT_EQ(a.t, (std::vector<double>{0.5, 1.5, 2.5}));
  EXPECT_EQ(d.t, (std::vector<double>{0.0, 0.5, 1.0}));
  EXPECT_EQ(a.columns[0], (std::vector<double>{1.25, 2.25, 3.25}));
  EXPECT_EQ(a.columns[1], (std::vector<double>{-0.0, -1.0, -2.0}));
  // "Pounds" is pound-force and "Gs" standard gravity where a force and an acceleration are meant.
  EXPECT_NEAR(units::conversion(a.units[0], "N", units::Quantity::Force).scale, 4.4482216152605, 1e-12);
  EXPECT_NEAR(units::conversion(a.units[1], "m/s^2", units::Quantity::Acceleration).scale, 9.80665, 1e-12);
}

TEST(Lvm, WhatTheReaderDoesNotTakeIsRefusedNamingFileAndLine) {
  EXPECT_NE(error_of([] { read_data(write_lvm("cc.lvm", small_lvm(",", ",", "One")).string()); })
                .find("a comma is both the separator and the decimal mark"),
            std::string::npos);
  EXPECT_NE(error_of([] { read_data(write_lvm("fq.lvm", small_lvm("\t", ".", "One", "Frequency")).string()); })
                .find("X_Dimension is 'Frequency': not a time record"),
            std::string::npos);
  std::string two = small_lvm("\t", ".", "One");
  two += "\t\n" + two.substr(two.find("Channels"));
  const std::string m2 = error_of([&] { read_data(write_lvm("two.lvm", two).string()); });
  EXPECT_NE(m2.find("line 20: a second segment begins here"), std::string::npos) << m2;
  std::string hex = small_lvm("\t", ".", "One");
  hex.replace(hex.rfind("3.25"), 4, "0x10");
  EXPECT_NE(error_of([&] { read_data(write_lvm("hex.lvm", hex).string()); }).find("not a number, got '0x10'"), std::string::npos);
  std::string back = small_lvm("\t", ".", "One");
  back.replace(back.rfind("2.5\t"), 3, "0.1");
  EXPECT_NE(error_of([&] { read_data(write_lvm("back.lvm", back).string()); }).find("time must be strictly increasing"),
            std::string::npos);
}

// A file without the X_Value row (some writers leave it out): the channels get LabVIEW's default
// names and no data row is lost.
TEST(Lvm, AFileWithoutTheColumnNamesKeepsEveryRow) {
  std::string text = small_lvm("\t", ".", "One");
  const auto at = text.find("X_Value");
  text.erase(at, text.find('\n', at) + 1 - at);
  const DataTable t = read_data(write_lvm("nonames.lvm", text).string());
  EXPECT_EQ(t.names, (std::vector<std::string>{"Untitled", "Untitled 1"}));
  EXPECT_EQ(t.t, (std::vector<double>{0.5, 1.5, 2.5}));
}

// A LabVIEW file without a time column states its step as Delta_X, written to few digits
// (0.000977 for 1/1024 s: the times 1023.54 Hz): a stated rate within that writing's rounding
// replaces it, one that is not is refused as before.
TEST(Lvm, AStatedRateReplacesADeltaXWrittenToFewDigits) {
  const std::string file = (kData / "long_single_header_multi_ch.lvm").string();
  const DataTable l = read_data(file);
  EXPECT_EQ(l.stated_step, 0.000977);
  EXPECT_DOUBLE_EQ(l.stated_step_rounding, 5e-7);
  std::string why;
  EXPECT_FALSE(stated_grid(l.t, 1024.0, &why)) << "without the written step the per-sample check refuses 1024 Hz";
  const auto g = stated_grid(l.t, 1024.0, &why, l.stated_step, l.stated_step_rounding);
  ASSERT_TRUE(g);
  EXPECT_EQ(g->step, 1.0 / 1024);
  EXPECT_FALSE(stated_grid(l.t, 1000.0, &why, l.stated_step, l.stated_step_rounding)) << "1000 Hz is not what 0.000977 rounds";
  RecordFrfOptions o;
  o.input = "F";
  o.units = {{"F", "N"}};
  EXPECT_NEAR(frf_of_record(file, {}, o).sample_rate, 1.0 / 0.000977, 1e-6);
  o.sample_rate = 1024;
  const RecordFrf r = frf_of_record(file, {}, o);
  EXPECT_EQ(r.sample_rate, 1024.0);
  EXPECT_EQ(r.data.f_hz.front(), 1024.0 / 2048);
}
