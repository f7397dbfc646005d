// NI TDMS files (io/tdms.h): files written here byte by byte in the layout of docs/data.md "TDMS"
// (lead-in, metadata, raw data) read into the values, names, units and times they hold; the
// layouts the reader does not take refused with the file and the object named.
#include "scoleid/io/tdms.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "common/test_data.h"
#include "scoleid/io/data_source.h"
#include "scoleid/io/error.h"
#include "scoleid/io/lvm.h"
#include "common/scratch.h"
#include "scoleid/io/units.h"

namespace fs = std::filesystem;
using namespace scoleid::io;

namespace {

const auto& error_of = scoleid::test::input_error_of;

// Data types and table-of-contents bits of the format.
constexpr std::uint32_t kI16 = 2, kI32 = 3, kF32 = 9, kF64 = 10, kString = 0x20, kTimeStamp = 0x44;
constexpr std::uint32_t kMeta = 1u << 1, kNewList = 1u << 2, kRaw = 1u << 3, kInterleaved = 1u << 5, kBig = 1u << 6,
                        kDaqmx = 1u << 7;

// Bytes in one byte order.
struct Out {
  bool big = false;
  std::string bytes;
  template <class T>
  Out& put(T v) {
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof v);
    if (big) std::reverse(b, b + sizeof(T));
    bytes.append(b, sizeof(T));
    return *this;
  }
  Out& text(const std::string& s) {
    put<std::uint32_t>(static_cast<std::uint32_t>(s.size()));
    bytes += s;
    return *this;
  }
};

struct Prop {
  std::string name;
  std::uint32_t type;
  double number = 0;
  std::string text;
};
Prop num(const std::string& name, double v) { return {name, kF64, v, ""}; }
Prop str(const std::string& name, const std::string& v) { return {name, kString, 0, v}; }

// An object of a segment's metadata: raw index kNone (0xFFFFFFFF), kSame (0) or a new index.
enum class Raw { None, Same, New };
struct Obj {
  std::string path;
  Raw raw = Raw::None;
  std::uint32_t type = kF64;
  std::uint64_t count = 0;
  std::vector<Prop> props;
  std::uint32_t index_length = 20;
};

std::string metadata(const std::vector<Obj>& objs, bool big) {
  Out m{big, ""};
  m.put<std::uint32_t>(static_cast<std::uint32_t>(objs.size()));
  for (const Obj& o : objs) {
    m.text(o.path);
    if (o.raw == Raw::None) {
      m.put<std::uint32_t>(0xFFFFFFFFu);
    } else if (o.raw == Raw::Same) {
      m.put<std::uint32_t>(0);
    } else {
      m.put<std::uint32_t>(o.index_length).put<std::uint32_t>(o.type).put<std::uint32_t>(1).put<std::uint64_t>(o.count);
      if (o.index_length == 28) m.put<std::uint64_t>(0);
    }
    m.put<std::uint32_t>(static_cast<std::uint32_t>(o.props.size()));
    for (const Prop& p : o.props) {
      m.text(p.name).put<std::uint32_t>(p.type);
      if (p.type == kString) m.text(p.text);
      else if (p.type == kI32) m.put<std::int32_t>(static_cast<std::int32_t>(p.number));
      else m.put<double>(p.number);
    }
  }
  return m.bytes;
}

// One segment: lead-in (tag and table of contents little-endian, the rest in the segment's byte
// order), metadata, raw data. `next` replaces the next-segment offset when set.
std::string segment(std::uint32_t toc, const std::vector<Obj>& objs, const std::string& raw,
                    std::uint64_t next = 0) {
  const bool big = (toc & kBig) != 0;
  const std::string meta = (toc & kMeta) ? metadata(objs, big) : std::string();
  Out lead{false, "TDSm"};
  lead.put<std::uint32_t>(toc);
  lead.big = big;
  lead.put<std::uint32_t>(4713).put<std::uint64_t>(next ? next : meta.size() + raw.size()).put<std::uint64_t>(meta.size());
  return lead.bytes + meta + raw;
}

template <class T>
std::string values(const std::vector<T>& v, bool big = false) {
  Out o{big, ""};
  for (T x : v) o.put<T>(x);
  return o.bytes;
}

fs::path write_file(const std::string& name, const std::string& bytes) {
  const fs::path d = scoleid::test::scratch_root() / "tdms";
  fs::create_directories(d);
  std::ofstream(d / name, std::ios::binary) << bytes;
  return d / name;
}

std::vector<Prop> wf(double increment, double offset = 0.0) { return {num("wf_increment", increment), num("wf_start_offset", offset)}; }

// The file and group objects, then the channels.
std::vector<Obj> with_roots(std::vector<Obj> channels) {
  std::vector<Obj> all{{"/", Raw::None, 0, 0, {str("name", "test")}}, {"/'g'", Raw::None, 0, 0, {}}};
  all.insert(all.end(), channels.begin(), channels.end());
  return all;
}

}  // namespace

TEST(Tdms, Float64ContiguousReadsValuesUnitsAndTimesFromWfIncrement) {
  std::vector<Prop> pa = wf(0.5, 1.0), pb = wf(0.5, 1.0);
  pa.push_back(str("unit_string", "Newtons"));
  pb.push_back(str("unit_string", "g"));
  const std::string raw = values<double>({1.25, -2.5, 3.0}) + values<double>({0.1, 0.2, 0.3});
  const std::string file = segment(kMeta | kNewList | kRaw,
                                   with_roots({{"/'g'/'Force'", Raw::New, kF64, 3, pa}, {"/'g'/'Acc'", Raw::New, kF64, 3, pb}}), raw);
  const fs::path f = write_file("f64.tdms", file);
  const DataTable t = read_data(f.string());
  ASSERT_EQ(t.names, (std::vector<std::string>{"Force", "Acc"}));
  EXPECT_EQ(t.units, (std::vector<std::string>{"Newtons", "g"}));
  EXPECT_EQ(t.t, (std::vector<double>{1.0, 1.5, 2.0}));
  EXPECT_EQ(t.columns[0], (std::vector<double>{1.25, -2.5, 3.0}));
  EXPECT_EQ(t.columns[1], (std::vector<double>{0.1, 0.2, 0.3}));
  // "Newtons" and "g" read by the alias table as a force in N and standard gravity.
  EXPECT_EQ(units::conversion(t.units[0], "N", units::Quantity::Force).scale, 1.0);
  EXPECT_NEAR(units::conversion(t.units[1], "m/s^2", units::Quantity::Acceleration).scale, 9.80665, 1e-12);
  const DataFileInfo info = describe_data(f.string());
  EXPECT_EQ(info.format, "tdms");
  ASSERT_EQ(info.channels.size(), 2u);
  EXPECT_EQ(info.channels[1].unit, "g");
  EXPECT_DOUBLE_EQ(info.channels[0].step, 0.5);
  // The same bytes from memory.
  EXPECT_EQ(read_tdms_bytes(file, "mem.tdms").columns, t.columns);
}

TEST(Tdms, Int16WithALinearScaleReadsTheScaledValues) {
  std::vector<Prop> p = wf(0.01);
  for (const Prop& q : {str("NI_Scaling_Status", "unscaled"), num("NI_Number_Of_Scales", 1), str("NI_Scale[0]_Scale_Type", "Linear"),
                        num("NI_Scale[0]_Linear_Slope", 0.25), num("NI_Scale[0]_Linear_Y_Intercept", 1.5)})
    p.push_back(q);
  p[3].type = kI32;  // NI_Number_Of_Scales as LabVIEW writes it, an integer
  const std::vector<std::int16_t> raw{-3, 0, 7, 32767, -32768};
  const std::string file =
      segment(kMeta | kNewList | kRaw, with_roots({{"/'g'/'strain'", Raw::New, kI16, raw.size(), p}}), values(raw));
  const DataTable t = read_tdms_bytes(file, "i16.tdms");
  ASSERT_EQ(t.columns.size(), 1u);
  EXPECT_EQ(t.columns[0], (std::vector<double>{0.75, 1.5, 3.25, 8193.25, -8190.5}));
  EXPECT_DOUBLE_EQ(t.t[4], 0.04);
  // Two scales chained: the last applied to the first's output.
  std::vector<Prop> p2 = p;
  p2[3] = num("NI_Number_Of_Scales", 2);
  for (const Prop& q : {str("NI_Scale[1]_Scale_Type", "Linear"), num("NI_Scale[1]_Linear_Slope", 2.0),
                        num("NI_Scale[1]_Linear_Y_Intercept", -1.0)})
    p2.push_back(q);
  const DataTable t2 = read_tdms_bytes(
      segment(kMeta | kNewList | kRaw, with_roots({{"/'g'/'strain'", Raw::New, kI16, raw.size(), p2}}), values(raw)), "i16b.tdms");
  EXPECT_EQ(t2.columns[0], (std::vector<double>{0.5, 2.0, 5.5, 16385.5, -16382.0}));
  // Values the file states as scaled already are read as they are.
  std::vector<Prop> p3 = p;
  p3[2].text = "scaled";
  const DataTable t3 = read_tdms_bytes(
      segment(kMeta | kNewList | kRaw, with_roots({{"/'g'/'strain'", Raw::New, kI16, raw.size(), p3}}), values(raw)), "i16c.tdms");
  EXPECT_EQ(t3.columns[0], (std::vector<double>{-3, 0, 7, 32767, -32768}));
  // Any other scale is refused.
  std::vector<Prop> p4 = p;
  p4[4].text = "Polynomial";
  const std::string m = error_of([&] {
    read_tdms_bytes(segment(kMeta | kNewList | kRaw, with_roots({{"/'g'/'strain'", Raw::New, kI16, raw.size(), p4}}), values(raw)),
                    "poly.tdms");
  });
  EXPECT_NE(m.find("TDMS file 'poly.tdms': channel '/'g'/'strain'': NI_Scale[0]_Scale_Type is 'Polynomial': only Linear scales"),
            std::string::npos)
      << m;
}

TEST(Tdms, InterleavedRawDataOfTwoTypesInTwoChunks) {
  // Two chunks of 2 rows, each row an int32 and a float32.
  std::string raw;
  const std::vector<std::int32_t> a{10, -20, 30, -40};
  const std::vector<float> b{0.5f, 1.5f, -2.25f, 4.0f};
  for (std::size_t k = 0; k < 4; ++k) raw += values<std::int32_t>({a[k]}) + values<float>({b[k]});
  const std::string file = segment(kMeta | kNewList | kRaw | kInterleaved,
                                   with_roots({{"/'g'/'a'", Raw::New, kI32, 2, wf(1e-3)}, {"/'g'/'b'", Raw::New, kF32, 2, wf(1e-3)}}), raw);
  const DataTable t = read_tdms_bytes(file, "inter.tdms");
  EXPECT_EQ(t.columns[0], (std::vector<double>{10, -20, 30, -40}));
  EXPECT_EQ(t.columns[1], (std::vector<double>{0.5, 1.5, -2.25, 4.0}));
  EXPECT_EQ(t.t.size(), 4u);
  EXPECT_DOUBLE_EQ(t.t[3], 3e-3);
}

TEST(Tdms, BigEndianSegmentsReadAlikeLittleEndianOnes) {
  auto file = [](bool big) {
    std::vector<Prop> p = wf(0.25, -1.0);
    p.push_back(str("unit_string", "Pounds"));
    const std::uint32_t toc = kMeta | kNewList | kRaw | (big ? kBig : 0);
    return segment(toc, with_roots({{"/'g'/'F'", Raw::New, kF64, 3, p}, {"/'g'/'n'", Raw::New, kI16, 3, wf(0.25, -1.0)}}),
                   values<double>({1e-3, -7.5, 123456.789}, big) + values<std::int16_t>({-2, 300, 4}, big));
  };
  const DataTable le = read_tdms_bytes(file(false), "le.tdms");
  const DataTable be = read_tdms_bytes(file(true), "be.tdms");
  EXPECT_EQ(be.columns, le.columns);
  EXPECT_EQ(be.t, le.t);
  EXPECT_EQ(be.units, le.units);
  EXPECT_EQ(be.columns[0], (std::vector<double>{1e-3, -7.5, 123456.789}));
  EXPECT_EQ(be.columns[1], (std::vector<double>{-2, 300, 4}));
  EXPECT_EQ(be.t, (std::vector<double>{-1.0, -0.75, -0.5}));
}

TEST(Tdms, IncrementalMetadataAcrossSegments) {
  // Segment 1: both channels with indexes. Segment 2: metadata listing only 'a' as "same as
  // previous" (b keeps its place and index). Segment 3: no metadata, the same layout again.
  // Segment 4: a new object list with 'b' before 'a', 1 value each.
  std::string file = segment(kMeta | kNewList | kRaw, with_roots({{"/'g'/'a'", Raw::New, kF64, 2, wf(0.1)}, {"/'g'/'b'", Raw::New, kI16, 2, wf(0.1)}}),
                             values<double>({1, 2}) + values<std::int16_t>({10, 20}));
  file += segment(kMeta | kRaw, {{"/'g'/'a'", Raw::Same, 0, 0, {}}}, values<double>({3, 4}) + values<std::int16_t>({30, 40}));
  file += segment(kRaw, {}, values<double>({5, 6}) + values<std::int16_t>({50, 60}));
  file += segment(kMeta | kNewList | kRaw, {{"/'g'/'b'", Raw::New, kI16, 1, {}}, {"/'g'/'a'", Raw::New, kF64, 1, {}}},
                  values<std::int16_t>({70}) + values<double>({7}));
  // A segment of metadata only (a property changes), then raw data in the last layout.
  file += segment(kMeta, {{"/'g'/'a'", Raw::Same, 0, 0, {str("unit_string", "m")}}}, "");
  file += segment(kRaw, {}, values<std::int16_t>({80}) + values<double>({8}));
  const DataTable t = read_tdms_bytes(file, "incr.tdms");
  EXPECT_EQ(t.columns[0], (std::vector<double>{1, 2, 3, 4, 5, 6, 7, 8}));
  EXPECT_EQ(t.columns[1], (std::vector<double>{10, 20, 30, 40, 50, 60, 70, 80}));
  EXPECT_EQ(t.units[0], "m");
  EXPECT_DOUBLE_EQ(t.t[7], 0.7);
}

TEST(Tdms, SeveralChunksInOneSegment) {
  // A segment whose raw data is three chunks of (a: 2 values, b: 2 values).
  std::string raw;
  for (int c = 0; c < 3; ++c) raw += values<double>({c * 10.0, c * 10.0 + 1}) + values<double>({-c * 10.0, -c * 10.0 - 1});
  const DataTable t = read_tdms_bytes(
      segment(kMeta | kNewList | kRaw, with_roots({{"/'g'/'a'", Raw::New, kF64, 2, wf(2.0)}, {"/'g'/'b'", Raw::New, kF64, 2, wf(2.0)}}), raw),
      "chunks.tdms");
  EXPECT_EQ(t.columns[0], (std::vector<double>{0, 1, 10, 11, 20, 21}));
  EXPECT_EQ(t.columns[1], (std::vector<double>{-0.0, -1, -10, -11, -20, -21}));
  EXPECT_EQ(t.t.back(), 10.0);
}

TEST(Tdms, ATimeChannelGivesTheTimesInItsUnit) {
  std::vector<Prop> pt{str("unit_string", "ms")};
  const std::string file = segment(
      kMeta | kNewList | kRaw,
      with_roots({{"/'g'/'Time'", Raw::New, kF64, 3, pt}, {"/'g'/'y'", Raw::New, kF64, 3, {}}, {"/'g'/'note'", Raw::New, kString, 0, {}, 28}}),
      values<double>({0, 2, 5}) + values<double>({1, 2, 3}));
  const DataTable t = read_tdms_bytes(file, "time.tdms");
  EXPECT_EQ(t.names, (std::vector<std::string>{"y"}));
  EXPECT_EQ(t.time_name, "Time");
  EXPECT_EQ(t.time_unit, "ms");
  EXPECT_EQ(t.t, (std::vector<double>{0.0, 0.002, 0.005}));
  // A bracketed unit in the name ("t [ms]") says the same.
  const std::string f2 = segment(kMeta | kNewList | kRaw, with_roots({{"/'g'/'t [ms]'", Raw::New, kF64, 2, {}}, {"/'g'/'y'", Raw::New, kF64, 2, {}}}),
                                 values<double>({1, 3}) + values<double>({1, 2}));
  EXPECT_EQ(read_tdms_bytes(f2, "t.tdms").t, (std::vector<double>{0.001, 0.003}));
  // A time channel that goes back is refused naming the sample.
  const std::string f3 = segment(kMeta | kNewList | kRaw, with_roots({{"/'g'/'Time'", Raw::New, kF64, 2, {}}, {"/'g'/'y'", Raw::New, kF64, 2, {}}}),
                                 values<double>({1, 1}) + values<double>({1, 2}));
  EXPECT_NE(error_of([&] { read_tdms_bytes(f3, "back.tdms"); }).find("channel '/'g'/'Time'': sample 2: time must be strictly increasing"),
            std::string::npos);
  // A timestamp channel is a time channel: seconds after its first value.
  Out ts{false, ""};
  ts.put<std::uint64_t>(0).put<std::int64_t>(3700000000);
  ts.put<std::uint64_t>(std::uint64_t{1} << 63).put<std::int64_t>(3700000000);
  ts.put<std::uint64_t>(0).put<std::int64_t>(3700000002);
  const std::string f4 = segment(kMeta | kNewList | kRaw,
                                 with_roots({{"/'g'/'stamp'", Raw::New, kTimeStamp, 3, {}}, {"/'g'/'y'", Raw::New, kF64, 3, {}}}),
                                 ts.bytes + values<double>({1, 2, 3}));
  EXPECT_EQ(read_tdms_bytes(f4, "stamp.tdms").t, (std::vector<double>{0.0, 0.5, 2.0}));
}

TEST(Tdms, ATruncatedLastSegmentIsReadToItsLastWholeChunk) {
  const std::vector<Obj> objs = with_roots({{"/'g'/'a'", Raw::New, kF64, 2, wf(1.0)}, {"/'g'/'b'", Raw::New, kF64, 2, wf(1.0)}});
  const std::string first = segment(kMeta | kNewList | kRaw, objs, values<double>({1, 2, 3, 4}));
  // Never finished: 0xFFFFFFFFFFFFFFFF, one whole chunk and half of the next.
  const std::string second = segment(kRaw, {}, values<double>({5, 6, 7, 8}) + values<double>({9, 10}), 0xFFFFFFFFFFFFFFFFull);
  const DataTable t = read_tdms_bytes(first + second, "cut.tdms");
  EXPECT_EQ(t.columns[0], (std::vector<double>{1, 2, 5, 6}));
  EXPECT_EQ(t.columns[1], (std::vector<double>{3, 4, 7, 8}));
  // An offset past the end of the file: the same.
  const std::string third = segment(kRaw, {}, values<double>({5, 6, 7, 8}) + values<double>({9}), 1000);
  const fs::path f = write_file("cut.tdms", first + third);
  EXPECT_EQ(read_tdms(f.string()).columns[1], (std::vector<double>{3, 4, 7, 8}));
  bool noted = false;
  for (const auto& n : describe_tdms(f.string()).notes) noted = noted || n.find("past the end of the file") != std::string::npos;
  EXPECT_TRUE(noted);
  // A file cut inside the next lead-in, too.
  EXPECT_EQ(read_tdms_bytes(first + second.substr(0, 10), "lead.tdms").columns[0], (std::vector<double>{1, 2}));
  // Nothing complete: refused.
  const std::string only = segment(kMeta | kNewList | kRaw, objs, values<double>({1, 2, 3}), 0xFFFFFFFFFFFFFFFFull);
  const std::string m = error_of([&] { read_tdms_bytes(only, "none.tdms"); });
  EXPECT_NE(m.find("TDMS file 'none.tdms': no channel holds a whole chunk of samples: nothing complete to read"), std::string::npos) << m;
}

TEST(Tdms, WhatTheReaderDoesNotTakeIsRefusedNamingTheFileAndTheItem) {
  // Channels of different lengths.
  const std::string uneven = segment(kMeta | kNewList | kRaw, with_roots({{"/'g'/'a'", Raw::New, kF64, 3, wf(1)}, {"/'g'/'b'", Raw::New, kF64, 2, wf(1)}}),
                                     values<double>({1, 2, 3}) + values<double>({1, 2}));
  const fs::path fu = write_file("uneven.tdms", uneven);
  const std::string m1 = error_of([&] { read_data(fu.string()); });
  EXPECT_NE(m1.find("TDMS file '" + fu.string() + "': channel '/'g'/'b'': has 2 samples, channel '/'g'/'a'' 3: the channels of one record share one time grid"),
            std::string::npos)
      << m1;
  // An unknown data type.
  const std::string unknown = segment(kMeta | kNewList | kRaw, with_roots({{"/'g'/'odd'", Raw::New, 0x99, 3, wf(1)}}), values<double>({1, 2, 3}));
  const std::string m2 = error_of([&] { read_tdms_bytes(unknown, "odd.tdms"); });
  EXPECT_NE(m2.find("TDMS file 'odd.tdms': segment 1 (byte 0), channel '/'g'/'odd'': data type 0x99 (unknown) is not read"), std::string::npos) << m2;
  // Not a TDMS file.
  const std::string m3 = error_of([&] { read_tdms_bytes("LabVIEW Measurement\n", "lvm.tdms"); });
  EXPECT_NE(m3.find("TDMS file 'lvm.tdms': segment 1 (byte 0): does not start with the tag 'TDSm': not a TDMS file"), std::string::npos) << m3;
  // DAQmx raw data, by the table of contents or by the index.
  const std::string daq = segment(kMeta | kNewList | kRaw | kDaqmx, with_roots({{"/'g'/'ai0'", Raw::New, kF64, 1, {}}}), values<double>({1}));
  const std::string m4 = error_of([&] { read_tdms_bytes(daq, "daq.tdms"); });
  EXPECT_NE(m4.find("TDMS file 'daq.tdms': segment 1 (byte 0): DAQmx raw data"), std::string::npos) << m4;
  Obj o{"/'g'/'ai0'", Raw::New, kF64, 1, {}, 0x69120000u};
  const std::string m5 = error_of([&] { read_tdms_bytes(segment(kMeta | kNewList | kRaw, with_roots({o}), values<double>({1})), "daq2.tdms"); });
  EXPECT_NE(m5.find("TDMS file 'daq2.tdms': segment 1 (byte 0), channel '/'g'/'ai0'': DAQmx raw data (index 0x69120000)"), std::string::npos) << m5;
  // Different sampling.
  const std::string rates = segment(kMeta | kNewList | kRaw, with_roots({{"/'g'/'a'", Raw::New, kF64, 2, wf(0.1)}, {"/'g'/'b'", Raw::New, kF64, 2, wf(0.2)}}),
                                    values<double>({1, 2}) + values<double>({1, 2}));
  const std::string m6 = error_of([&] { read_tdms_bytes(rates, "rates.tdms"); });
  EXPECT_NE(m6.find("TDMS file 'rates.tdms': channel '/'g'/'b'': wf_increment 0.2 differs from the 0.1 of channel '/'g'/'a''"), std::string::npos) << m6;
  // No time at all.
  const std::string untimed = segment(kMeta | kNewList | kRaw, with_roots({{"/'g'/'a'", Raw::New, kF64, 2, {}}}), values<double>({1, 2}));
  EXPECT_NE(error_of([&] { read_tdms_bytes(untimed, "u.tdms"); }).find("channel '/'g'/'a'': no wf_increment property"), std::string::npos);
  // Values that are not finite.
  const std::string nan = segment(kMeta | kNewList | kRaw, with_roots({{"/'g'/'a'", Raw::New, kF64, 3, wf(1)}}),
                                  values<double>({1, std::numeric_limits<double>::quiet_NaN(), 3}));
  const std::string m7 = error_of([&] { read_tdms_bytes(nan, "nan.tdms"); });
  EXPECT_NE(m7.find("TDMS file 'nan.tdms': channel '/'g'/'a'': sample 2: must be finite, got nan"), std::string::npos) << m7;
  // Raw data that is not a whole number of chunks in a finished segment; sizes beyond the file.
  const std::string ragged = segment(kMeta | kNewList | kRaw, with_roots({{"/'g'/'a'", Raw::New, kF64, 2, wf(1)}}), values<double>({1, 2, 3}));
  EXPECT_NE(error_of([&] { read_tdms_bytes(ragged, "r.tdms"); }).find("raw data of 24 bytes is not a whole number of chunks of 16 bytes"),
            std::string::npos);
  const std::string huge = segment(kMeta | kNewList | kRaw, with_roots({{"/'g'/'a'", Raw::New, kF64, 1ull << 60, wf(1)}}), values<double>({1, 2}));
  EXPECT_NE(error_of([&] { read_tdms_bytes(huge, "h.tdms"); }).find("bytes per chunk, more than the file holds"), std::string::npos);
}

TEST(Tdms, GroupsHoldingDataAreReadTogetherAndRepeatedNamesQualified) {
  const std::string file = segment(kMeta | kNewList | kRaw,
                                   {{"/", Raw::None, 0, 0, {}}, {"/'empty'", Raw::None, 0, 0, {}},
                                    {"/'g1'/'x'", Raw::New, kF64, 2, wf(1)}, {"/'g2'/'x'", Raw::New, kF64, 2, wf(1)},
                                    {"/'g2'/'y'", Raw::New, kF64, 2, wf(1)}, {"/'g2'/'unused'", Raw::None, kF64, 0, wf(1)}},
                                   values<double>({1, 2}) + values<double>({3, 4}) + values<double>({5, 6}));
  const DataTable t = read_tdms_bytes(file, "groups.tdms");
  EXPECT_EQ(t.names, (std::vector<std::string>{"g1/x", "g2/x", "y"}));
  EXPECT_EQ(t.columns[2], (std::vector<double>{5, 6}));
}

// The same numbers as an LVM (X_Columns No) and as a TDMS read into the same table.
TEST(Tdms, ATdmsAndAnLvmOfTheSameNumbersGiveTheSameTable) {
  const std::vector<double> a{0.125, -3.5, 2.75, 1e-3, 42.0}, b{9.80665, -1.5, 0.0, 3.25, -7.0};
  std::string lvm = "LabVIEW Measurement\t\nWriter_Version\t2\nSeparator\tTab\nDecimal_Separator\t.\nX_Columns\tNo\n"
                    "***End_of_Header***\t\n\t\nChannels\t2\t\nSamples\t5\t5\nY_Unit_Label\tNewtons\tg\nX_Dimension\tTime\tTime\n"
                    "X0\t0.5\t0.5\nDelta_X\t0.001\t0.001\n***End_of_Header***\t\t\nX_Value\tForce\tAcc\tComment\n";
  for (std::size_t k = 0; k < a.size(); ++k) {
    char row[128];
    std::snprintf(row, sizeof row, "\t%.17g\t%.17g\n", a[k], b[k]);
    lvm += row;
  }
  std::vector<Prop> pa = wf(0.001, 0.5), pb = wf(0.001, 0.5);
  pa.push_back(str("unit_string", "Newtons"));
  pb.push_back(str("unit_string", "g"));
  const std::string tdms = segment(kMeta | kNewList | kRaw, with_roots({{"/'g'/'Force'", Raw::New, kF64, 5, pa}, {"/'g'/'Acc'", Raw::New, kF64, 5, pb}}),
                                   values(a) + values(b));
  const DataTable l = read_data(write_file("same.lvm", lvm).string());
  const DataTable t = read_data(write_file("same.tdms", tdms).string());
  EXPECT_EQ(t.names, l.names);
  EXPECT_EQ(t.units, l.units);
  ASSERT_EQ(t.t.size(), l.t.size());
  ASSERT_EQ(t.columns.size(), l.columns.size());
  for (std::size_t k = 0; k < t.t.size(); ++k) {
    EXPECT_NEAR(t.t[k], l.t[k], 1e-12);
    for (std::size_t j = 0; j < t.columns.size(); ++j) EXPECT_NEAR(t.columns[j][k], l.columns[j][k], 1e-12);
  }
}
