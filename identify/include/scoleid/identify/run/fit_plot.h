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

namespace scoleid::identify {

// `text` as a gnuplot single-quoted string literal: ' doubled; line breaks and other control
// characters, which would end the command, shown as spaces.
std::string gnuplot_quote(const std::string& text);

// The script: reads `csv` (t, then measured, predicted, residual per sensor, in `sensors`
// order) and writes `png`; cost history as (iteration, cost) pairs.
std::string fit_plot_script(const std::vector<std::string>& sensors, const std::vector<std::pair<int, double>>& cost,
                            const std::string& csv = "fit.csv", const std::string& png = "fit.png");

enum class RenderStatus { Rendered, NoGnuplot, Failed };
// Runs `gnuplot SCRIPT` in `dir`. Throws io::Interrupted if the program is interrupted meanwhile.
RenderStatus render_gnuplot(const std::string& dir, const std::string& script);

}  // namespace scoleid::identify
