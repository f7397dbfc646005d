#pragma once
// fit.gp / fit.png: measured against predicted output and the residual per sensor, and the cost
// per iteration, drawn by gnuplot when it is installed.
//
// Nothing a user typed reaches a shell or gnuplot's command parser: gnuplot runs through
// io::run_program (fork + execvp with an argument vector, in the output directory, so the
// script refers to its files by bare names), and every name in the script is a gnuplot
// single-quoted string, in which gnuplot interprets nothing but '' (a quote).
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "scoleid/io/data_files.h"
#include "scoleid/io/frf_data.h"

namespace scoleid::identify {

// `text` as a gnuplot single-quoted string literal: ' doubled; line breaks and other control
// characters, which would end the command, shown as spaces.
std::string gnuplot_quote(const std::string& text);

// What the plot says beyond the curves: a title (the run, its estimates, its verdict), each
// sensor's unit, and a window [zoom_from, zoom_to] drawn beside each whole record (a record of
// many cycles is a solid band at full width; the window shows about ten of them where the response
// starts). No window when zoom_to <= zoom_from.
struct FitPlotAnnotations {
  std::string title;
  std::vector<std::string> units;
  double zoom_from = 0, zoom_to = 0;
};

// The script: reads `csv` (t, then measured, predicted, residual per sensor, in `sensors`
// order) and writes `png`; cost history as (iteration, cost) pairs. With `binary_columns` > 0
// the file is that table as write_plot_binary writes it, rows of that many values.
std::string fit_plot_script(const std::vector<std::string>& sensors, const std::vector<std::pair<int, double>>& cost,
                            const std::string& csv = "fit.csv", const std::string& png = "fit.png",
                            const FitPlotAnnotations& notes = {}, int binary_columns = 0);

// A frequency-domain fit's table: per line, per channel the measured and model FRF (real and
// imaginary parts, magnitude, phase in degrees) and the measured value's standard deviation; the
// model columns NaN when `model` (lines × channels) is empty.
io::DataTable frf_fit_table(const io::FrfData& data, const Eigen::MatrixXcd& model);
// Its script: reads `csv` (frf_fit_table's columns) and writes `png`, per channel the magnitude
// (log-log) and the phase, measured (points) and model at the estimate (line); `input` names what
// the FRFs are per unit of.
std::string frf_plot_script(const io::FrfData& data, const std::string& input, const std::string& title, const std::string& csv,
                            const std::string& png);

// The table as raw float64 rows (t, then every column; machine byte order), which gnuplot reads
// several times faster than CSV: parsing the text was most of a long record's rendering time. The
// CSV holds each value in its shortest round-trip form, so both files hold the same numbers and
// draw the same picture.
void write_plot_binary(const std::string& path, const io::DataTable& tab);

// What spectrum.gp shows: per sensor its PSD range (empty: gnuplot's own), and the fitted band
// (empty: the whole spectrum; else the x axis from half its lower edge to twice its upper one,
// the edges drawn).
struct SpectrumView {
  std::vector<std::pair<double, double>> psd_range;
  std::vector<double> band;
};
// The view of measured and predicted PSDs (bins × sensors at f): within the band's view, each
// sensor's axis from a third of the measured spectrum's lowest value (its noise floor), but at
// most nine decades under, to ten times the highest of either — not the 25 decades of a filtered
// record's stop band.
SpectrumView spectrum_view(const std::vector<double>& f, const Eigen::MatrixXd& measured, const Eigen::MatrixXd& predicted,
                           const std::vector<double>& band);

// spectrum.gp: reads `csv` (frequency in Hz, then measured and predicted power spectral density per
// sensor) and draws both on logarithmic axes, one panel per sensor, with the identified model's
// natural frequencies as vertical lines, within `view`.
std::string spectrum_plot_script(const std::vector<std::string>& sensors, const std::vector<std::string>& units,
                                 const std::vector<double>& modes_hz, const std::string& title, const SpectrumView& view = {},
                                 const std::string& csv = "spectrum.csv", const std::string& png = "spectrum.png");

enum class RenderStatus { Rendered, NoGnuplot, Failed };

// One fit.png to draw: the table (fit_table's columns), its sensors, cost history and annotations.
struct FitPlot {
  const io::DataTable* table = nullptr;
  std::vector<std::string> sensors;
  std::vector<std::pair<int, double>> cost;
  std::string png;
  FitPlotAnnotations notes;
};
// Draws every plot in `dir` from a raw float64 copy of its table (write_plot_binary) by a script
// that reads it, and runs `scripts` (names in `dir`) too, all side by side; the copies and their
// scripts are removed afterwards. Statuses in order: the plots, then `scripts`.
std::vector<RenderStatus> render_fit_plots(const std::string& dir, const std::vector<FitPlot>& plots,
                                           const std::vector<std::string>& scripts = {});

// Runs `gnuplot SCRIPT` in `dir`. Throws io::Interrupted if the program is interrupted meanwhile.
RenderStatus render_gnuplot(const std::string& dir, const std::string& script);
// The same for several scripts at once, one gnuplot each (the plots render side by side).
std::vector<RenderStatus> render_gnuplot(const std::string& dir, const std::vector<std::string>& scripts);

}  // namespace scoleid::identify
