// Output files named on a command line (io/output_paths.h): never an input however spelled, never
// inside the run's output directory, never a directory; and a staged file appears only when
// committed.
#include "scoleid/io/output_paths.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>

#include "common/test_data.h"
#include "scoleid/io/error.h"

namespace fs = std::filesystem;
using namespace scoleid::io;

namespace {
const auto& error_of = scoleid::test::input_error_of;

struct Dir {
  fs::path root = fs::temp_directory_path() / ("scoleid-outpaths-" + std::to_string(::getpid()));
  Dir() {
    fs::remove_all(root);
    fs::create_directories(root / "sub");
    std::ofstream(root / "in.csv") << "t,a\n0,1\n";
  }
  ~Dir() { fs::remove_all(root); }
};
}  // namespace

TEST(OutputPaths, AnInputHoweverSpelledIsRefused) {
  Dir d;
  const std::string in = (d.root / "in.csv").string();
  for (const std::string& p : {in, (d.root / "sub" / ".." / "in.csv").string(), (d.root / "." / "in.csv").string()}) {
    const std::string m = error_of([&] { check_output_file("--out", p, {in}); });
    EXPECT_NE(m.find("is an input of this run"), std::string::npos) << p << ": " << m;
  }
  // A hard link is the same file under another name.
  fs::create_hard_link(in, d.root / "link.csv");
  EXPECT_NE(error_of([&] { check_output_file("--out", (d.root / "link.csv").string(), {in}); }).find("is an input"), std::string::npos);
  // Another name in the same directory is fine.
  EXPECT_EQ(error_of([&] { check_output_file("--out", (d.root / "out.csv").string(), {in}); }), "");
}

TEST(OutputPaths, InsideTheOutputDirectoryADirectoryOrAMissingDirectoryIsRefused) {
  Dir d;
  EXPECT_NE(error_of([&] { check_output_file("--export-model", (d.root / "sub" / "m.json").string(), {}, (d.root / "sub").string()); })
                .find("lies inside the output directory"),
            std::string::npos);
  EXPECT_NE(error_of([&] { check_output_file("--export-model", (d.root / "sub").string(), {}); }).find("is a directory"),
            std::string::npos);
  EXPECT_NE(error_of([&] { check_output_file("--export-model", (d.root / "none" / "m.json").string(), {}); }).find("does not exist"),
            std::string::npos);
  EXPECT_TRUE(inside((d.root / "sub" / "x").string(), d.root.string()));
  EXPECT_FALSE(inside((d.root.string() + "x/y"), d.root.string()));  // a sibling with a longer name
}

TEST(OutputPaths, AStagedFileAppearsOnlyWhenCommitted) {
  Dir d;
  const fs::path final_path = d.root / "m.json";
  {
    StagedFile f(final_path.string(), "test");
    EXPECT_TRUE(fs::exists(f.path()));  // made at once: a directory that takes no file is refused before work
    EXPECT_EQ(fs::path(f.path()).extension(), ".json");
    std::ofstream(f.path()) << "{}";
    EXPECT_FALSE(fs::exists(final_path));
  }
  EXPECT_FALSE(fs::exists(final_path));
  EXPECT_EQ(std::distance(fs::directory_iterator(d.root), fs::directory_iterator()), 2);  // in.csv, sub
  {
    StagedFile f(final_path.string(), "test");
    std::ofstream(f.path()) << "{}";
    f.commit();
  }
  EXPECT_TRUE(fs::is_regular_file(final_path));
  EXPECT_NE(error_of([&] { StagedFile f((d.root / "none" / "m.json").string(), "--export-model"); }).find("--export-model"),
            std::string::npos);
}
