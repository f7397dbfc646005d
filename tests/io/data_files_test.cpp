#include "scoleid/io/data_files.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "common/cli_support.h"
#include "common/scratch.h"
#include "scoleid/io/error.h"

using namespace scoleid::io;
namespace fs = std::filesystem;

namespace {
fs::path temp_dir() {
  const fs::path d = scoleid::test::scratch_root() / ::testing::UnitTest::GetInstance()->current_test_info()->name();
  fs::create_directories(d);
  return d;
}
using scoleid::test::write_file;
std::string error_of_csv(const std::string& text) {
  const auto p = write_file(temp_dir() / "d.csv", text);
  try {
    read_csv(p);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(DataFiles, CsvRoundTripIsExact) {
  DataTable t;
  t.names = {"P", "w"};
  t.t = {0.0, 0.1, 0.2};
  t.columns = {{10.0, 10.0, 10.0}, {0.0, 1.0 / 3.0, -2.5e-17}};
  const auto p = (temp_dir() / "truth.csv").string();
  write_csv(p, t);
  const DataTable r = read_csv(p);
  EXPECT_EQ(r.names, t.names);
  EXPECT_EQ(r.t, t.t);
  EXPECT_EQ(r.columns, t.columns);
  EXPECT_DOUBLE_EQ(r.interpolate(1, 0.05), 1.0 / 6.0);
  // nothing but the target file is left in the directory
  int files = 0;
  for (const auto& e : fs::directory_iterator(fs::path(p).parent_path())) files += e.is_regular_file();
  EXPECT_EQ(files, 1);
}

TEST(DataFiles, CsvErrorsNameFileLineColumnValue) {
  EXPECT_NE(error_of_csv("time\n0\n1\n").find("line 1: no data columns beside the time column 'time'"), std::string::npos);
  EXPECT_NE(error_of_csv("t,a\n0,1\n0,2\n").find("line 3, column 't': time must be strictly increasing, got 0 after 0"),
            std::string::npos);
  EXPECT_NE(error_of_csv("t,a\n0,1\n1,nan\n").find("line 3, column 'a': must be finite, got nan"), std::string::npos);
  EXPECT_NE(error_of_csv("t,a\n0,1\n1,x\n").find("line 3, column 'a': not a number, got 'x'"), std::string::npos);
  EXPECT_NE(error_of_csv("t,a\n0,1\n1\n").find("line 3: expected 2 fields, got 1"), std::string::npos);
  EXPECT_NE(error_of_csv("").find("empty"), std::string::npos);
  EXPECT_NE(error_of_csv("t,a,a\n0,1,2\n1,1,1\n").find("duplicate column 'a'"), std::string::npos);
}

TEST(DataFiles, MissingCsvIsNamed) {
  try {
    read_csv("/nonexistent/truth.csv");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "data file '/nonexistent/truth.csv': cannot be opened");
  }
}

TEST(DataFiles, TruthMetaRoundTrips) {
  TruthMeta m;
  m.scenario = "paper-beam-1";
  m.structure = "beam";
  m.columns.push_back({"P", "N", "input", "force", "beam", 5.0, {0, 0, 0}, 0.0});
  m.columns.push_back({"w_mid", "m", "output", "displacement", "beam", 5.0, {0, 0, 0}, 1e-4});
  m.true_parameters = {{"EI", 23000.0}, {"rho_A", 67.0}};
  const auto p = (temp_dir() / "truth.json").string();
  write_json_atomic(p, to_json(m));
  const TruthMeta r = read_truth_meta(p);
  ASSERT_EQ(r.columns.size(), 2u);
  EXPECT_EQ(r.columns[1].quantity, "displacement");
  EXPECT_DOUBLE_EQ(r.columns[1].noise_std, 1e-4);
  EXPECT_DOUBLE_EQ(r.true_parameters.at("EI"), 23000.0);
}

TEST(DataFiles, MalformedJsonIsNamed) {
  const auto p = write_file(temp_dir() / "bad.json", "{\"a\": [1, 2");
  try {
    read_json(p);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("malformed"), std::string::npos);
  }
}

// A DAQ export as a test engineer's software writes it: a comment line, a time column named
// otherwise, channels with free-text names and units in brackets.
TEST(DataFiles, DaqCsvTimeColumnByPositionNamesAndUnits) {
  const auto p = write_file(temp_dir() / "daq.csv",
                            "# exported 2026-11-30, 2 kHz\n"
                            "Time [ms],Hammer [N],\"Acc1, @0.30m [g]\",Acc3 @tip [g]\n"
                            "0,0,0.5,1e-3\n0.5,2.5,-0.25,2e-3\n1.0,0,0,3e-3\n");
  const DataTable t = read_csv(p);
  EXPECT_EQ(t.time_name, "Time [ms]");
  EXPECT_EQ(t.time_unit, "ms");
  ASSERT_EQ(t.names, (std::vector<std::string>{"Hammer [N]", "Acc1, @0.30m [g]", "Acc3 @tip [g]"}));
  EXPECT_EQ(t.units, (std::vector<std::string>{"N", "g", "g"}));
  // t in seconds: the header's ms converted (UDUNITS: 1 ms = 1e-3 s)
  ASSERT_EQ(t.t.size(), 3u);
  EXPECT_DOUBLE_EQ(t.t[1], 0.5e-3);
  EXPECT_DOUBLE_EQ(t.t[2], 1.0e-3);
  // the values stay in the file's units
  EXPECT_EQ(t.columns[1], (std::vector<double>{0.5, -0.25, 0.0}));
}

TEST(DataFiles, SemicolonSeparatorReadsDecimalCommas) {
  const auto p = write_file(temp_dir() / "eu.csv", "Zeit [s];Kraft [N];Beschl. [m/s^2]\r\n0,000;1,5;-2,25\r\n0,001;0;1e-3\r\n");
  const DataTable t = read_csv(p);
  EXPECT_EQ(t.names, (std::vector<std::string>{"Kraft [N]", "Beschl. [m/s^2]"}));
  EXPECT_EQ(t.t, (std::vector<double>{0.0, 0.001}));
  EXPECT_EQ(t.columns[0], (std::vector<double>{1.5, 0.0}));
  EXPECT_EQ(t.columns[1], (std::vector<double>{-2.25, 1e-3}));
  // a comma-separated file keeps its commas as separators: "1,5" there is two fields
  EXPECT_NE(error_of_csv("t,a\n0,1,5\n").find("line 2: expected 2 fields, got 3"), std::string::npos);
}

TEST(DataFiles, TimeColumnByNameAndUnitOption) {
  const auto p = write_file(temp_dir() / "named.csv", "a,stamp,b\n1,0,2\n3,10,4\n5,20,6\n");
  CsvOptions o;
  o.time_column = "stamp";
  o.time_unit = "ms";
  const DataTable t = read_csv(p, o);
  EXPECT_EQ(t.names, (std::vector<std::string>{"a", "b"}));
  EXPECT_EQ(t.columns[0], (std::vector<double>{1, 3, 5}));
  EXPECT_EQ(t.columns[1], (std::vector<double>{2, 4, 6}));
  EXPECT_DOUBLE_EQ(t.t[2], 0.02);
  o.time_column = "clock";
  try {
    read_csv(p, o);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no time column 'clock' (data.time_column)"), std::string::npos) << e.what();
  }
  // a time unit that is no time
  EXPECT_NE(error_of_csv("t [m],a\n0,1\n1,2\n").find("time column 't [m]': unit 'm' is not a unit of time"), std::string::npos);
}

TEST(DataFiles, FreeTextNamesRoundTripThroughWriteCsv) {
  DataTable t;
  t.names = {"Acc1, @0.30m [g]", "say \"hi\"", "plain"};
  t.t = {0.0, 1.0};
  t.columns = {{1, 2}, {3, 4}, {5, 6}};
  const auto p = (temp_dir() / "free.csv").string();
  write_csv(p, t);
  const DataTable r = read_csv(p);
  EXPECT_EQ(r.names, t.names);
  EXPECT_EQ(r.columns, t.columns);
  EXPECT_EQ(r.units, (std::vector<std::string>{"g", "", ""}));
}

// truth.json of the wrong shape: one line naming the file and the field, never the JSON library's text.
TEST(DataFiles, TruthJsonTypeErrorsNameTheField) {
  auto error_of = [](const std::string& text) {
    try {
      truth_meta_from_json(nlohmann::json::parse(text), "truth.json");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(error_of(R"({"columns": [{"name": "w", "kind": "output", "noise_std": "big"}]})"),
            "truth.json: columns['w'].noise_std must be a number (or a list of numbers), got text");
  EXPECT_EQ(error_of(R"({"columns": [{"name": 3}]})"), "truth.json: columns[0].name must be text, got a number");
  EXPECT_EQ(error_of(R"({"columns": {"w": 1}})"), "truth.json: columns must be a list, got an object");
  EXPECT_EQ(error_of(R"({"true_parameters": {"EI": "23000"}})"), "truth.json: true_parameters.EI must be a number, got text");
  EXPECT_EQ(error_of(R"([1, 2])"), "truth.json: document must be a JSON object, got a list");
  EXPECT_EQ(error_of(R"({"scenario": 7})"), "truth.json: scenario must be text, got a number");
}

TEST(DataFiles, BlanksAroundQuotesAndATrailingSeparator) {
  EXPECT_EQ(split_csv_line("t, \"a b\" ,c"), (std::vector<std::string>{"t", "a b", "c"}));
  EXPECT_EQ(split_csv_line("\" x \",y"), (std::vector<std::string>{" x ", "y"}));  // inside quotes: kept
  const auto p = write_file(temp_dir() / "trailing.csv", "Zeit [s];Kraft [N];\n0;1,5;\n0,5;2;\n");
  const DataTable t = read_csv(p);
  EXPECT_EQ(t.names, std::vector<std::string>{"Kraft [N]"});
  EXPECT_EQ(t.columns[0], (std::vector<double>{1.5, 2.0}));
}

// Hexadecimal is no number in a data file (strtod would read 0x1p-10 as 0.0009765625).
TEST(DataFiles, HexadecimalCellsAreRefused) {
  EXPECT_NE(error_of_csv("t,a\n0,1\n1,0x1p-10\n").find("line 3, column 'a': not a number, got '0x1p-10'"), std::string::npos);
  EXPECT_NE(error_of_csv("t,a\n0,1\n0x10,1\n").find("line 3, column 't': not a number, got '0x10'"), std::string::npos);
  EXPECT_NE(error_of_csv("t,a\n0,1\n1,1e400\n").find("line 3, column 'a': must be finite"), std::string::npos);
}

// A table built in memory (a program's, Python's) passes the checks a file's does.
TEST(DataFiles, ATableBuiltInMemoryIsCheckedAsAFileIs) {
  auto table = [] {
    DataTable t;
    t.source = "mem";
    t.t = {0.0, 0.1, 0.2};
    t.names = {"a"};
    t.columns = {{1.0, 2.0, 3.0}};
    return t;
  };
  auto error_of_table = [](const DataTable& t) {
    try {
      check_table(t);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(error_of_table(table()), "");
  DataTable t = table();
  t.columns[0][1] = std::nan("");
  EXPECT_EQ(error_of_table(t), "data 'mem': column 'a', sample 2 (t = 0.1 s): must be finite, got nan");
  t = table();
  t.t[2] = 0.1;
  EXPECT_EQ(error_of_table(t), "data 'mem': time, sample 3: must be strictly increasing (after 0.1), got 0.1");
  t = table();
  t.t = {};
  t.columns[0] = {};
  EXPECT_EQ(error_of_table(t), "data 'mem': needs at least 2 samples, got 0");
  t = table();
  t.columns[0].pop_back();
  EXPECT_EQ(error_of_table(t), "data 'mem': column 'a' has 2 values for 3 times");
  t = table();
  t.columns[0][0] = 1e300;
  EXPECT_NE(error_of_table(t).find("magnitude must be at most"), std::string::npos);
  t = table();
  t.names = {"t"};
  EXPECT_NE(error_of_table(t).find("has the time column's name"), std::string::npos);
}

TEST(DataFiles, ATrueValueBeyondTheScenarioRangeIsRefused) {
  const auto d = temp_dir();
  const auto p = write_file(d / "truth.json", R"({"true_parameters": {"EI": 1e308}})");
  std::string msg;
  try {
    read_truth_meta(p);
  } catch (const InputError& e) {
    msg = e.what();
  }
  EXPECT_NE(msg.find("true_parameters.EI must be 0 or of magnitude within"), std::string::npos) << msg;
}

// Columns held in memory with a header (a DataFrame's) are read as a CSV with that header is: the
// time column chosen alike, the bracketed units taken alike, the time converted alike.
TEST(DataFiles, ColumnsInMemoryAreReadAsACsvWithTheirHeader) {
  const std::string csv = "a [g],Time [ms],b\n1,0,4\n2,0.5,5\n3,1.25,6\n";
  const CsvOptions by_name{"Time [ms]", ""};
  const DataTable file = read_csv_text(csv, "f.csv", by_name);
  const DataTable mem = table_from_columns({"a [g]", "Time [ms]", "b"}, {{1, 2, 3}, {0, 0.5, 1.25}, {4, 5, 6}}, "mem", by_name);
  EXPECT_EQ(mem.t, file.t);
  EXPECT_EQ(mem.t, (std::vector<double>{0.0, 0.0005, 0.00125}));
  EXPECT_EQ(mem.names, file.names);
  EXPECT_EQ(mem.units, file.units);
  EXPECT_EQ(mem.units, (std::vector<std::string>{"g", ""}));
  EXPECT_EQ(mem.columns, file.columns);
  // No time column named: the first, as in a file; a unit for an unstated time from the options.
  const DataTable first = table_from_columns({"x", "a"}, {{0, 2, 4}, {1, 1, 1}}, "mem", {"", "ms"});
  EXPECT_EQ(first.t, (std::vector<double>{0.0, 0.002, 0.004}));
  auto error_of = [](const std::vector<std::string>& header, const std::vector<std::vector<double>>& cols, const CsvOptions& o) {
    try {
      table_from_columns(header, cols, "mem", o);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(error_of({"t", "a"}, {{0, 1}, {1, 2}}, {"time", ""}), "data 'mem': no time column 'time' (data.time_column); the header's first is 't'");
  EXPECT_EQ(error_of({"t [m]", "a"}, {{0, 1}, {1, 2}}, {}), "data 'mem': time column 't [m]': unit 'm' is not a unit of time");
  EXPECT_EQ(error_of({"t", "a"}, {{1, 0}, {1, 2}}, {}), "data 'mem': time, sample 2: must be strictly increasing (after 1), got 0");
  EXPECT_EQ(error_of({"t", "t"}, {{0, 1}, {1, 2}}, {}), "data 'mem': duplicate column 't'");
}

// The chunked reader gives read_csv's table, chunk by chunk: comments, blank lines, a quoted
// field, decimal commas and a time column in ms read alike whatever the chunk size.
TEST(DataFiles, CsvReaderChunksGiveReadCsvsTable) {
  const std::string text =
      "# exported\nTime [ms];\"Acc, tip [g]\";F [N]\n0;1,5;-2\n0,5;2;3e-1\n\n# pause\n1;\"2,5\";4\n1,5;-1;0\n2;7;8\n";
  const DataTable whole = read_csv_text(text, "x.csv");
  for (std::size_t chunk : {1u, 2u, 3u, 100u}) {
    std::istringstream in(text);
    CsvReader r(in, "x.csv");
    EXPECT_EQ(r.header().names, whole.names);
    EXPECT_EQ(r.header().units, whole.units);
    std::vector<double> t, all_t;
    std::vector<std::vector<double>> cols, all(2);
    while (r.read(chunk, t, cols) > 0) {
      EXPECT_LE(t.size(), chunk);
      all_t.insert(all_t.end(), t.begin(), t.end());
      for (int j = 0; j < 2; ++j) all[j].insert(all[j].end(), cols[j].begin(), cols[j].end());
    }
    EXPECT_EQ(r.rows(), 5u);
    EXPECT_EQ(all_t, whole.t) << "chunk " << chunk;
    EXPECT_EQ(all, whole.columns) << "chunk " << chunk;
  }
  EXPECT_DOUBLE_EQ(whole.t[1], 0.5e-3);
  EXPECT_DOUBLE_EQ(whole.columns[0][2], 2.5);
  // The sample limit names the line of the first row beyond it.
  std::istringstream in(text);
  CsvReader r(in, "x.csv");
  std::vector<double> t;
  std::vector<std::vector<double>> cols;
  try {
    r.read(100, t, cols, 3);
    ADD_FAILURE() << "a fourth row read under a limit of 3";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("line 8: more than 3 samples"), std::string::npos) << e.what();
  }
}
