// The writers of io/lvm.h and io/tdms.h (docs/data.md 1.1, `scole-data convert`): a record
// written as LVM or TDMS and read back with read_data gives every time, name, unit and value bit
// for bit, and the same record written as CSV, LVM and TDMS gives one and the same table (so
// identification from each gives the same estimates). A table a format cannot hold is refused
// naming the path, and nothing is written.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/test_data.h"
#include "scoleid/io/data_files.h"
#include "scoleid/io/data_source.h"
#include "scoleid/io/error.h"
#include "scoleid/io/lvm.h"
#include "common/scratch.h"
#include "scoleid/io/tdms.h"

namespace fs = std::filesystem;
using namespace scoleid::io;

namespace {

const auto& error_of = scoleid::test::input_error_of;

fs::path scratch() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const fs::path d = scoleid::test::scratch_root() / info->name();
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::vector<std::uint64_t> bits(const std::vector<double>& v) {
  std::vector<std::uint64_t> b(v.size());
  std::memcpy(b.data(), v.data(), v.size() * sizeof(double));
  return b;
}

// Values that a careless writer loses: thirds, a tiny and a huge magnitude, a negative zero, more
// digits than a double holds, values that need all 17 significant digits.
std::vector<double> awkward(std::size_t n, double shift) {
  const double pool[] = {1.0 / 3.0,           1e-300, -0.0, 123456789.123456789, 0.1 + 0.2, std::nextafter(1.0, 2.0),
                         -2.0 / 3.0,          1e23,   0.0,  -1.0 / 7.0 * 1e-5,   M_PI,      std::nextafter(0.1, 0.0),
                         -9007199254740991.0, 5e-17};
  const std::size_t m = sizeof pool / sizeof pool[0];
  std::vector<double> v(n);
  for (std::size_t k = 0; k < n; ++k) v[k] = pool[(k + static_cast<std::size_t>(shift)) % m] * (k % 2 ? 1.0 : shift);
  return v;
}

// 40 samples at 2048 Hz (t = k / 2048) or at irregular times; three channels, one without a unit.
DataTable record(bool uniform) {
  DataTable tab;
  tab.source = "record";
  const std::size_t n = 40;
  tab.t.resize(n);
  for (std::size_t k = 0; k < n; ++k)
    tab.t[k] = uniform ? static_cast<double>(k) / 2048.0 : 0.1 + static_cast<double>(k) / 3.0 + 1e-7 * static_cast<double>(k * k % 7);
  tab.names = {"Acc 1/3", "Kraft \xc3\xbc", "tip's LOS"};
  tab.units = {"m/s^2", "N", ""};
  tab.columns = {awkward(n, 1.0), awkward(n, 3.0), awkward(n, 7.0)};
  return tab;
}

void expect_same(const DataTable& got, const DataTable& want, const std::string& what) {
  SCOPED_TRACE(what);
  EXPECT_EQ(got.t, want.t);
  EXPECT_EQ(bits(got.t), bits(want.t));
  EXPECT_EQ(got.names, want.names);
  ASSERT_EQ(got.units.size(), want.names.size());
  for (std::size_t j = 0; j < want.names.size(); ++j) EXPECT_EQ(got.unit(static_cast<int>(j)), want.unit(static_cast<int>(j)));
  ASSERT_EQ(got.columns.size(), want.columns.size());
  for (std::size_t j = 0; j < want.columns.size(); ++j) {
    ASSERT_EQ(got.columns[j].size(), want.columns[j].size());
    for (std::size_t k = 0; k < want.columns[j].size(); ++k) EXPECT_EQ(got.columns[j][k], want.columns[j][k]) << j << ", " << k;
    EXPECT_EQ(bits(got.columns[j]), bits(want.columns[j])) << "column " << j;  // -0.0 too
  }
}

// OUT.csv with the column description convert writes beside it (the units).
void write_csv_record(const DataTable& tab, const fs::path& path) {
  write_csv(path.string(), tab);
  nlohmann::json cols = nlohmann::json::array();
  for (std::size_t j = 0; j < tab.names.size(); ++j) cols.push_back({{"name", tab.names[j]}, {"unit", tab.unit(static_cast<int>(j))}});
  fs::path meta = path;
  meta.replace_extension(".json");
  write_json_atomic(meta.string(), {{"format", kColumnsFormat}, {"columns", cols}});
}

}  // namespace

TEST(DataWriters, AnLvmGivesBackEveryTimeNameUnitAndValueBitForBit) {
  const fs::path dir = scratch();
  for (const bool uniform : {true, false}) {
    const DataTable tab = record(uniform);
    const fs::path p = dir / (uniform ? "uniform.lvm" : "irregular.lvm");
    write_lvm(tab, p.string());
    expect_same(read_data(p.string()), tab, p.string());
    // LabVIEW's layout: the file and segment headers of one write.
    const std::string text = scoleid::test::slurp(p);
    EXPECT_EQ(text.rfind("LabVIEW Measurement\t\nWriter_Version\t2\nReader_Version\t2\nSeparator\tTab\nDecimal_Separator\t.\n"
                         "Multi_Headings\tNo\nX_Columns\tOne\nTime_Pref\tRelative\n",
                         0),
              0u)
        << text.substr(0, 300);
    EXPECT_NE(text.find("\nChannels\t3\t\nSamples\t40\t40\t40\t\n"), std::string::npos);
    EXPECT_NE(text.find("\nY_Unit_Label\tm/s^2\tN\t\t\n"), std::string::npos);
    EXPECT_NE(text.find("\nX_Dimension\tTime\tTime\tTime\t\n"), std::string::npos);
    EXPECT_NE(text.find("\n***End_of_Header***\t\nX_Value\tAcc 1/3\tKraft \xc3\xbc\ttip's LOS\tComment\n"), std::string::npos);
    if (uniform) {
      EXPECT_NE(text.find("\nDelta_X\t0.00048828125\t0.00048828125\t0.00048828125\t\n"), std::string::npos);
      EXPECT_TRUE(describe_lvm(p.string()).channels[0].even);
    }
  }
}

TEST(DataWriters, ATdmsGivesBackEveryTimeNameUnitAndValueBitForBit) {
  const fs::path dir = scratch();
  for (const bool uniform : {true, false}) {
    const DataTable tab = record(uniform);
    const fs::path p = dir / (uniform ? "uniform.tdms" : "irregular.tdms");
    write_tdms(tab, p.string());
    expect_same(read_data(p.string()), tab, p.string());
    // t = k / 2048 as wf_increment; irregular times as a Time channel.
    const DataFileInfo info = describe_tdms(p.string());
    std::string notes;
    for (const auto& n : info.notes) notes += n + "\n";
    EXPECT_NE(notes.find("version 4713, 1 segment, group 'record'"), std::string::npos) << notes;
    EXPECT_NE(notes.find(uniform ? "time from wf_increment 0.00048828125 and wf_start_offset 0" : "time from channel 'Time' [s]"),
              std::string::npos)
        << notes;
  }
}

// A column the TDMS reader would take for the time ("Time", "T", "time [ms]") sends the times into
// a channel of their own ahead of it, named so as not to clash.
TEST(DataWriters, ATdmsColumnNamedLikeTimeStaysAColumn) {
  const fs::path dir = scratch();
  DataTable tab = record(true);
  tab.time_name = "X_Value";
  tab.names = {"Time", "T", "time [ms]"};
  write_tdms(tab, (dir / "t.tdms").string());
  const DataTable back = read_data((dir / "t.tdms").string());
  expect_same(back, tab, "t.tdms");
  EXPECT_EQ(back.time_name, "t");
}

TEST(DataWriters, OneRecordAsCsvLvmAndTdmsGivesOneTable) {
  const fs::path dir = scratch();
  for (const bool uniform : {true, false}) {
    const DataTable tab = record(uniform);
    const std::string stem = uniform ? "uniform" : "irregular";
    write_csv_record(tab, dir / (stem + ".csv"));
    write_lvm(tab, (dir / (stem + ".lvm")).string());
    write_tdms(tab, (dir / (stem + ".tdms")).string());
    const DataTable csv = read_data((dir / (stem + ".csv")).string());
    const DataTable lvm = read_data((dir / (stem + ".lvm")).string());
    const DataTable tdms = read_data((dir / (stem + ".tdms")).string());
    expect_same(csv, tab, stem + ".csv");
    expect_same(lvm, csv, stem + ".lvm against .csv");
    expect_same(tdms, csv, stem + ".tdms against .csv");
    // And back again: the LVM's table written as TDMS and the TDMS's as LVM change nothing.
    write_tdms(lvm, (dir / (stem + "2.tdms")).string());
    write_lvm(tdms, (dir / (stem + "2.lvm")).string());
    expect_same(read_data((dir / (stem + "2.tdms")).string()), csv, stem + "2.tdms");
    expect_same(read_data((dir / (stem + "2.lvm")).string()), csv, stem + "2.lvm");
  }
}

TEST(DataWriters, ATableTheFormatCannotHoldIsRefusedNamingThePathAndNothingIsWritten) {
  const fs::path dir = scratch();
  const std::string lvm = (dir / "r.lvm").string(), tdms = (dir / "r.tdms").string();
  auto refused = [&](const DataTable& tab, const std::string& path, const std::string& what) {
    const std::string e = error_of([&] {
      if (path == lvm) write_lvm(tab, path);
      else write_tdms(tab, path);
    });
    EXPECT_NE(e.find("'" + path + "'"), std::string::npos) << e;
    EXPECT_NE(e.find(what), std::string::npos) << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
    EXPECT_FALSE(fs::exists(path)) << path;
  };
  DataTable tab = record(true);
  tab.names[1] = "Kraft\tN";
  refused(tab, lvm, "control character");
  tab.names[1] = " Kraft";
  refused(tab, lvm, "blank");
  tab.names[1] = "X_Value";
  refused(tab, lvm, "X_Value");
  tab.names[1] = "Kraft \xfc";  // Latin-1, not UTF-8
  refused(tab, lvm, "UTF-8");
  refused(tab, tdms, "UTF-8");
  tab = record(true);
  tab.units[0] = "m/s^2\n";
  refused(tab, lvm, "control character");
  refused(tab, tdms, "blank");
  // What every record must satisfy (check_table).
  tab = record(true);
  tab.t[5] = tab.t[4];
  refused(tab, lvm, "strictly increasing");
  refused(tab, tdms, "strictly increasing");
  tab = record(true);
  tab.columns[2][3] = std::nan("");
  refused(tab, lvm, "finite");
  refused(tab, tdms, "finite");
  // A refused write leaves an earlier file as it was.
  write_lvm(record(false), lvm);
  write_tdms(record(false), tdms);
  const std::string before_lvm = scoleid::test::slurp(lvm), before_tdms = scoleid::test::slurp(tdms);
  tab.columns[2][3] = std::nan("");
  EXPECT_THROW(write_lvm(tab, lvm), InputError);
  EXPECT_THROW(write_tdms(tab, tdms), InputError);
  EXPECT_EQ(scoleid::test::slurp(lvm), before_lvm);
  EXPECT_EQ(scoleid::test::slurp(tdms), before_tdms);
}

// Files LabVIEW wrote (tests/data/lvm) and UFF records (tests/data/uff), read, written as LVM and
// TDMS and read again: the same table.
TEST(DataWriters, LabFilesWrittenAsLvmAndTdmsReadBackUnchanged) {
  const fs::path dir = scratch();
  const fs::path data(SCOLEID_TEST_DATA_DIR);
  int converted = 0;
  for (const fs::path& f : {data / "lvm" / "short.lvm", data / "lvm" / "multi_time_column.lvm", data / "lvm" / "with_comments.lvm",
                           data / "lvm" / "long_single_header_multi_ch.lvm", data / "lvm" / "with_empty_fields.lvm",
                           data / "uff" / "binary8byte.uff"}) {
    DataTable tab;
    try {
      tab = read_data(f.string());
    } catch (const InputError& e) {
      ADD_FAILURE() << e.what();
      continue;
    }
    const fs::path lvm = dir / (f.stem().string() + ".lvm"), tdms = dir / (f.stem().string() + ".tdms");
    write_lvm(tab, lvm.string());
    write_tdms(tab, tdms.string());
    expect_same(read_data(lvm.string()), tab, f.filename().string() + " as LVM");
    expect_same(read_data(tdms.string()), tab, f.filename().string() + " as TDMS");
    ++converted;
  }
  EXPECT_EQ(converted, 6);
}
