// fit.gp / fit.png (identify/fit_plot.h): a name is only ever text to gnuplot. Sensor names
// holding quotes, semicolons and gnuplot's own `system` command are drawn as titles, run
// nothing, and the plot is still rendered; the directory may hold quotes too.
#include "scoleid/identify/run/fit_plot.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
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
    std::ofstream(dir / "spectrum.gp") << spectrum_plot_script(names, notes.units, {2.0, 7.5}, notes.title,
                                                                 SpectrumView{{{1e-3, 1.0}, {1e-3, 1.0}, {0.0, 0.0}}, {1.0, 10.0}});
  }
  EXPECT_EQ(render_gnuplot(dir.string(), "fit.gp"), RenderStatus::Rendered);
  EXPECT_TRUE(fs::exists(dir / "fit.png") && fs::file_size(dir / "fit.png") > 1000) << "plot not drawn";
  EXPECT_EQ(render_gnuplot(dir.string(), "spectrum.gp"), RenderStatus::Rendered);
  EXPECT_TRUE(fs::exists(dir / "spectrum.png") && fs::file_size(dir / "spectrum.png") > 1000) << "spectrum not drawn";
  EXPECT_FALSE(fs::exists(marker)) << "a sensor name ran a command";
  fs::remove_all(dir.parent_path());
}

// fit.png is drawn from a raw float64 copy of fit.csv (write_plot_binary): the CSV holds each value
// in its shortest round-trip form, so both files draw the same picture, byte for byte.
TEST(FitPlot, TheBinaryCopyDrawsTheSamePictureAsTheCsv) {
  if (!scoleid::io::run_program({"gnuplot", "--version"}, ".").ok()) GTEST_SKIP() << "gnuplot is not installed";
  const fs::path dir = fs::temp_directory_path() / ("scoleid-fitplot-binary-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  scoleid::io::DataTable tab;
  const std::vector<std::string> sensors = {"tip", "mid"};
  for (const auto& s : sensors) tab.names.insert(tab.names.end(), {s + "_measured", s + "_predicted", s + "_residual"});
  tab.columns.resize(tab.names.size());
  for (int i = 0; i < 400; ++i) {
    const double t = 0.01 * i;
    tab.t.push_back(t);
    for (std::size_t k = 0; k < sensors.size(); ++k) {
      // values with long expansions, so a text round trip that lost a digit would move a pixel
      const double m = std::exp(-0.3 * t) * std::sin(7.1 * t + k) / 3.0, pr = m * (1.0 + 1e-3 * std::cos(t));
      tab.columns[3 * k].push_back(m);
      tab.columns[3 * k + 1].push_back(pr);
      tab.columns[3 * k + 2].push_back(m - pr);
    }
  }
  scoleid::io::write_csv((dir / "fit.csv").string(), tab);
  write_plot_binary((dir / "fit.f64").string(), tab);
  EXPECT_EQ(fs::file_size(dir / "fit.f64"), tab.t.size() * (tab.columns.size() + 1) * sizeof(double));
  fs::remove(dir / "fit.f64");
  const std::vector<std::pair<int, double>> cost = {{0, 1.0}, {1, 0.1}};
  std::ofstream(dir / "csv.gp") << fit_plot_script(sensors, cost, "fit.csv", "csv.png");
  ASSERT_EQ(render_gnuplot(dir.string(), "csv.gp"), RenderStatus::Rendered);
  // render_fit_plots: the binary copy and its script, drawn beside another script, then removed.
  std::ofstream(dir / "again.gp") << fit_plot_script(sensors, cost, "fit.csv", "again.png");
  const auto st = render_fit_plots(dir.string(), {FitPlot{&tab, sensors, cost, "bin.png", {}}}, {"again.gp"});
  ASSERT_EQ(st.size(), 2u);
  EXPECT_EQ(st[0], RenderStatus::Rendered);
  EXPECT_EQ(st[1], RenderStatus::Rendered);
  std::vector<std::string> left;
  for (const auto& e : fs::directory_iterator(dir)) left.push_back(e.path().filename().string());
  std::sort(left.begin(), left.end());
  EXPECT_EQ(left, (std::vector<std::string>{"again.gp", "again.png", "bin.png", "csv.gp", "csv.png", "fit.csv"}));
  auto bytes = [](const fs::path& f) {
    std::ifstream in(f, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  const std::string a = bytes(dir / "csv.png"), b = bytes(dir / "bin.png");
  EXPECT_GT(a.size(), 1000u);
  EXPECT_TRUE(a == b) << "the binary copy draws a different picture";
  fs::remove_all(dir);
}

// The spectrum's view: within the band (half its lower edge to twice its upper), each sensor from a
// third of its measured floor — at most nine decades under its peak — to ten times the peak.
TEST(FitPlot, TheSpectrumIsShownWithinTheBandAndAboveTheNoiseFloor) {
  std::vector<double> f;
  Eigen::MatrixXd m(200, 2), p(200, 2);
  for (int b = 0; b < 200; ++b) {
    f.push_back(1.0 + b);
    m(b, 0) = 1.0 / (1.0 + std::pow((f.back() - 50.0) / 2.0, 2)) + 1e-4;  // a resonance over a noise floor
    m(b, 1) = std::pow(10.0, -25.0 * b / 199.0);                          // a filtered record: 25 decades
    p(b, 0) = m(b, 0);
    p(b, 1) = 2.0 * m(b, 1);
  }
  const SpectrumView v = spectrum_view(f, m, p, {20.0, 60.0});
  ASSERT_EQ(v.psd_range.size(), 2u);
  double floor = INFINITY;  // the measured floor within 10..120 Hz
  for (int b = 0; b < 200; ++b)
    if (f[static_cast<std::size_t>(b)] >= 10.0 && f[static_cast<std::size_t>(b)] <= 120.0) floor = std::min(floor, m(b, 0));
  EXPECT_NEAR(v.psd_range[0].first, floor / 3.0, 1e-15);
  EXPECT_NEAR(v.psd_range[0].second, 10.0 * (1.0 + 1e-4), 1e-9);
  const double top = 2.0 * std::pow(10.0, -25.0 * 9 / 199.0);  // the predicted peak at f = 10 Hz
  EXPECT_NEAR(v.psd_range[1].second / (10.0 * top), 1.0, 1e-12);
  EXPECT_NEAR(v.psd_range[1].first / (1e-9 * top / 3.0), 1.0, 1e-12);  // nine decades, not the stop band's floor
  const std::string gp = spectrum_plot_script({"a", "b"}, {"m", "m"}, {50.0}, "t", v);
  EXPECT_NE(gp.find("set xrange [10:120]"), std::string::npos) << gp;
  EXPECT_NE(gp.find("set yrange ["), std::string::npos) << gp;
}
