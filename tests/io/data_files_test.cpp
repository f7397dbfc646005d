#include "scoleid/io/data_files.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "scoleid/io/error.h"

using namespace scoleid::io;
namespace fs = std::filesystem;

namespace {
fs::path temp_dir() {
  const fs::path d = fs::temp_directory_path() / ("scoleid_io_" + std::to_string(::getpid()) + "_" +
                                                  ::testing::UnitTest::GetInstance()->current_test_info()->name());
  fs::create_directories(d);
  return d;
}
std::string write_file(const fs::path& p, const std::string& text) {
  std::ofstream(p) << text;
  return p.string();
}
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
  EXPECT_NE(error_of_csv("time,a\n0,1\n1,2\n").find("first column must be 't', got 'time'"), std::string::npos);
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
