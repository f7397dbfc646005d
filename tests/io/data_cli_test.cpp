// scole-data end to end: `info` lists a lab file's channels, `convert` writes the product's CSV
// and its column description; a record that is no time response, a missing file or an output
// directory that does not exist exits 2 with one line and writes nothing.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/cli_support.h"
#include "scoleid/io/data_files.h"
#include "scoleid/io/data_source.h"
#include "scoleid/io/error.h"
#include "scoleid/io/frf_record.h"
#include "scoleid/io/uff_frf.h"
#include "common/scratch.h"
#include "scoleid/io/uff.h"

#ifndef SCOLE_DATA_EXE
#error "SCOLE_DATA_EXE must be defined to the path of the scole-data executable"
#endif

namespace fs = std::filesystem;
using namespace scoleid::io;

namespace {

const fs::path kData = fs::path(SCOLEID_TEST_DATA_DIR) / "uff";

using Result = scoleid::test::CommandResult;
using scoleid::test::slurp;

fs::path scratch() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const fs::path d = scoleid::test::scratch_root() / info->name();
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

Result run(const std::vector<std::string>& args, const fs::path& dir) {
  return scoleid::test::run_command(SCOLE_DATA_EXE, args, dir);
}

int lines(const std::string& s) {
  int n = 0;
  for (char c : s) n += c == '\n';
  return n;
}

// Nothing but stderr.txt in the scratch directory.
void expect_nothing_written(const fs::path& dir) {
  for (const auto& e : fs::directory_iterator(dir))
    EXPECT_EQ(e.path().filename(), "stderr.txt") << "left behind: " << e.path();
}

}  // namespace

TEST(DataCli, InfoListsAUniversalFilesChannels) {
  const fs::path dir = scratch();
  const Result r = run({"info", (kData / "binary8byte.uff").string(), "--json"}, dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["format"], "uff");
  ASSERT_EQ(j["channels"].size(), 1u);
  const auto& c = j["channels"][0];
  // What the file's one record 58b says: 250 points from 0 at 0.01 s, an acceleration in g.
  EXPECT_EQ(c["samples"], 250);
  EXPECT_DOUBLE_EQ(c["step"].get<double>(), 0.01);
  EXPECT_EQ(c["unit"], "g");
  EXPECT_EQ(c["quantity"], "acceleration");
  EXPECT_EQ(c["function"], "Time Response");
  EXPECT_TRUE(c["time_response"].get<bool>());
  // The table lists what the file holds beyond functions: a header, units, nodes.
  const Result t = run({"info", (kData / "TestLab_161_164_18_15_82.uff").string()}, dir);
  ASSERT_EQ(t.code, 0) << t.err;
  EXPECT_NE(t.out.find("units (164): code 9 'USER_DEFINED'"), std::string::npos) << t.out;
  EXPECT_NE(t.out.find("nodes (15/2411): 36"), std::string::npos) << t.out;
  EXPECT_NE(t.out.find("dataset 82"), std::string::npos) << t.out;
}

TEST(DataCli, ConvertWritesTheTimeResponsesAndTheirDescription) {
  const fs::path dir = scratch();
  const Result r = run({"convert", (kData / "binary8byte.uff").string(), "--out", "b8.csv"}, dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const DataTable t = read_data((dir / "b8.csv").string());
  const uff::File f = uff::read_file((kData / "binary8byte.uff").string());
  ASSERT_EQ(t.names, std::vector<std::string>{uff::channel_name(f.functions[0])});
  // The values exactly (17 digits), in the file's unit, which the JSON beside gives back.
  EXPECT_EQ(t.columns[0], f.functions[0].re);
  EXPECT_EQ(t.t, f.functions[0].x);
  EXPECT_EQ(t.units, std::vector<std::string>{"g"});
  const auto meta = nlohmann::json::parse(slurp(dir / "b8.json"));
  EXPECT_EQ(meta["columns"][0]["quantity"], "acceleration");
  EXPECT_EQ(meta["columns"][0]["node"], 1);
}

TEST(DataCli, ConvertReadsADaqCsvWithDecimalCommas) {
  const fs::path dir = scratch();
  std::ofstream(dir / "daq.csv") << "# Messung 3\n\"Zeit [ms]\";\"Kraft [N]\";\"Beschl. Spitze [g]\"\n0;0,5;0\n1;0;-0,125\n2;0;0,25\n";
  const Result r = run({"convert", "daq.csv", "-o", "si.csv", "-q"}, dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  const DataTable t = read_data((dir / "si.csv").string());
  EXPECT_EQ(t.t, (std::vector<double>{0.0, 0.001, 0.002}));
  EXPECT_EQ(t.columns[1], (std::vector<double>{0.0, -0.125, 0.25}));
  EXPECT_EQ(t.units, (std::vector<std::string>{"N", "g"}));
}

TEST(DataCli, ASpectrumAMissingFileOrAMissingDirectoryExitTwoWritingNothing) {
  const fs::path dir = scratch();
  Result r = run({"convert", (kData / "sample_dataset58_psd.uff").string(), "--out", "psd.csv"}, dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("record 1 (dataset 58 at line 2"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("function type 9 (Power Spectral Density) is not a time response"), std::string::npos) << r.err;
  expect_nothing_written(dir);
  r = run({"info", "nowhere.uff"}, dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "scole-data: data file 'nowhere.uff': cannot be opened\n");
  r = run({"convert", (kData / "binary8byte.uff").string(), "--out", "no/such/dir/b8.csv"}, dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(lines(r.err), 1) << r.err;
  expect_nothing_written(dir);
  r = run({"frobnicate"}, dir);
  EXPECT_EQ(r.code, 2);
}

// The converted file's JSON: t stays in seconds whatever the raw file's time unit was; a JSON that
// describes other columns is refused; a same-stem JSON that is not ours (truth.json, notes) is not
// read, and `convert` never writes over one.
TEST(DataCli, TheColumnDescriptionBesideAConvertedFile) {
  const fs::path dir = scratch();
  std::ofstream(dir / "raw.csv") << "clock,a [g]\n0,1\n2,3\n";
  ASSERT_EQ(run({"convert", "raw.csv", "-o", "si.csv", "-q", "--time-unit", "ms"}, dir).code, 0);
  CsvOptions raw_options;
  raw_options.time_unit = "ms";
  const DataTable t = read_data((dir / "si.csv").string(), raw_options);
  EXPECT_EQ(t.t, (std::vector<double>{0.0, 0.002}));
  EXPECT_EQ(t.units, std::vector<std::string>{"g"});
  std::ofstream(dir / "si.json") << R"({"format": "scole-data columns 1", "columns": [{"name": "b [g]", "unit": "g"}]})";
  try {
    read_data((dir / "si.csv").string());
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("describes column 'b [g]'"), std::string::npos) << e.what();
  }
  std::ofstream(dir / "si.json") << "{ not json";
  EXPECT_EQ(read_data((dir / "si.csv").string()).units, std::vector<std::string>{"g"});  // the header's, the JSON ignored
  std::ofstream(dir / "truth.json") << R"({"scenario": "x", "format": 3})";
  const Result r = run({"convert", "raw.csv", "-o", "truth.csv"}, dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("truth.json exists and is not a scole-data column description"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "truth.csv"));
}

// convert never writes over its input (however the path is spelled), nor onto a directory: each
// refused before reading (exit 2), the input unchanged.
TEST(DataCli, ConvertNeverOverwritesItsInputNorWritesOntoADirectory) {
  const fs::path dir = scratch();
  const std::string raw = "# comment\n\"time [s]\";\"P [N]\"\n0;10\n0,01;11\n";
  scoleid::test::write_file(dir / "data.csv", raw);
  for (const std::string out : {"data.csv", "./data.csv", "sub/../data.csv"}) {
    fs::create_directories(dir / "sub");
    const Result r = run({"convert", "data.csv", "--out", out}, dir);
    EXPECT_EQ(r.code, 2) << out;
    EXPECT_EQ(lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find("is an input of this run"), std::string::npos) << r.err;
    EXPECT_EQ(slurp(dir / "data.csv"), raw);
  }
  fs::create_directories(dir / "outdir");
  const Result d = run({"convert", "data.csv", "--out", "outdir"}, dir);
  EXPECT_EQ(d.code, 2);
  EXPECT_NE(d.err.find("--out 'outdir': is a directory"), std::string::npos) << d.err;
  const Result j = run({"convert", "data.csv", "--out", "x.json"}, dir);
  EXPECT_EQ(j.code, 2);
  EXPECT_NE(j.err.find("names the column description"), std::string::npos) << j.err;
  EXPECT_FALSE(fs::exists(dir / "x.json"));
}

namespace {

std::vector<std::uint64_t> bit_patterns(const std::vector<double>& v) {
  std::vector<std::uint64_t> b(v.size());
  std::memcpy(b.data(), v.data(), v.size() * sizeof(double));
  return b;
}

void expect_same_record(const DataTable& got, const DataTable& want, const std::string& what) {
  SCOPED_TRACE(what);
  EXPECT_EQ(bit_patterns(got.t), bit_patterns(want.t));
  EXPECT_EQ(got.names, want.names);
  EXPECT_EQ(got.units, want.units);
  ASSERT_EQ(got.columns.size(), want.columns.size());
  for (std::size_t j = 0; j < want.columns.size(); ++j) EXPECT_EQ(bit_patterns(got.columns[j]), bit_patterns(want.columns[j])) << j;
}

}  // namespace

// convert writes by the output's extension: .lvm, .tdms and .uff hold the record themselves (no
// JSON beside them), and every time, name, unit and value reads back bit for bit, through any of
// them and back to CSV.
TEST(DataCli, ConvertWritesLvmTdmsAndUffByTheOutputsExtension) {
  const fs::path dir = scratch();
  for (const bool uniform : {true, false}) {
    DataTable raw;
    raw.source = "raw.csv";
    for (int k = 0; k < 30; ++k) {
      raw.t.push_back(uniform ? k / 2048.0 : k / 3.0 + 1e-9 * (k % 4));
    }
    raw.names = {"acc [g]", "F [N]"};
    raw.columns.resize(2);
    for (int k = 0; k < 30; ++k) {
      raw.columns[0].push_back(k % 3 == 0 ? -0.0 : 1.0 / (k + 2.0));
      raw.columns[1].push_back(k % 2 ? 123456789.123456789 * k : 1e-300 * (k + 1));
    }
    write_csv((dir / "raw.csv").string(), raw);
    const DataTable want = read_data((dir / "raw.csv").string());
    ASSERT_EQ(want.units, (std::vector<std::string>{"g", "N"}));
    for (const std::string out : {"out.lvm", "out.tdms", "OUT.TDMS", "out.uff", "out.unv"}) {
      const Result r = run({"convert", "raw.csv", "-o", out}, dir);
      ASSERT_EQ(r.code, 0) << r.err;
      EXPECT_NE(r.err.find("2 channels x 30 samples -> " + out), std::string::npos) << r.err;
      expect_same_record(read_data((dir / out).string()), want, out);
    }
    EXPECT_FALSE(fs::exists(dir / "out.json"));
    EXPECT_EQ(slurp(dir / "out.lvm").rfind("LabVIEW Measurement", 0), 0u);
    EXPECT_EQ(slurp(dir / "out.tdms").rfind("TDSm", 0), 0u);
    EXPECT_EQ(slurp(dir / "out.uff").rfind("    -1\n   151\n", 0), 0u);
    // A uniform clock is written as an even abscissa, any other as times beside the values.
    const uff::File u = uff::read_file((dir / "out.uff").string());
    ASSERT_EQ(u.functions.size(), 2u);
    EXPECT_EQ(u.functions[0].even, uniform);
    EXPECT_EQ(u.functions[0].function_type, 1);
    EXPECT_EQ(u.functions[0].ordinate.spec_type, 12);  // g: an acceleration
    EXPECT_EQ(u.functions[1].ordinate.spec_type, 13);  // N: a force
    // LVM to TDMS, TDMS to LVM and to CSV (with its JSON): the same record every time.
    ASSERT_EQ(run({"convert", "out.lvm", "-o", "lvm.tdms", "-q"}, dir).code, 0);
    ASSERT_EQ(run({"convert", "out.tdms", "-o", "tdms.lvm", "-q"}, dir).code, 0);
    ASSERT_EQ(run({"convert", "out.tdms", "-o", "tdms.csv", "-q"}, dir).code, 0);
    ASSERT_EQ(run({"convert", "out.uff", "-o", "uff.tdms", "-q"}, dir).code, 0);
    ASSERT_EQ(run({"convert", "out.lvm", "-o", "lvm.uff", "-q"}, dir).code, 0);
    expect_same_record(read_data((dir / "uff.tdms").string()), want, "uff.tdms");
    expect_same_record(read_data((dir / "lvm.uff").string()), want, "lvm.uff");
    expect_same_record(read_data((dir / "lvm.tdms").string()), want, "lvm.tdms");
    expect_same_record(read_data((dir / "tdms.lvm").string()), want, "tdms.lvm");
    expect_same_record(read_data((dir / "tdms.csv").string()), want, "tdms.csv");
  }
}

// A record the output's format cannot hold, or an output over the input, exits 2 with one line
// naming it; nothing written.
TEST(DataCli, ConvertRefusesWhatTheFormatCannotHoldAndItsOwnInput) {
  const fs::path dir = scratch();
  scoleid::test::write_file(dir / "data.csv", "t,a\n0,1\n0.5,2\n");
  const std::string long_name(81, 'x');
  scoleid::test::write_file(dir / "long.csv", "t," + long_name + ",b [" + std::string(21, 'm') + "]\n0,1,2\n0.5,2,3\n");
  scoleid::test::write_file(dir / "units.csv", "t,a,b [" + std::string(21, 'm') + "]\n0,1,2\n0.5,2,3\n");
  scoleid::test::write_file(dir / "hash.csv", "t,a#2,b\n0,1,2\n0.5,2,3\n");
  scoleid::test::write_file(dir / "none.csv", "t,none,b\n0,1,2\n0.5,2,3\n");
  scoleid::test::write_file(dir / "none_unit.csv", "t,a [None],b\n0,1,2\n0.5,2,3\n");
  const std::pair<const char*, const char*> cases[] = {
      {"long.csv", "does not fit ID line 1"}, {"units.csv", "does not fit the axis units label"}, {"hash.csv", "ends in '#<number>'"},
      {"none.csv", "does not fit ID line 1"}, {"none_unit.csv", "does not fit the axis units label"}};
  for (const auto& [in, why] : cases) {
    const Result r = run({"convert", in, "-o", "x.uff"}, dir);
    EXPECT_EQ(r.code, 2) << in;
    EXPECT_EQ(lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find("UFF file 'x.uff': cannot be written"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(why), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "x.uff"));
  }
  ASSERT_EQ(run({"convert", "data.csv", "-o", "d.lvm", "-q"}, dir).code, 0);
  const std::string lvm = slurp(dir / "d.lvm");
  const Result r = run({"convert", "./d.lvm", "-o", "d.lvm"}, dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("is an input of this run"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(dir / "d.lvm"), lvm);
}

// `frf`: a record's FRFs written as UFF 58 (read back by the product's FRF reader with the
// stations and averages the summary names, equal to the library's estimate to the 13 digits
// written) and as CSV; a column the file lacks exits 2 writing nothing.
TEST(DataCli, FrfWritesUffAndCsvThatReadBack) {
  const fs::path dir = scratch();
  DataTable tab;
  tab.names = {"F [N]", "acc [m/s^2]", "vel [mm/s]"};
  tab.columns.assign(3, {});
  std::uint64_t state = 12345;
  auto noise = [&] {  // a reproducible uniform (−0.5, 0.5)
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return double(state >> 11) / 9007199254740992.0 - 0.5;
  };
  double before = 0;
  for (int i = 0; i < 40000; ++i) {
    const double f = noise();
    tab.t.push_back(i / 2048.0);
    tab.columns[0].push_back(f);
    tab.columns[1].push_back(0.7 * f - 0.2 * before + 0.05 * noise());
    tab.columns[2].push_back(30 * f + 2 * noise());
    before = f;
  }
  write_csv((dir / "r.csv").string(), tab);
  const Result r = run({"frf", "r.csv", "--input", "F [N]", "--station", "vel [mm/s]=7-Y", "-o", "h.uff"}, dir);
  ASSERT_EQ(r.code, 0) << slurp(dir / "stderr.txt");
  const std::string err = slurp(dir / "stderr.txt");
  EXPECT_NE(err.find("stations: {acc: 1+Z, vel: 7-Y}"), std::string::npos) << err;
  const auto at = err.find("averages: ");
  ASSERT_NE(at, std::string::npos) << err;
  RecordFrfOptions o;
  o.input = "F [N]";
  const RecordFrf lib = frf_of_record((dir / "r.csv").string(), {}, o);
  EXPECT_EQ(std::stoi(err.substr(at + 10)), static_cast<int>(std::floor(lib.effective_averages - 1)));
  UffFrfOptions u;
  u.stations = {{"a", "1+Z"}, {"v", "7-Y"}};
  u.averages = std::stoi(err.substr(at + 10));
  std::vector<int> orders;
  const FrfData back = frf_data_from_uff(uff::read_file((dir / "h.uff").string()), "h.uff", u, &orders);
  EXPECT_EQ(orders, (std::vector<int>{2, 1}));
  ASSERT_EQ(back.f_hz.size(), lib.data.f_hz.size());
  for (int s = 0; s < 2; ++s)
    for (std::size_t k = 0; k < back.f_hz.size(); ++k) {
      EXPECT_NEAR(std::abs(back.channels[s].H[k] - lib.data.channels[s].H[k]), 0, 1e-12 * std::abs(lib.data.channels[s].H[k]));
      EXPECT_NEAR(back.channels[s].coherence[k], lib.data.channels[s].coherence[k], 1e-12);
    }
  // The velocity in mm/s is per N in m/s: |H| near 0.03.
  EXPECT_NEAR(std::abs(lib.data.channels[1].H[3]), 0.03, 0.003);

  const Result c = run({"frf", "r.csv", "--input", "F [N]", "-q", "-o", "h.csv"}, dir);
  ASSERT_EQ(c.code, 0) << slurp(dir / "stderr.txt");
  const DataTable csv = read_csv((dir / "h.csv").string());
  EXPECT_EQ(csv.t, lib.data.f_hz);
  ASSERT_EQ(csv.names.size(), 8u);
  EXPECT_EQ(csv.names[2], "acc [m/s^2] std");
  for (std::size_t k = 0; k < csv.t.size(); ++k) {
    EXPECT_DOUBLE_EQ(csv.columns[4][k], lib.data.channels[1].H[k].real());
    EXPECT_DOUBLE_EQ(csv.columns[6][k], std::sqrt(lib.data.channels[1].variance[k]));
  }

  const fs::path bad = dir / "bad";
  fs::create_directories(bad);
  fs::copy_file(dir / "r.csv", bad / "r.csv");
  const Result n = run({"frf", "r.csv", "--input", "Force", "-o", "x.uff"}, bad);
  EXPECT_EQ(n.code, 2);
  const std::string msg = slurp(bad / "stderr.txt");
  EXPECT_EQ(lines(msg), 1) << msg;
  EXPECT_NE(msg.find("--input names no column of the file"), std::string::npos) << msg;
  EXPECT_FALSE(fs::exists(bad / "x.uff"));
  const Result self = run({"frf", "r.csv", "--input", "F [N]", "-o", "r.csv"}, bad);
  EXPECT_EQ(self.code, 2);
  EXPECT_EQ(tab.t.size() + 1, static_cast<std::size_t>(lines(slurp(bad / "r.csv"))));

  // --estimator impact: a CSV whose second column is the window's decay (the values are H at
  // s = decay + iω), each value as the library gives it; a UFF cannot say s: refused, nothing written.
  const Result im = run({"frf", "r.csv", "--input", "F [N]", "--estimator", "impact", "--decay", "3", "--noise", "acc [m/s^2]=0.05",
                         "--noise", "vel [mm/s]=2", "-q", "-o", "i.csv"}, dir);
  ASSERT_EQ(im.code, 0) << slurp(dir / "stderr.txt");
  o.estimator = RecordFrfEstimator::Impact;
  o.decay = 3;
  o.noise = {{"acc [m/s^2]", 0.05}, {"vel [mm/s]", 2}};
  const RecordFrf imp = frf_of_record((dir / "r.csv").string(), {}, o);
  // (One hit has no coherence: those fields are empty.)
  std::istringstream icsv(slurp(dir / "i.csv"));
  std::string row;
  std::getline(icsv, row);
  EXPECT_EQ(row.rfind("f_hz,decay_per_s,acc [m/s^2] re,acc [m/s^2] im,acc [m/s^2] std,acc [m/s^2] coherence,", 0), 0u) << row;
  for (std::size_t k = 0; std::getline(icsv, row); ++k) {
    ASSERT_LT(k, imp.data.f_hz.size());
    std::vector<std::string> cell;
    std::istringstream fields(row);
    for (std::string c; std::getline(fields, c, ',');) cell.push_back(c);
    ASSERT_GE(cell.size(), 5u) << row;
    EXPECT_EQ(std::stod(cell[0]), imp.data.f_hz[k]);
    EXPECT_EQ(std::stod(cell[1]), 3.0);
    EXPECT_EQ(std::stod(cell[2]), imp.data.channels[0].H[k].real());
    EXPECT_EQ(std::stod(cell[4]), std::sqrt(imp.data.channels[0].variance[k]));
    EXPECT_TRUE(cell[5].empty()) << row;
  }
  const Result iu = run({"frf", "r.csv", "--input", "F [N]", "--estimator", "impact", "-o", "i.uff"}, bad);
  EXPECT_EQ(iu.code, 2);
  const std::string ium = slurp(bad / "stderr.txt");
  EXPECT_EQ(lines(ium), 1) << ium;
  EXPECT_NE(ium.find("dataset 58 cannot state"), std::string::npos) << ium;
  EXPECT_FALSE(fs::exists(bad / "i.uff"));
}

// `convert` of a truth.csv takes each column's unit from the truth.json beside it (the header
// states none): the UFF written carries them.
TEST(DataCli, ConvertTakesATruthCsvsUnitsFromItsTruthJson) {
  const fs::path dir = scratch();
  DataTable tab;
  tab.names = {"F", "roll_tip"};
  tab.t = {0.0, 0.01, 0.02};
  tab.columns = {{1, 2, 3}, {0.1, 0.2, 0.3}};
  write_csv((dir / "truth.csv").string(), tab);
  TruthMeta m;
  m.scenario = "x";
  m.structure = "scole";
  ColumnMeta f, r;
  f.name = "F", f.unit = "lb", f.kind = "input", f.quantity = "force";
  r.name = "roll_tip", r.unit = "ft", r.kind = "output", r.quantity = "displacement";
  m.columns = {f, r};
  m.true_parameters = {{"EI", 4e7}};
  write_json_atomic((dir / "truth.json").string(), to_json(m));
  const Result c = run({"convert", "truth.csv", "-o", "x.uff", "-q"}, dir);
  ASSERT_EQ(c.code, 0) << slurp(dir / "stderr.txt");
  const DataTable back = read_data((dir / "x.uff").string());
  ASSERT_EQ(back.names.size(), 2u);
  EXPECT_EQ(back.unit(0), "lb");
  EXPECT_EQ(back.unit(1), "ft");
}
