// Frequency response functions in a Universal File (io/uff_frf.h): reading them into FRF data
// (stations, signs, lines, SI units, variances from coherence or a relative deviation), writing FRF
// data as ASCII datasets 58 and reading it back, and every refusal with the field it names.
#include "scoleid/io/uff_frf.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <complex>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <cstdlib>

#include "scoleid/io/error.h"

using namespace scoleid::io;
namespace fs = std::filesystem;

namespace {

using cd = std::complex<double>;

// A small file as a modal-test program writes it, in the fixed columns of the SDRL layout: a unit
// system (dataset 164, code 5: mm and milli-newton, Fortran D25.17 factors), two FRFs of complex
// single precision (ordinate type 5: E13.5 in Fortran's 0.ddddd form, 6 values — 3 complex — a
// line, the last line short) per excitation 1+Z at 0, 2.5, ... 10 Hz: an accelerance at 3+Z in
// (mm/s^2)/mN and a mobility at 4-X in (mm/s)/mN; and the accelerance's coherence (function type
// 6, real single precision).
const char* const kHand = R"(    -1
   164
         5MM (milli-newton)            2
  0.10000000000000000D+04  0.10000000000000000D+04  0.10000000000000000D+01
  0.27315000000000000D+03
    -1
    -1
    58
acc 3+Z / 1+Z
NONE
NONE
NONE
NONE
    4         1    1         0 NONE               3   3 NONE               1   3
         5         5         1  0.00000E+00  0.25000E+01  0.00000E+00
        18    0    0    0 Frequency            Hz
        12    1    0    0 Acceleration         mm/s^2
        13    0    1    0 Force                mN
         0    0    0    0 NONE                 NONE
  0.10000E+00  0.20000E-01  0.12500E+01 -0.35000E+00 -0.27500E+01  0.41250E+00
 -0.62500E+00 -0.80000E-01  0.31250E+00  0.10000E-02
    -1
    -1
    58
vel 4-X / 1+Z
NONE
NONE
NONE
NONE
    4         2    1         0 NONE               4  -1 NONE               1   3
         5         5         1  0.00000E+00  0.25000E+01  0.00000E+00
        18    0    0    0 Frequency            Hz
        11    1    0    0 Velocity             mm/s
        13    0    1    0 Force                mN
         0    0    0    0 NONE                 NONE
  0.00000E+00  0.00000E+00  0.50000E+00  0.15000E+01 -0.25000E+00  0.75000E+00
  0.12500E+00 -0.62500E-01  0.31250E-01 -0.15625E-01
    -1
    -1
    58
coh 3+Z / 1+Z
NONE
NONE
NONE
NONE
    6         3    1         0 NONE               3   3 NONE               1   3
         2         5         1  0.00000E+00  0.25000E+01  0.00000E+00
        18    0    0    0 Frequency            Hz
         0    0    0    0 Coherence            NONE
         0    0    0    0 NONE                 NONE
         0    0    0    0 NONE                 NONE
  0.00000E+00  0.90000E+00  0.80000E+00  0.95000E+00  0.50000E+00
    -1
)";

struct TempDir {
  fs::path dir;
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir = fs::temp_directory_path() / ("scoleid-uff-frf-" + std::to_string(::getpid()) + "-" + info->name());
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
  std::string file(const std::string& name) const { return (dir / name).string(); }
};

// `text` with its only occurrence of `from` replaced.
std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto p = text.find(from);
  EXPECT_NE(p, std::string::npos) << from;
  EXPECT_EQ(text.find(from, p + 1), std::string::npos) << from;
  if (p != std::string::npos) text.replace(p, from.size(), to);
  return text;
}

const std::string kHandPath = "hand.uff";

uff::File hand(const std::string& text = kHand) { return uff::parse(text, kHandPath); }

UffFrfOptions hand_options() {
  UffFrfOptions o;
  o.stations = {{"acc", "3+Z"}, {"vel", "4-X"}};
  o.reference = "1+Z";
  o.relative_std = 0.1;
  o.averages = 20;
  o.source = "frf.yaml";
  return o;
}

std::string error_of(const uff::File& f, const UffFrfOptions& o) {
  try {
    frf_data_from_uff(f, kHandPath, o);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

bool has(const std::string& message, const std::string& part) { return message.find(part) != std::string::npos; }

// Known FRFs of three sensors on 40 lines 2, 2.25, ... 11.75 Hz: two modes' receptance-like curves
// at magnitudes from 1e-7 to 1e3, with coherence on the first sensor.
FrfData known_frfs() {
  FrfData d;
  d.source = "known";
  d.estimator = "H1";
  d.averages = 16;
  for (int k = 0; k < 40; ++k) d.f_hz.push_back(2.0 + 0.25 * k);
  const double scale[] = {3.7e2, 1.3e-4, 2.9e-7};
  const char* names[] = {"tip", "mid", "twist"};
  for (int s = 0; s < 3; ++s) {
    FrfData::Channel c;
    c.sensor = names[s];
    for (const double f : d.f_hz) {
      const cd w(0.0, 2 * M_PI * f);
      const cd h = scale[s] * (cd(1.0, 0.3 * s) / (w * w + 0.7 * w + 1500.0) + cd(-0.4, 0.11) / (w * w + 1.3 * w + 3.0e3 + 1e3 * s));
      c.H.push_back(h);
      c.variance.push_back(std::norm(h) * 1e-4);
      if (s == 0) c.coherence.push_back(0.5 + 0.49 * std::sin(f));
    }
    d.channels.push_back(c);
  }
  return d;
}

const std::vector<std::pair<std::string, std::string>> kKnownStations = {{"tip", "3+Z"}, {"mid", "5-Y"}, {"twist", "7+RX"}};
const std::vector<int> kKnownOrders = {2, 1, 0};

UffFrfOptions known_options() {
  UffFrfOptions o;
  o.stations = kKnownStations;
  o.reference = "1+Z";
  o.relative_std = 0.05;
  o.source = "frf.yaml";
  return o;
}

double relative(cd a, cd b) { return std::abs(a - b) / std::abs(b); }

}  // namespace

// Written and read back: the same lines, every value to 1e-12 relative (13 significant digits),
// the coherence, the response orders; the datasets as the format states them.
TEST(UffFrf, WriteThenReadGivesTheKnownFrfsBack) {
  TempDir t;
  const std::string path = t.file("known.uff");
  const FrfData d = known_frfs();
  write_uff_frf(path, d, kKnownStations, "1+Z", kKnownOrders);
  const uff::File file = uff::read_file(path);
  std::vector<int> orders;
  const FrfData r = frf_data_from_uff(file, path, known_options(), &orders);
  EXPECT_EQ(r.source, path);
  EXPECT_EQ(r.estimator, "file");
  EXPECT_EQ(r.input, "1+Z");
  EXPECT_EQ(r.averages, 0);
  EXPECT_EQ(orders, kKnownOrders);
  EXPECT_EQ(r.f_hz, d.f_hz);  // 2 + 0.25 k is exact in the 13-character header fields
  ASSERT_EQ(r.channels.size(), 3u);
  for (std::size_t s = 0; s < 3; ++s) {
    EXPECT_EQ(r.channels[s].sensor, d.channels[s].sensor);
    ASSERT_EQ(r.channels[s].H.size(), d.f_hz.size());
    for (std::size_t k = 0; k < d.f_hz.size(); ++k) {
      EXPECT_LT(relative(r.channels[s].H[k], d.channels[s].H[k]), 1e-12) << s << " " << k;
      // No averages: every value weighted by relative_std.
      EXPECT_NEAR(r.channels[s].variance[k], std::pow(0.05 * std::abs(r.channels[s].H[k]), 2),
                  1e-14 * r.channels[s].variance[k]);
    }
  }
  ASSERT_EQ(r.channels[0].coherence.size(), d.f_hz.size());
  for (std::size_t k = 0; k < d.f_hz.size(); ++k) EXPECT_NEAR(r.channels[0].coherence[k], d.channels[0].coherence[k], 1e-12);
  EXPECT_TRUE(r.channels[1].coherence.empty());

  // What other readers find: per channel a type-4 function (complex double, even abscissa in Hz,
  // spec types by the response order, denominator force) and a type-6 one beside the coherence.
  ASSERT_EQ(file.functions.size(), 4u);
  const auto& tip = file.functions[0];
  EXPECT_EQ(tip.function_type, 4);
  EXPECT_EQ(tip.ordinate_type, 6);
  EXPECT_FALSE(tip.binary);
  EXPECT_TRUE(tip.even);
  EXPECT_EQ(tip.abscissa_min, 2.0);
  EXPECT_EQ(tip.abscissa_increment, 0.25);
  EXPECT_EQ(tip.abscissa.spec_type, 18);
  EXPECT_EQ(uff::abscissa_unit(tip), "Hz");
  EXPECT_EQ(tip.ordinate.spec_type, 12);
  EXPECT_EQ(uff::ordinate_unit(tip), "m/s^2");
  EXPECT_EQ(tip.denominator.spec_type, 13);
  EXPECT_EQ(tip.denominator.force_exp, 1);
  EXPECT_EQ(tip.id1, "tip");
  EXPECT_EQ(tip.response_node, 3);
  EXPECT_EQ(tip.response_direction, 3);
  EXPECT_EQ(tip.reference_node, 1);
  EXPECT_EQ(tip.reference_direction, 3);
  EXPECT_EQ(file.functions[1].function_type, 6);
  EXPECT_EQ(file.functions[1].ordinate_type, 4);
  EXPECT_EQ(file.functions[2].ordinate.spec_type, 11);
  EXPECT_EQ(file.functions[2].response_direction, -2);  // the station's signed axis
  EXPECT_EQ(file.functions[3].ordinate.spec_type, 8);
  EXPECT_EQ(file.functions[3].ordinate.length_exp, 0);  // a rotation: rad
  EXPECT_EQ(uff::ordinate_unit(file.functions[3]), "rad");
  ASSERT_TRUE(file.units);
  EXPECT_EQ(file.units->code, 1);

  // Fixed columns: no line over 80 characters; complex double values 4 of 20 characters a line.
  // The first FRF's 80 values (40 complex) are 20 full lines right after its 11 header lines.
  std::ifstream in(path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) {
    EXPECT_LE(line.size(), 80u) << line;
    lines.push_back(line);
  }
  const std::size_t first = static_cast<std::size_t>(tip.line) + 11;
  ASSERT_GT(lines.size(), first + 20);
  for (std::size_t i = first; i < first + 20; ++i) {
    ASSERT_EQ(lines[i].size(), 80u) << lines[i];
    for (std::size_t j = 0; j < 4; ++j) {
      const std::string field = lines[i].substr(20 * j, 20);
      EXPECT_EQ(field[0], field[0] == '-' ? '-' : ' ') << field;  // a blank before every value
      const std::size_t v = 2 * (i - first) + j / 2;
      EXPECT_EQ(std::strtod(field.c_str(), nullptr), j % 2 ? tip.im[v] : tip.re[v]);
    }
  }
  EXPECT_EQ(lines[first + 20], "    -1");
  // Record 7 splits at blanks too: ordinate type, num_pts, spacing, minimum, increment, z value.
  std::istringstream record7(lines[static_cast<std::size_t>(tip.line) + 6]);
  std::vector<std::string> tokens;
  for (std::string w; record7 >> w;) tokens.push_back(w);
  EXPECT_EQ(tokens, (std::vector<std::string>{"6", "40", "1", "2.000000E+00", "2.500000E-01", "0.00000E+00"}));
}

// Lines that are not evenly spaced are written with each line before its values (uneven
// abscissa), each to 7 significant digits.
TEST(UffFrf, UnevenLinesAreWrittenWithTheirValues) {
  TempDir t;
  const std::string path = t.file("uneven.uff");
  FrfData d = known_frfs();
  d.f_hz = {1.0, 2.5, 2.7, 10.123456789};
  for (auto& c : d.channels) {
    c.H.resize(4);
    c.variance.resize(4);
    if (!c.coherence.empty()) c.coherence.resize(4);
  }
  write_uff_frf(path, d, kKnownStations, "1+Z", kKnownOrders);
  const uff::File file = uff::read_file(path);
  EXPECT_FALSE(file.functions[0].even);
  // Each data line splits at blanks: a complex point a line (x re im), two real points a line.
  std::ifstream in(path);
  std::vector<std::string> text;
  for (std::string line; std::getline(in, line);) text.push_back(line);
  auto count = [](const std::string& line) {
    std::istringstream is(line);
    int n = 0;
    for (std::string w; is >> w;) ++n;
    return n;
  };
  const auto at = [&](const uff::Function& f, std::size_t i) { return text[static_cast<std::size_t>(f.line) + 11 + i]; };
  for (std::size_t i = 0; i < 4; ++i) EXPECT_EQ(count(at(file.functions[0], i)), 3) << at(file.functions[0], i);
  EXPECT_EQ(at(file.functions[0], 4), "    -1");
  EXPECT_EQ(count(at(file.functions[1], 0)), 4) << at(file.functions[1], 0);
  EXPECT_EQ(count(at(file.functions[1], 1)), 4);
  EXPECT_EQ(at(file.functions[1], 2), "    -1");
  const FrfData r = frf_data_from_uff(file, path, known_options());
  ASSERT_EQ(r.lines(), 4);
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(r.f_hz[k], d.f_hz[k], 5e-7 * d.f_hz[k]);
  for (std::size_t s = 0; s < 3; ++s)
    for (int k = 0; k < 4; ++k) EXPECT_LT(relative(r.channels[s].H[k], d.channels[s].H[k]), 1e-12);
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(r.channels[0].coherence[k], d.channels[0].coherence[k], 1e-12);
}

// A "-" station reads the node's axis the other way: H negated. So does a reference given with
// the other sign; "" takes the file's one reference as it is written.
TEST(UffFrf, SignsOfStationAndReference) {
  TempDir t;
  const std::string path = t.file("known.uff");
  write_uff_frf(path, known_frfs(), kKnownStations, "1+Z", kKnownOrders);
  const uff::File file = uff::read_file(path);
  const FrfData base = frf_data_from_uff(file, path, known_options());
  UffFrfOptions o = known_options();
  o.stations = {{"tip", "3-Z"}, {"mid", "5+Y"}, {"twist", "7+RX"}};
  const FrfData flipped = frf_data_from_uff(file, path, o);
  o = known_options();
  o.reference = "1-Z";
  const FrfData other_ref = frf_data_from_uff(file, path, o);
  o.reference = "";
  const FrfData shared = frf_data_from_uff(file, path, o);
  EXPECT_EQ(shared.input, "");
  for (std::size_t k = 0; k < base.f_hz.size(); ++k) {
    EXPECT_EQ(flipped.channels[0].H[k], -base.channels[0].H[k]);
    EXPECT_EQ(flipped.channels[1].H[k], -base.channels[1].H[k]);
    EXPECT_EQ(flipped.channels[2].H[k], base.channels[2].H[k]);
    for (std::size_t s = 0; s < 3; ++s) {
      EXPECT_EQ(other_ref.channels[s].H[k], -base.channels[s].H[k]);
      EXPECT_EQ(shared.channels[s].H[k], base.channels[s].H[k]);
    }
  }
}

// With coherence and averages, σ² = (1 − γ²)/(γ² · averages)·|H|²; a station without coherence
// is weighted by relative_std, and without that it is refused naming the option.
TEST(UffFrf, CoherenceAndAveragesGiveTheVariance) {
  TempDir t;
  const std::string path = t.file("known.uff");
  write_uff_frf(path, known_frfs(), kKnownStations, "1+Z", kKnownOrders);
  const uff::File file = uff::read_file(path);
  UffFrfOptions o = known_options();
  o.averages = 16;
  const FrfData r = frf_data_from_uff(file, path, o);
  EXPECT_EQ(r.averages, 16);
  for (std::size_t k = 0; k < r.f_hz.size(); ++k) {
    const double g = r.channels[0].coherence[k];
    const double expected = (1 - g) / (g * 16) * std::norm(r.channels[0].H[k]);
    EXPECT_NEAR(r.channels[0].variance[k], expected, 1e-13 * expected);
    EXPECT_NEAR(r.channels[1].variance[k], std::norm(0.05 * r.channels[1].H[k]), 1e-13 * r.channels[1].variance[k]);
  }
  o.relative_std = 0;
  try {
    frf_data_from_uff(file, path, o);
    FAIL() << "no deviation for 'mid' accepted";
  } catch (const InputError& e) {
    EXPECT_TRUE(has(e.what(), "frf.yaml: frf.relative_std must be > 0: the file has no coherence (function type 6) for station 'mid'"))
        << e.what();
  }
}

// The hand-written file: fixed 13-character single-precision fields in Fortran's form, the 0 Hz
// line left out, accelerance read as order 2 and mobility as order 1, values in SI: in the MM
// system 1 (mm/s^2)/mN = 1e-3 (m/s^2) / 1e-3 N = 1 (m/s^2)/N, so exactly the written numbers.
TEST(UffFrf, ReadsAHandWrittenFixedColumnFile) {
  const uff::File f = hand();
  ASSERT_EQ(f.functions.size(), 3u);
  EXPECT_EQ(f.functions[0].value_bytes, 4);
  EXPECT_EQ(f.functions[0].ordinate_type, 5);
  std::vector<int> orders;
  const FrfData d = frf_data_from_uff(f, kHandPath, hand_options(), &orders);
  EXPECT_EQ(orders, (std::vector<int>{2, 1}));
  EXPECT_EQ(d.f_hz, (std::vector<double>{2.5, 5.0, 7.5, 10.0}));
  ASSERT_EQ(d.channels.size(), 2u);
  EXPECT_EQ(d.channels[0].sensor, "acc");
  const std::vector<cd> acc = {{1.25, -0.35}, {-2.75, 0.4125}, {-0.625, -0.08}, {0.3125, 0.001}};
  const std::vector<double> gamma2 = {0.9, 0.8, 0.95, 0.5};
  const std::vector<cd> vel = {{0.5, 1.5}, {-0.25, 0.75}, {0.125, -0.0625}, {0.03125, -0.015625}};
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_EQ(d.channels[0].H[k], acc[k]);
    EXPECT_EQ(d.channels[0].coherence[k], gamma2[k]);
    EXPECT_DOUBLE_EQ(d.channels[0].variance[k], (1 - gamma2[k]) / (gamma2[k] * 20) * std::norm(acc[k]));
    EXPECT_EQ(d.channels[1].H[k], vel[k]);  // station 4-X on the file's 4-X
    EXPECT_TRUE(d.channels[1].coherence.empty());
    EXPECT_DOUBLE_EQ(d.channels[1].variance[k], 0.01 * std::norm(vel[k]));
  }
  UffFrfOptions o = hand_options();
  o.stations = {{"vel", "4+X"}};
  const FrfData plus = frf_data_from_uff(f, kHandPath, o);
  EXPECT_EQ(plus.channels[0].H[0], -vel[0]);
}

// Dataset 164's factors and the axes' exponents into SI, against factors worked by hand.
TEST(UffFrf, UnitSystemsConvertIntoSi) {
  const std::string mm_mN = "         5MM (milli-newton)            2\n"
                            "  0.10000000000000000D+04  0.10000000000000000D+04  0.10000000000000000D+01";
  auto accelerance = [&](const std::string& units) {
    return frf_data_from_uff(hand(replaced(kHand, mm_mN, units)), kHandPath, hand_options()).channels[0].H[0];
  };
  const cd written(1.25, -0.35);
  // MN: mm and N. 1 (mm/s^2)/N = 1e-3 (m/s^2)/N.
  EXPECT_EQ(accelerance("        10MN (newton)                  2\n"
                        "  0.10000000000000000D+04  0.10000000000000000D+01  0.10000000000000000D+01"),
            written * 1e-3);
  // GM: mm and kilogram force. 1 (mm/s^2)/kgf = 1e-3 (m/s^2) / 9.80665 N = 1.0197162129779e-4 (m/s^2)/N.
  const cd gm = accelerance("         8GM (kilogram f)              2\n"
                            "  0.10000000000000000D+04  0.10197162129779283D+00  0.10000000000000000D+01");
  EXPECT_LT(relative(gm, written * 1.0197162129779283e-4), 1e-14);
  // The same system with its factors written the other way up (a writer's inverse): read as SDRL's.
  const cd gm_inverse = accelerance("         8GM (kilogram f)              2\n"
                                    "  0.10000000000000000D-02  0.98066500000000000D+01  0.10000000000000000D+01");
  EXPECT_LT(relative(gm_inverse, written * 1.0197162129779283e-4), 1e-14);
  // User defined: as written. Length 2, force 8 (file units per SI unit): (1/2)/(1/8) = 4 → H · 8/2.
  EXPECT_EQ(accelerance("         9USER_DEFINED                 2\n"
                        "  0.20000000000000000D+01  0.80000000000000000D+01  0.10000000000000000D+01"),
            written * 4.0);
  // Exponents that make no response per force cannot be converted when the factors matter.
  const std::string units = "        10MN (newton)                  2\n"
                            "  0.10000000000000000D+04  0.10000000000000000D+01  0.10000000000000000D+01";
  const std::string zero_exp = replaced(replaced(kHand, mm_mN, units), "        12    1    0    0 Acceleration",
                                        "        12    0    0    0 Acceleration");
  const std::string e = error_of(hand(zero_exp), hand_options());
  EXPECT_TRUE(has(e, "UFF file 'hand.uff': record 2 (dataset 58 at line 8, Frequency Response Function at 3+Z per 1+Z): "
                     "ordinate length units exponent less the denominator's must be 1 for a translation"))
      << e;
  EXPECT_TRUE(has(e, "got 0 - 0")) << e;
  // In SI (or MM's cancelling factors for this numerator) the same exponents change nothing.
  EXPECT_EQ(frf_data_from_uff(hand(replaced(replaced(kHand, mm_mN,
                                                     "         1SI                           2\n"
                                                     "  0.10000000000000000D+01  0.10000000000000000D+01  0.10000000000000000D+01"),
                                            "        12    1    0    0 Acceleration", "        12    0    0    0 Acceleration")),
                              kHandPath, hand_options())
                .channels[0]
                .H[0],
            written);
}

TEST(UffFrf, StationsAndReferenceTheFileLacksAreRefused) {
  const uff::File f = hand();
  UffFrfOptions o = hand_options();
  o.stations = {{"tip", "9+Z"}};
  EXPECT_EQ(error_of(f, o),
            "frf.yaml: frf.stations.tip must be the response of a frequency response function (function type 4) per 1+Z in UFF "
            "file 'hand.uff', whose responses there are 3+Z, 4-X, got '9+Z'");
  o.stations = {{"tip", "3*Z"}};
  EXPECT_EQ(error_of(f, o), "frf.yaml: frf.stations.tip must be <node><+|-><X|Y|Z|RX|RY|RZ> (e.g. 12+Y) or <node> (scalar), got '3*Z'");
  o.stations = {{"a", "3+Z"}, {"b", "3-Z"}};
  EXPECT_TRUE(has(error_of(f, o), "frf.stations.b must name a response no other station names (frf.stations.a is at it), got '3-Z'"));
  o.stations = {{"a", "3+Z"}, {"a", "4-X"}};
  EXPECT_TRUE(has(error_of(f, o), "frf.stations.a must be given once"));
  o = hand_options();
  o.reference = "8+Z";
  EXPECT_EQ(error_of(f, o),
            "frf.yaml: frf.reference must be the reference of a frequency response function (function type 4) in UFF file "
            "'hand.uff', whose references are 1+Z, got '8+Z'");
  o.reference = "1+Q";
  EXPECT_TRUE(has(error_of(f, o), "frf.yaml: frf.reference must be <node>"));
  // Two references and none chosen.
  const std::string two = replaced(kHand, "    4         2    1         0 NONE               4  -1 NONE               1   3",
                                   "    4         2    1         0 NONE               4  -1 NONE               2   1");
  o.reference = "";
  EXPECT_EQ(error_of(hand(two), o),
            "frf.yaml: frf.reference must name the excitation: the FRFs in UFF file 'hand.uff' have several references "
            "(1+Z, 2+X), got ''");
  // No FRF at all.
  EXPECT_TRUE(has(error_of(hand(replaced(replaced(kHand, "    4         1    1", "    1         1    1"), "    4         2    1",
                                         "    1         2    1")),
                           hand_options()),
                  "UFF file 'hand.uff': no frequency response function (dataset 58, function type 4)"));
}

TEST(UffFrf, DuplicateFunctionsAreRefused) {
  // The velocity FRF moved onto 3+Z: two FRFs for one station and reference.
  std::string text = replaced(kHand, "    4         2    1         0 NONE               4  -1",
                              "    4         2    1         0 NONE               3   3");
  UffFrfOptions o = hand_options();
  o.stations = {{"acc", "3+Z"}};
  EXPECT_EQ(error_of(hand(text), o),
            "UFF file 'hand.uff': record 3 (dataset 58 at line 24, Frequency Response Function at 3+Z per 1+Z): response and "
            "reference must be those of one function only: record 2 is the same function type at the same response and "
            "reference, got '3+Z' per '1+Z'");
}

TEST(UffFrf, AbscissaAndUnitsOtherThanAnFrfsAreRefused) {
  const UffFrfOptions o = hand_options();
  const std::string where = "UFF file 'hand.uff': record 2 (dataset 58 at line 8, Frequency Response Function at 3+Z per 1+Z): ";
  EXPECT_EQ(error_of(hand(replaced(kHand, "        18    0    0    0 Frequency            Hz\n        12",
                                   "        17    0    0    0 Time                 s\n        12")),
                     o),
            where + "abscissa specific data type must be 18 (frequency), got 17");
  EXPECT_EQ(error_of(hand(replaced(kHand, "        18    0    0    0 Frequency            Hz\n        12",
                                   "        18    0    0    0 Frequency            rad/s\n        12")),
                     o),
            where + "abscissa units label must be Hz (or NONE), got 'rad/s'");
  EXPECT_EQ(error_of(hand(replaced(kHand, "        12    1    0    0 Acceleration", "        13    0    1    0 Force       ")), o),
            where + "ordinate specific data type must be 8 (displacement), 11 (velocity) or 12 (acceleration), got 13");
  EXPECT_EQ(error_of(hand(replaced(kHand, "        13    0    1    0 Force                mN\n         0    0    0    0 NONE                 NONE\n  0.100",
                                   "        12    1    0    0 Acceleration         mm/s^2\n         0    0    0    0 NONE                 NONE\n  0.100")),
                     o),
            where + "ordinate denominator specific data type must be 13 (excitation force), got 12");
  // A real "FRF" (a magnitude, say) is not one.
  const std::string real =
      replaced(kHand, "         5         5         1  0.00000E+00  0.25000E+01  0.00000E+00\n        18    0    0    0 Frequency            Hz\n        12",
               "         2        10         1  0.00000E+00  0.25000E+01  0.00000E+00\n        18    0    0    0 Frequency            Hz\n        12");
  EXPECT_EQ(error_of(hand(real), o), where + "ordinate data type must be 5 or 6 (complex) for a frequency response function, got 2");
  // Lines that differ between stations: the velocity's increment 2.4 Hz.
  const std::string lines = replaced(kHand, "    4         2    1         0 NONE               4  -1 NONE               1   3\n"
                                            "         5         5         1  0.00000E+00  0.25000E+01",
                                     "    4         2    1         0 NONE               4  -1 NONE               1   3\n"
                                     "         5         5         1  0.00000E+00  0.24000E+01");
  EXPECT_EQ(error_of(hand(lines), o),
            "UFF file 'hand.uff': record 3 (dataset 58 at line 24, Frequency Response Function at 4-X per 1+Z): lines must be those "
            "of record 2 (4 lines 2.5 to 10 Hz: line 1 is 2.4 Hz against 2.5 Hz): every station's FRF and coherence share one set "
            "of lines, got 4 lines 2.4 to 9.6 Hz");
  // A value the reader accepted that is not finite in SI (set in memory: text holds finite numbers only).
  uff::File inf = hand();
  inf.functions[0].re[2] = std::numeric_limits<double>::infinity();
  EXPECT_TRUE(has(error_of(inf, o), where + "value 3 (5 Hz) must be finite, of magnitude at most 1e+24 in SI, got inf+0.4125i")) << error_of(inf, o);
  inf = hand();
  inf.functions[0].im[4] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(has(error_of(inf, o), where + "value 5 (10 Hz) must be finite, of magnitude at most 1e+24 in SI, got 0.3125+nani")) << error_of(inf, o);
}

TEST(UffFrf, CoherenceThatCannotWeightIsRefused) {
  const UffFrfOptions o = hand_options();
  const std::string coh = "  0.00000E+00  0.90000E+00  0.80000E+00  0.95000E+00  0.50000E+00";
  const std::string where = "UFF file 'hand.uff': record 4 (dataset 58 at line 40, Coherence at 3+Z per 1+Z): ";
  EXPECT_EQ(error_of(hand(replaced(kHand, coh, "  0.00000E+00  0.90000E+00  0.00000E+00  0.95000E+00  0.50000E+00")), o),
            where + "coherence at point 3 (5 Hz) must be in (0, 1] to weight the FRF with frf.averages, got 0");
  EXPECT_EQ(error_of(hand(replaced(kHand, coh, "  0.00000E+00  0.90000E+00  0.80000E+00  0.15000E+01  0.50000E+00")), o),
            where + "coherence at point 4 (7.5 Hz) must be in (0, 1] to weight the FRF with frf.averages, got 1.5");
  // γ² = 1: variance 0, a value known exactly; the user is told to weight by relative_std.
  const std::string one = replaced(kHand, coh, "  0.00000E+00  0.90000E+00  0.10000E+01  0.95000E+00  0.50000E+00");
  EXPECT_EQ(error_of(hand(one), o),
            where + "coherence at point 3 (5 Hz) gives the value variance 0 (coherence 1), which cannot weight it: state "
                    "frf.relative_std (with frf.averages: 0) in frf.yaml to weight the values by their magnitude instead, got 1");
  UffFrfOptions by_magnitude = o;
  by_magnitude.averages = 0;
  const FrfData d = frf_data_from_uff(hand(one), kHandPath, by_magnitude);
  EXPECT_EQ(d.channels[0].coherence[1], 1.0);
  EXPECT_DOUBLE_EQ(d.channels[0].variance[1], 0.01 * std::norm(d.channels[0].H[1]));
  // Without averages, coherence 0 is a coherence (kept), but not one above 1.
  EXPECT_EQ(frf_data_from_uff(hand(replaced(kHand, coh, "  0.00000E+00  0.90000E+00  0.00000E+00  0.95000E+00  0.50000E+00")),
                              kHandPath, by_magnitude)
                .channels[0]
                .coherence[1],
            0.0);
  EXPECT_EQ(error_of(hand(replaced(kHand, coh, "  0.00000E+00  0.90000E+00  0.80000E+00  0.15000E+01  0.50000E+00")), by_magnitude),
            where + "coherence at point 4 (7.5 Hz) must be in [0, 1], got 1.5");
  // A coherence of complex values is not one.
  uff::File complex = hand();
  complex.functions[2].ordinate_type = 5;
  complex.functions[2].im.assign(5, 0.0);
  EXPECT_EQ(error_of(complex, o), where + "ordinate data type must be 2 or 4 (real) for a coherence, got 5");
}

TEST(UffFrf, MissingDeviationsNameTheOptions) {
  const uff::File f = hand();
  UffFrfOptions o = hand_options();
  o.relative_std = 0;
  // 'acc' has coherence and averages; 'vel' has neither.
  EXPECT_EQ(error_of(f, o),
            "frf.yaml: frf.relative_std must be > 0: the file has no coherence (function type 6) for station 'vel' (UFF file "
            "'hand.uff': record 3 (dataset 58 at line 24, Frequency Response Function at 4-X per 1+Z)) to weight it with "
            "frf.averages, got 0");
  o.averages = 0;
  o.stations = {{"acc", "3+Z"}};
  EXPECT_EQ(error_of(f, o),
            "frf.yaml: frf.averages must be > 0 to weight station 'acc' by its coherence (UFF file 'hand.uff': record 4 (dataset 58 "
            "at line 40, Coherence at 3+Z per 1+Z)), or frf.relative_std > 0, got 0");
  o = hand_options();
  o.relative_std = -0.1;
  EXPECT_EQ(error_of(f, o), "frf.yaml: frf.relative_std must be a relative standard deviation >= 0, got -0.1");
  o = hand_options();
  o.averages = -3;
  EXPECT_EQ(error_of(f, o), "frf.yaml: frf.averages must be >= 0, got -3");
  o = hand_options();
  o.stations.clear();
  EXPECT_EQ(error_of(f, o), "frf.yaml: frf.stations must name at least one sensor, got none");
}

TEST(UffFrf, WriterRefusesWhatItCannotWrite) {
  TempDir t;
  const std::string path = t.file("bad.uff");
  auto error = [&](const FrfData& d, const std::vector<std::pair<std::string, std::string>>& st, const std::string& ref,
                   const std::vector<int>& orders) {
    try {
      write_uff_frf(path, d, st, ref, orders);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const std::string where = "UFF file '" + path + "': cannot be written: ";
  const FrfData d = known_frfs();
  EXPECT_EQ(error(d, {{"tip", "3+Z"}, {"mid", "5-Y"}}, "1+Z", kKnownOrders), where + "sensor 'twist' has no station (<node><sign><axis>)");
  EXPECT_EQ(error(d, {{"tip", "3+Z"}, {"mid", "3-Z"}, {"twist", "7+RX"}}, "1+Z", kKnownOrders),
            where + "sensor 'mid' is at the response of sensor 'tip' ('3-Z'): one FRF per response and reference");
  EXPECT_EQ(error(d, kKnownStations, "1+Z", {2, 3, 0}),
            where + "sensor 'mid': response order must be 0 (displacement), 1 (velocity) or 2 (acceleration), got 3");
  EXPECT_EQ(error(d, kKnownStations, "1+Z", {2, 1}), where + "response orders must number 3 (one per channel), got 2");
  EXPECT_TRUE(has(error(d, kKnownStations, "1*Z", kKnownOrders), where + "reference must be <node>"));
  FrfData bad = d;
  bad.f_hz[3] = bad.f_hz[2];
  EXPECT_EQ(error(bad, kKnownStations, "1+Z", kKnownOrders), where + "line 4 must be a frequency > 0 Hz above the one before, got 2.5");
  bad = d;
  bad.channels[1].H[5] = cd(std::nan(""), 0.0);
  EXPECT_TRUE(has(error(bad, kKnownStations, "1+Z", kKnownOrders), where + "sensor 'mid': value at line 6 must be finite"));
  bad = d;
  bad.channels[0].coherence[0] = 1.5;
  EXPECT_EQ(error(bad, kKnownStations, "1+Z", kKnownOrders), where + "sensor 'tip': coherence at line 1 must be in [0, 1], got 1.5");
  EXPECT_FALSE(fs::exists(path));
}
