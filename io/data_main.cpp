// scole-data: measured data as labs export it, read and converted (docs/data.md).
//   scole-data info FILE [--json]           the file's channels: name, unit, quantity, samples,
//                                           start, step, node and direction where the file has them
//   scole-data convert FILE --out OUT.csv   the time responses as the product's CSV (t in s, then
//                                           the channels in file order, values in the file's units)
//                                           and OUT.json beside it describing each column
//   scole-data convert FILE --out OUT.lvm   the same record as a LabVIEW Measurement file (lvm.h)
//   scole-data convert FILE --out OUT.tdms  the same record as an NI TDMS file (tdms.h)
//   scole-data convert FILE --out OUT.uff   the same record as a Universal File, a binary 58 per
//                                           channel (uff.h; .unv too)
//   scole-data frf FILE --input F --out OUT.uff   frequency responses of the response columns to the
//                                           force column F (Welch H1/H2 streamed, or harmonic lines;
//                                           frf_record.h) as UFF 58 FRFs + coherence (uff_frf.h), or
//                                           OUT.csv: per line f, then per response re, im, std, coherence
// FILE is a Universal File (58/58b, 151, 164, 15, 2411, 55), a LabVIEW Measurement file (.lvm, one
// segment), an NI TDMS file (.tdms, binary) or a CSV (DAQ dialects: comment lines, any time-column
// name, quoted headers, ';' with decimal commas, units in brackets).
// Exit codes: 0 success, 2 bad usage or bad input (one line naming the file, record or line, field
// and value; nothing written), 130/143 interrupted.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <cstdio>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "scoleid/io/program.h"
#include "scoleid/io/data_files.h"
#include "scoleid/io/data_source.h"
#include "scoleid/io/error.h"
#include "scoleid/io/frf_record.h"
#include "scoleid/io/number.h"
#include "scoleid/io/uff_frf.h"
#include "scoleid/io/uff.h"
#include "scoleid/io/interrupt.h"
#include "scoleid/io/lvm.h"
#include "scoleid/io/output_paths.h"
#include "scoleid/io/tdms.h"
#include "scoleid/io/units.h"
#include "scoleid/io/validation.h"

namespace {

using namespace scoleid;
using nlohmann::json;

json channel_json(const io::Channel& c) {
  json j{{"name", c.name},       {"unit", c.unit},          {"quantity", c.quantity},
         {"samples", c.samples}, {"start", c.start},        {"step", c.step},
         {"even", c.even},       {"function", c.function},  {"time_response", c.time_response},
         {"abscissa_unit", c.abscissa_unit}};
  if (c.record > 0) j["record"] = c.record;
  if (c.node > 0) j["node"] = c.node;
  if (!c.direction.empty()) j["direction"] = c.direction;
  return j;
}

// The listing: one row per channel, then the file's notes.
void print_info(const io::DataFileInfo& info) {
  std::printf("%s (%s): %zu channel%s\n", info.source.c_str(), info.format.c_str(), info.channels.size(),
              info.channels.size() == 1 ? "" : "s");
  std::printf("%-4s %-28s %-10s %-14s %9s %12s %12s %-6s %s\n", "#", "name", "unit", "quantity", "samples", "start", "step",
              "node", "function");
  int k = 0;
  for (const auto& c : info.channels) {
    const std::string node = c.node > 0 ? std::to_string(c.node) + c.direction : c.direction;
    std::printf("%-4d %-28s %-10s %-14s %9zu %12.6g %12.6g%s %-6s %s\n", ++k, io::one_line(io::shorten(c.name, 60)).c_str(),
                c.unit.empty() ? "-" : io::one_line(io::shorten(c.unit, 20)).c_str(),
                c.quantity.empty() ? "-" : io::one_line(io::shorten(c.quantity, 40)).c_str(), c.samples, c.start,
                c.step, c.even ? " " : "~", node.empty() ? "-" : node.c_str(), c.function.c_str());
  }
  for (const auto& n : info.notes) std::printf("  %s\n", n.c_str());
}

// A truth.csv's columns state no unit in their header; the truth.json beside it (scole-truth's)
// states each one. Units the table already has are kept; a JSON that is no truth.json is ignored.
io::DataTable with_truth_units(io::DataTable tab, const std::string& file) {
  std::filesystem::path meta(file);
  if (meta.extension() != ".csv") return tab;
  meta.replace_extension(".json");
  std::error_code ec;
  if (!std::filesystem::is_regular_file(meta, ec)) return tab;
  io::TruthMeta truth;
  try {
    const json j = io::read_json(meta.string());
    if (!j.is_object() || !j.contains("true_parameters") || !j.contains("columns")) return tab;
    truth = io::truth_meta_from_json(j, meta.string());
  } catch (const io::InputError&) {
    return tab;
  }
  tab.units.resize(tab.names.size());
  for (std::size_t k = 0; k < tab.names.size(); ++k)
    for (const auto& c : truth.columns)
      if (c.name == tab.names[k] && tab.units[k].empty()) tab.units[k] = c.unit;
  return tab;
}

// The format OUT's extension asks for (any case): "lvm", "tdms", "uff" (.uff, .unv), else
// "csv" (.csv, or any other name, as before).
std::string out_format(const std::string& out) {
  std::string ext = std::filesystem::path(out).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".lvm") return "lvm";
  if (ext == ".tdms") return "tdms";
  if (ext == ".uff" || ext == ".unv") return "uff";
  return "csv";
}

// OUT.lvm, OUT.tdms or OUT.uff: the record in that format, nothing beside it (the file holds the units).
void convert_to(const std::string& format, const std::string& file, const std::string& out, const io::CsvOptions& options,
                bool quiet) {
  io::check_output_file("--out", out, {file});
  const io::DataTable tab = with_truth_units(io::read_data(file, options), file);
  if (format == "lvm") io::write_lvm(tab, out);
  else if (format == "uff") io::uff::write_file(tab, out);
  else io::write_tdms(tab, out);
  if (!quiet)
    std::fprintf(stderr, "scole-data: %zu channel%s x %zu samples -> %s\n", tab.names.size(), tab.names.size() == 1 ? "" : "s",
                 tab.t.size(), out.c_str());
}

// OUT.csv and OUT.json (written to temporary files and renamed: both or neither); OUT.lvm,
// OUT.tdms or OUT.uff alone.
void convert(const std::string& file, const std::string& out, const io::CsvOptions& options, bool quiet) {
  const std::string format = out_format(out);
  if (format != "csv") return convert_to(format, file, out, options, quiet);
  // Neither output may be the input, a directory, or in a directory that cannot be written.
  {
    std::filesystem::path m(out);
    if (m.extension() == ".json")
      throw io::InputError("command line: --out '" + out + "': names the column description; give the CSV's name (OUT.json is written beside it)");
    m.replace_extension(".json");
    io::check_output_file("--out", out, {file});
    io::check_output_file("--out", m.string(), {file});
  }
  io::DataTable tab = with_truth_units(io::read_data(file, options), file);
  const io::DataFileInfo info = io::describe_data(file, options);
  json cols = json::array();
  for (std::size_t j = 0; j < tab.names.size(); ++j) {
    json c{{"name", tab.names[j]}, {"unit", tab.unit(static_cast<int>(j))}};
    for (const auto& ch : info.channels)
      if (ch.name == tab.names[j]) {
        c["quantity"] = ch.quantity;
        if (ch.node > 0) c["node"] = ch.node;
        if (!ch.direction.empty()) c["direction"] = ch.direction;
      }
    cols.push_back(c);
  }
  std::filesystem::path meta(out);
  meta.replace_extension(".json");
  if (std::filesystem::exists(meta)) {  // never over another program's JSON (a truth.json beside truth.csv)
    nlohmann::json old;
    try {
      old = io::read_json(meta.string());
    } catch (const io::InputError&) {
    }
    if (!old.is_object() || !old.contains("format") || old["format"] != io::kColumnsFormat)
      throw io::InputError("command line: --out '" + out + "': " + meta.string() +
                           " exists and is not a scole-data column description; choose another --out");
  }
  const json doc{{"format", io::kColumnsFormat}, {"source", file}, {"time", {{"name", "t"}, {"unit", "s"}}},
                 {"columns", cols}};
  io::write_json_atomic(meta.string(), doc);
  tab.time_name = "t";  // seconds, as the description says
  try {
    io::write_csv(out, tab);
  } catch (...) {
    std::error_code ec;
    std::filesystem::remove(meta, ec);
    throw;
  }
  if (!quiet)
    std::fprintf(stderr, "scole-data: %zu channel%s x %zu samples -> %s (+ %s)\n", tab.names.size(),
                 tab.names.size() == 1 ? "" : "s", tab.t.size(), out.c_str(), meta.string().c_str());
}

// The FRFs of a record, written as OUT.uff/.unv (dataset 58, function types 4 and 6) or OUT.csv.
struct FrfArgs {
  io::RecordFrfOptions options;
  std::vector<std::string> units, stations, noise;
  std::string reference, estimator = "h1", window = "hann";
};

// "NAME=VALUE" pairs of a repeated option.
std::map<std::string, std::string> pairs(const std::vector<std::string>& items, const char* option) {
  std::map<std::string, std::string> out;
  for (const auto& it : items) {
    const auto eq = it.rfind('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == it.size())
      throw io::InputError(std::string("command line: ") + option + " must be COLUMN=VALUE, got '" + io::one_line(it) + "'");
    if (!out.emplace(it.substr(0, eq), it.substr(eq + 1)).second)
      throw io::InputError(std::string("command line: ") + option + " names column '" + io::one_line(it.substr(0, eq)) + "' twice");
  }
  return out;
}

// f_hz (and, for impact FRFs, decay_per_s: the values are H at s = decay + iω), then per response
// re, im, std, coherence.
void write_frf_csv(const std::string& out, const io::RecordFrf& r) {
  const bool windowed = r.data.decay != 0;
  std::string text = windowed ? "f_hz,decay_per_s" : "f_hz";
  for (const auto& ch : r.data.channels)
    for (const char* part : {"re", "im", "std", "coherence"}) text += "," + io::csv_field(ch.sensor + " " + part);
  text += "\n";
  char buf[40];
  for (std::size_t k = 0; k < r.data.f_hz.size(); ++k) {
    std::snprintf(buf, sizeof buf, "%.17g", r.data.f_hz[k]);
    text += buf;
    if (windowed) {
      std::snprintf(buf, sizeof buf, ",%.17g", r.data.decay);
      text += buf;
    }
    for (const auto& ch : r.data.channels) {
      const double coh = ch.coherence.empty() ? std::nan("") : ch.coherence[k];
      for (double v : {ch.H[k].real(), ch.H[k].imag(), std::sqrt(ch.variance[k]), coh}) {
        std::snprintf(buf, sizeof buf, ",%.17g", v);
        text += std::isnan(v) ? std::string(",") : std::string(buf);
      }
    }
    text += "\n";
  }
  io::write_text_atomic(out, text);
}

// A column's name as a UFF ID line 1 takes it (printable ASCII, no blanks): its unit suffix dropped
// ("acc [g]" -> "acc"), blanks as '_', other characters left out; "response<k>" when nothing is left.
std::string uff_name(const std::string& column, std::size_t k) {
  std::string name = column;
  const std::string unit = io::units::bracketed_unit(name);
  if (!unit.empty()) {
    const auto open = name.find_last_of(name.back() == ']' ? '[' : '(');
    if (open != std::string::npos) name.erase(open);
  }
  std::string out;
  for (char c : name) {
    if (c == ' ' || c == '\t') out += '_';
    else if (c > ' ' && c < 127) out += c;
  }
  while (!out.empty() && out.back() == '_') out.pop_back();
  while (!out.empty() && out.front() == '_') out.erase(0, 1);
  if (out.size() > 60) out.resize(60);
  return out.empty() ? "response" + std::to_string(k + 1) : out;
}

// How to read the UFF back: the stations and the averages behind its coherence.
void summary_uff(const io::RecordFrf& r, const std::vector<std::pair<std::string, std::string>>& st) {
  std::string map;
  for (const auto& [name, station] : st) map += (map.empty() ? "" : ", ") + name + ": " + station;
  if (r.segments > 0) {
    const int averages = std::max(1, static_cast<int>(std::floor(r.effective_averages - 1.0)));
    std::fprintf(stderr,
                 "scole-data: to identify from it: identification.frf: {stations: {%s}, averages: %d} (the coherence and "
                 "K_eff - 1 averages give each value's variance)\n",
                 map.c_str(), averages);
  } else {
    std::fprintf(stderr,
                 "scole-data: stations {%s}; the file holds no coherence for harmonic lines (their variance has no place in a "
                 "UFF 58): write OUT.csv to keep each value's std, or state identification.frf.relative_std\n",
                 map.c_str());
  }
}

void frf(const std::string& file, const std::string& out, const io::CsvOptions& csv, FrfArgs a, bool quiet) {
  io::check_output_file("--out", out, {file});
  const std::string format = out_format(out);
  if (format != "uff" && format != "csv")
    throw io::InputError("command line: --out '" + out + "': frequency responses are written as OUT.uff (or .unv) or OUT.csv");
  if (a.estimator == "h1") a.options.estimator = io::RecordFrfEstimator::H1;
  else if (a.estimator == "h2") a.options.estimator = io::RecordFrfEstimator::H2;
  else if (a.estimator == "lines") a.options.estimator = io::RecordFrfEstimator::Lines;
  else if (a.estimator == "impact") a.options.estimator = io::RecordFrfEstimator::Impact;
  else throw io::InputError("command line: --estimator must be h1, h2, lines or impact, got '" + io::one_line(a.estimator) + "'");
  if (a.options.estimator == io::RecordFrfEstimator::Impact && format == "uff")
    throw io::InputError("command line: --out '" + out + "': impact FRFs are H at s = decay + i omega (an exponential window), "
                         "which a Universal File's dataset 58 cannot state; write OUT.csv");
  for (const auto& [name, value] : pairs(a.noise, "--noise")) {
    double v = 0;
    if (!io::parse_decimal(value, v))
      throw io::InputError("command line: --noise '" + io::one_line(name) + "' must be a decimal number, got '" + io::one_line(value) + "'");
    a.options.noise[name] = v;
  }
  if (a.window == "hann") a.options.window = io::FrfWindow::Hann;
  else if (a.window == "rectangular") a.options.window = io::FrfWindow::Rectangular;
  else throw io::InputError("command line: --window must be hann or rectangular, got '" + io::one_line(a.window) + "'");
  a.options.units = pairs(a.units, "--unit");
  const auto stations = pairs(a.stations, "--station");
  if (!quiet)
    a.options.progress = [](std::size_t n) { std::fprintf(stderr, "scole-data: %zu samples read\n", n); };
  io::RecordFrf r = io::frf_of_record(file, csv, a.options);
  for (const auto& [name, station] : stations)
    if (std::none_of(r.data.channels.begin(), r.data.channels.end(), [&](const auto& c) { return c.sensor == name; }))
      throw io::InputError("command line: --station names no response column, got '" + io::one_line(name) + "'");
  std::vector<std::pair<std::string, std::string>> st;
  if (format == "csv") {
    write_frf_csv(out, r);
  } else {
    // In the UFF each FRF is named as ID line 1 allows; the stations go with those names.
    for (std::size_t s = 0; s < r.data.channels.size(); ++s) {
      auto& ch = r.data.channels[s];
      const auto it = stations.find(ch.sensor);
      ch.sensor = uff_name(ch.sensor, s);
      for (std::size_t p = 0; p < s; ++p)
        if (r.data.channels[p].sensor == ch.sensor) ch.sensor = "response" + std::to_string(s + 1);
      st.emplace_back(ch.sensor, it != stations.end() ? it->second : std::to_string(s + 1) + "+Z");
    }
    io::write_uff_frf(out, r.data, st, a.reference, r.orders);
  }
  if (quiet) return;
  std::fprintf(stderr, "scole-data: %zu samples at %.9g Hz; %s\n", r.samples, r.sample_rate, r.note.c_str());
  std::fprintf(stderr, "scole-data: %zu FRF%s x %d lines -> %s\n", r.data.channels.size(), r.data.channels.size() == 1 ? "" : "s",
               r.data.lines(), out.c_str());
  if (format == "uff") summary_uff(r, st);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "scole-data: measured data as labs export it. Reads Universal Files (UFF/UNV datasets 58 and 58b time\n"
      "histories and functions, 151 header, 164 units, 15/2411 nodes, 55 mode shapes) and DAQ CSV exports\n"
      "(comment lines, any time-column name, quoted headers, ';' with decimal commas, units in brackets), and\n"
      "LabVIEW Measurement files (.lvm text: X_Columns No/One/Multi, Tab or Comma, decimal point or comma), and\n"
      "NI TDMS files (.tdms binary: integer and float channels, contiguous or interleaved, either byte order,\n"
      "linear NI_Scaling, time from wf_increment or a Time channel; DAQmx raw data refused). `convert` writes the\n"
      "record as the product's CSV, an LVM or a TDMS file, by the output's extension, every time and value exact."};
  app.require_subcommand(1);
  std::string file, out, time_column, time_unit;
  bool as_json = false, quiet = false;
  auto* info = app.add_subcommand("info", "list the file's channels (name, unit, quantity, samples, start, step, node)");
  info->add_option("file", file, "data file (UFF, LabVIEW LVM, TDMS or CSV)")->required();
  info->add_flag("--json", as_json, "print the listing as JSON");
  auto* conv = app.add_subcommand("convert", "write the time responses as the product's CSV (and a JSON of its columns), "
                                             "a LabVIEW LVM, an NI TDMS or a Universal File, by OUT's extension");
  conv->add_option("file", file, "data file (UFF, LabVIEW LVM, TDMS or CSV)")->required();
  conv->add_option("-o,--out", out,
                   "output: OUT.csv (OUT.json is written beside it), OUT.lvm (LabVIEW Measurement, tab-separated, X_Columns "
                   "One), OUT.tdms (one group 'record', float64 channels) or OUT.uff / OUT.unv (a binary dataset 58 per "
                   "channel, doubles); every time and value reads back exactly")
      ->required();
  conv->add_flag("-q,--quiet", quiet, "no summary on stderr");
  FrfArgs fa;
  auto* fr = app.add_subcommand("frf", "frequency response functions of response columns to a force column, the record streamed "
                                       "(Welch H1/H2) or fitted at known lines, written as UFF 58 FRFs with coherence or a CSV");
  fr->add_option("file", file, "data file (CSV read in chunks, any length; UFF, LVM or TDMS read whole)")->required();
  fr->add_option("-o,--out", out,
                 "OUT.uff / OUT.unv (ASCII dataset 58: FRFs in SI per N, function type 4, and coherence, type 6) or OUT.csv "
                 "(f_hz [, decay_per_s for impact], then per response: re, im, std, coherence)")
      ->required();
  fr->add_option("--input", fa.options.input, "the force column")->required();
  fr->add_option("--response", fa.options.responses, "a response column, repeated (default: every column but the input)");
  fr->add_option("--unit", fa.units, "COLUMN=UNIT for a column whose file states no unit, or states a wrong one (N, lbf, m/s^2, g, mm, ...)");
  fr->add_option("--station", fa.stations,
                 "COLUMN=<node><sign><axis> of a response in the UFF (e.g. acc_tip=3+Z; default: the k-th response at node k, +Z)");
  fr->add_option("--reference", fa.reference, "<node><sign><axis> of the excitation in the UFF (default: node 0, scalar)");
  fr->add_option("--estimator", fa.estimator,
                 "h1 (noise on the responses; default), h2 (noise on the force), lines (steady sines), impact (one hit from rest: "
                 "the record one segment under e^{-decay t}, H at s = decay + i omega; OUT.csv only)");
  fr->add_option("--decay", fa.options.decay, "impact: the exponential window's rate, 1/s (default ln(100)/T: a hundredth at the end)");
  fr->add_option("--noise", fa.noise,
                 "COLUMN=SIGMA, impact: a response's noise level in its column's unit (the input's: the force's); default: the "
                 "record's quiet start before the hit");
  fr->add_option("--segment", fa.options.segment,
                 "Welch segment length in s (default: the largest power of two of samples up to the record / 4.5: eight segments)");
  fr->add_option("--overlap", fa.options.overlap, "Welch overlap of adjacent segments, in [0, 1) (default 0.5)");
  fr->add_option("--window", fa.window, "Welch window: hann (default) or rectangular (a periodic input a whole number of periods per segment)");
  fr->add_option("--f-min", fa.options.f_min, "lowest line kept, Hz (exclusive; default 0)");
  fr->add_option("--f-max", fa.options.f_max, "highest line kept, Hz (default 0.8 of Nyquist)");
  fr->add_option("--lines", fa.options.lines_hz, "the input's frequencies, Hz, for --estimator lines")->delimiter(',');
  fr->add_option("--sample-rate", fa.options.sample_rate,
                 "the DAQ's sample rate, Hz (default: from the time column, uniform within its written precision)");
  fr->add_flag("-q,--quiet", quiet, "no summary on stderr");
  for (auto* sub : {info, conv, fr}) {
    sub->add_option("--time-column", time_column, "CSV: the time column's header (default: the first column)");
    sub->add_option("--time-unit", time_unit, "CSV: the time column's unit when its header states none (default: s)");
  }
  app.footer("Exit codes: 0 success; 2 bad usage or bad input (one line naming the file, record or line, field and "
             "value; nothing written); 130/143 interrupted.");
  if (const auto code = io::parse_command_line(app, argc, argv, "scole-data")) return *code;
  io::install_interrupt_handlers();
  return io::guarded_main("scole-data", [&] {
    const io::CsvOptions options{time_column, time_unit};
    if (*info) {
      const io::DataFileInfo d = io::describe_data(file, options);
      if (as_json) {
        json j{{"source", d.source}, {"format", d.format}, {"channels", json::array()}, {"notes", d.notes}};
        for (const auto& c : d.channels) j["channels"].push_back(channel_json(c));
        std::printf("%s\n", j.dump(2, ' ', false, json::error_handler_t::replace).c_str());
      } else {
        print_info(d);
      }
    } else if (*conv) {
      convert(file, out, options, quiet);
    } else {
      frf(file, out, options, fa, quiet);
    }
    return 0;
  });
}
