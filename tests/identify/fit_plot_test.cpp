// fit.gp / fit.png (identify/fit_plot.h): a name is only ever text to gnuplot. Sensor names
// holding quotes, semicolons and gnuplot's own `system` command are drawn as titles, run
// nothing, and the plot is still rendered; the directory may hold quotes too.
#include "scoleid/identify/run/fit_plot.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "scoleid/io/process.h"

namespace fs = std::filesystem;
using namespace scoleid::identify;

TEST(FitPlot, GnuplotQuoteDoublesQuotesAndDropsLineBreaks) {
  EXPECT_EQ(gnuplot_quote("w_tip"), "'w_tip'");
  EXPECT_EQ(gnuplot_quote("a'b"), "'a''b'");
  EXPECT_EQ(gnuplot_quote("a\nb"), "'a b'");
}

TEST(FitPlot, HostileNamesAreDrawnNotExecuted) {
  if (!scoleid::io::run_program({"gnuplot", "--version"}, ".").ok()) GTEST_SKIP() << "gnuplot is not installed";
  const fs::path dir = fs::temp_directory_path() / ("scoleid-fitplot-" + std::to_string(::getpid()) + "/mast's runs; '");
  fs::create_directories(dir);
  const fs::path marker = dir / "pwned";
  const std::vector<std::string> names = {"w'; print system(\"touch pwned\"); #", "a'.'b", "x\"; system \"touch pwned\""};
  {
    std::ofstream csv(dir / "fit.csv");
    csv << "t";
    for (std::size_t k = 0; k < names.size(); ++k) csv << ",m" << k << ",p" << k << ",r" << k;
    csv << "\n";
    for (int i = 0; i < 50; ++i) {
      csv << i * 0.1;
      for (std::size_t k = 0; k < names.size(); ++k) csv << "," << std::sin(0.1 * i + k) << "," << std::sin(0.1 * i + k) << ",0";
      csv << "\n";
    }
    // With the annotations: a hostile title and units, and a window beside each record.
    FitPlotAnnotations notes;
    notes.title = "run'; system \"touch pwned\"";
    notes.units = {"m'; system \"touch pwned\"", "g", ""};
    notes.zoom_from = 1.0;
    notes.zoom_to = 2.0;
    std::ofstream(dir / "fit.gp") << fit_plot_script(names, {{0, 1.0}, {1, 0.1}, {2, 0.01}}, "fit.csv", "fit.png", notes);
    std::ofstream spec(dir / "spectrum.csv");
    spec << "frequency_hz";
    for (std::size_t k = 0; k < names.size(); ++k) spec << ",m" << k << ",p" << k;
    spec << "\n";
    for (int i = 1; i < 50; ++i) {
      spec << i * 0.5;
      for (std::size_t k = 0; k < names.size(); ++k) spec << "," << 1.0 / (1.0 + i) << "," << 1.1 / (1.0 + i);
      spec << "\n";
    }
    spec.close();
    std::ofstream(dir / "spectrum.gp") << spectrum_plot_script(names, notes.units, {2.0, 7.5}, notes.title);
  }
  EXPECT_EQ(render_gnuplot(dir.string(), "fit.gp"), RenderStatus::Rendered);
  EXPECT_TRUE(fs::exists(dir / "fit.png") && fs::file_size(dir / "fit.png") > 1000) << "plot not drawn";
  EXPECT_EQ(render_gnuplot(dir.string(), "spectrum.gp"), RenderStatus::Rendered);
  EXPECT_TRUE(fs::exists(dir / "spectrum.png") && fs::file_size(dir / "spectrum.png") > 1000) << "spectrum not drawn";
  EXPECT_FALSE(fs::exists(marker)) << "a sensor name ran a command";
  fs::remove_all(dir.parent_path());
}
