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
// FILE is a Universal File (58/58b, 151, 164, 15, 2411, 55), a LabVIEW Measurement file (.lvm, one
// segment), an NI TDMS file (.tdms, binary) or a CSV (DAQ dialects: comment lines, any time-column
// name, quoted headers, ';' with decimal commas, units in brackets).
// Exit codes: 0 success, 2 bad usage or bad input (one line naming the file, record or line, field
// and value; nothing written), 130/143 interrupted.
#include <CLI/CLI.hpp>

#include <cctype>
#include <cstdio>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "scoleid/io/program.h"
#include "scoleid/io/data_files.h"
#include "scoleid/io/data_source.h"
#include "scoleid/io/error.h"
#include "scoleid/io/uff.h"
#include "scoleid/io/interrupt.h"
#include "scoleid/io/lvm.h"
#include "scoleid/io/output_paths.h"
#include "scoleid/io/tdms.h"
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
  const io::DataTable tab = io::read_data(file, options);
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
  io::DataTable tab = io::read_data(file, options);
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
  for (auto* sub : {info, conv}) {
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
    } else {
      convert(file, out, options, quiet);
    }
    return 0;
  });
}
