// The validation pass (io/validation.h) and the scenario loader's document checks: each finding
// of a hostile-input review is reproduced here and must be refused with an InputError that
// names the field and the value (never another exception, a crash, a hang or a silent default).
#include "common/test_data.h"
#include "scoleid/io/validation.h"

#include <gtest/gtest.h>

#include <chrono>
#include <nlohmann/json.hpp>
#include <string>

#include "scoleid/io/data_files.h"
#include "scoleid/io/error.h"
#include "scoleid/io/limits.h"
#include "scoleid/io/scenario.h"

using namespace scoleid::io;

namespace {
// A valid beam scenario with `extra` appended (YAML).
const char* kBase = R"(name: v
beam: {length: 10, left: clamped, right: free, rho_A: 67, EI: 23000}
simulation: {duration: 2, sample_interval: 0.01}
)";

std::string error_of(const std::string& yaml) { return scoleid::test::scenario_error(yaml, "scenario 's.yaml'"); }

::testing::AssertionResult refused(const std::string& yaml, const std::vector<std::string>& needles) {
  const std::string e = error_of(yaml);
  if (e.empty()) return ::testing::AssertionFailure() << "accepted:\n" << yaml;
  for (const auto& n : needles)
    if (e.find(n) == std::string::npos) return ::testing::AssertionFailure() << "'" << n << "' missing from: " << e;
  if (e.find('\n') != std::string::npos) return ::testing::AssertionFailure() << "multi-line message: " << e;
  return ::testing::AssertionSuccess();
}
}  // namespace

TEST(Names, CharacterClassAndReservedTime) {
  for (const char* ok : {"w_tip", "P", "roll-tip.2", "_x", "9a"}) EXPECT_TRUE(valid_name(ok)) << ok;
  for (const char* bad : {"", "t", "w,tip", "w tip", "w\ntip", "-a", ".a", "w'x", "w\"x", "a;b", "é"})
    EXPECT_FALSE(valid_name(bad)) << bad;
  EXPECT_TRUE(valid_name(std::string(limits::kMaxNameLength, 'a')));
  EXPECT_FALSE(valid_name(std::string(limits::kMaxNameLength + 1, 'a')));
}

TEST(Names, SensorAndInputNamesThatBreakACsvAreRefused) {
  const std::string in = "inputs: [{name: P, at: beam, location: 10, signal: {type: step, amplitude: 1}}]\n";
  EXPECT_TRUE(refused(std::string(kBase) + in + "sensors: [{name: 'w,tip', location: 10}]\n", {"sensors[0].name", "'w,tip'"}));
  EXPECT_TRUE(refused(std::string(kBase) + in + "sensors: [{name: \"w\\ntip\", location: 10}]\n", {"sensors[0].name", "w\\ntip"}));
  EXPECT_TRUE(refused(std::string(kBase) + in + "sensors: [{name: '', location: 10}]\n", {"sensors[0].name", "''"}));
  EXPECT_TRUE(refused(std::string(kBase) + in + "sensors: [{name: P, location: 10}]\n",
                      {"sensors[0].name", "unique among inputs and sensors", "'P'"}));
  EXPECT_TRUE(refused(std::string(kBase) + in + "sensors: [{name: t, location: 10}]\n", {"sensors[0].name", "'t'"}));
  EXPECT_TRUE(refused(std::string(kBase) + in + "sensors: [{name: \"w'; print system(\\\"touch pwned\\\"); #\", location: 10}]\n",
                      {"sensors[0].name"}));
  EXPECT_TRUE(refused("name: ../../etc\n", {"name", "'../../etc'"}));
}

TEST(Document, DuplicateKeysAreRefusedAtAnyDepth) {
  EXPECT_TRUE(refused("name: a\nname: b\n", {"name appears more than once"}));
  EXPECT_TRUE(refused(std::string(kBase) + "truth: {segments: 10, segments: 20}\n", {"truth.segments appears more than once"}));
  EXPECT_TRUE(refused(std::string(kBase) + "sensors: [{name: w, location: 1, location: 2}]\n",
                      {"sensors[0].location appears more than once"}));
}

TEST(Document, InvalidUtf8IsRefusedBeforeAndAfterYamlEscapes) {
  EXPECT_TRUE(refused(std::string(kBase) + "description: \"caf\xC3\"\n", {"not valid UTF-8", "line 4"}));
  // YAML's \N and \_ decode to the single bytes 0x85 and 0xA0: refused, not left to break the
  // JSON echo of the scenario later.
  EXPECT_TRUE(refused(std::string(kBase) + "description: \"\\N\"\n", {"description", "UTF-8"}));
  EXPECT_TRUE(refused(std::string(kBase) + "description: \"\\_\"\n", {"description", "UTF-8"}));
  // Valid multi-byte text passes and survives the echo.
  const Scenario s = parse_scenario(std::string(kBase) + "description: \"Träger, 3 m — ζ\"\n", "s");
  EXPECT_NO_THROW(to_json(s).dump());
}

TEST(Document, SelfReferencingAndExpandingAliasesEndQuickly) {
  // A self-referencing alias (once a stack overflow) and 10^9 nodes of nested aliases (once a
  // 10 s walk) are each read in well under a second.
  std::string bomb = "a0: &a0 [x, x, x, x, x, x, x, x, x, x]\n";
  for (int k = 1; k <= 9; ++k) {
    const std::string p = "*a" + std::to_string(k - 1);
    bomb += "a" + std::to_string(k) + ": &a" + std::to_string(k) + " [" + p;
    for (int i = 1; i < 10; ++i) bomb += ", " + p;
    bomb += "]\n";
  }
  for (const std::string& doc : {std::string("a: &a [*a]\n"), std::string("a: &a {b: *a}\n"), bomb}) {
    const auto t0 = std::chrono::steady_clock::now();
    EXPECT_NE(error_of(doc), "");  // unknown fields, but refused cleanly
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 1.0);
  }
}

TEST(Numbers, ExtremeFiniteValuesAreRefused) {
  EXPECT_TRUE(refused("name: v\nbeam: {EI: 1e300}\n", {"beam.EI", "magnitude", "1e+300"}));
  EXPECT_TRUE(refused("name: v\nbeam: {rho_A: 1e-300}\n", {"beam.rho_A", "magnitude"}));
  EXPECT_TRUE(refused(std::string(kBase) +
                          "inputs: [{name: P, location: 10, signal: {type: step, amplitude: 1e308}}]\n",
                      {"inputs[0].signal.amplitude", "magnitude"}));
  EXPECT_EQ(error_of(std::string(kBase) + "inputs: [{name: P, location: 10, signal: {type: step, amplitude: 0}}]\n"), "");
}

TEST(Counts, SamplesStepsSegmentsAndElementsAreBounded) {
  EXPECT_TRUE(refused("name: v\nsimulation: {duration: 1e9, sample_interval: 0.01}\n",
                      {"simulation.sample_interval", "samples", "limit"}));
  EXPECT_TRUE(refused("name: v\nsimulation: {duration: 20, sample_interval: 1e-9}\n",
                      {"simulation.sample_interval", "samples", "1e-09"}));
  EXPECT_TRUE(refused(std::string(kBase) + "truth: {output_interval: 1e-9}\n", {"truth.output_interval"}));
  // The anti-alias corner must lie below the output's Nyquist frequency (50 Hz at 0.01 s).
  EXPECT_TRUE(refused(std::string(kBase) + "truth: {anti_alias_hz: 50}\n", {"truth.anti_alias_hz", "Nyquist", "50"}));
  EXPECT_TRUE(refused(std::string(kBase) + "truth: {anti_alias_hz: -1}\n", {"truth.anti_alias_hz"}));
  EXPECT_EQ(error_of(std::string(kBase) + "truth: {anti_alias_hz: 49}\n"), "");
  EXPECT_TRUE(refused(std::string(kBase) + "identification: {time_step: 1e-12}\n",
                      {"identification.time_step", "steps", "1e-12"}));
  EXPECT_TRUE(refused(std::string(kBase) + "truth: {segments: 10000000}\n", {"truth.segments", "10000000"}));
  EXPECT_TRUE(refused(std::string(kBase) + "identification: {elements: 100000}\n", {"identification.elements"}));
  EXPECT_EQ(sample_count(2.0, 0.01), 201.0);
}

TEST(Plausibility, AttachedMassesInertiasAndOffsetsAreBoundedByTheStructuresOwn) {
  // The beam of kBase weighs 670 kg over 10 m: a tip mass within 1e-12..1e12 times that (or 0), a
  // tip inertia up to 1e12 m L^2; SCOLE's masses alike and its offsets within 10 mast lengths.
  const std::string beam = "name: v\nbeam: {length: 10, left: clamped, right: free, rho_A: 67, EI: 23000, ";
  EXPECT_TRUE(refused(beam + "tip_mass: 1e24}\n", {"beam.tip_mass", "1e+24", "670"}));
  EXPECT_TRUE(refused(beam + "tip_mass: 1e-15}\n", {"beam.tip_mass", "1e-15"}));
  EXPECT_TRUE(refused(beam + "tip_inertia: 1e20}\n", {"beam.tip_inertia", "1e+20"}));
  EXPECT_EQ(error_of(beam + "tip_mass: 0, tip_inertia: 0}\n"), "");
  EXPECT_EQ(error_of(beam + "tip_mass: 6e14, tip_inertia: 6e16}\n"), "");
  const std::string scole = "name: v\nstructure: scole\nscole: {";
  EXPECT_TRUE(refused(scole + "reflector_rx: 1e24}\n", {"scole.reflector_rx", "1e+24", "1300"}));
  EXPECT_TRUE(refused(scole + "mast_root: [0, 0, -2000]}\n", {"scole.mast_root[2]", "-2000"}));
  EXPECT_TRUE(refused(scole + "shuttle: {mass: 1e-24, Ixx: 1, Iyy: 1, Izz: 1}}\n", {"scole.shuttle.mass", "1e-24"}));
  EXPECT_TRUE(refused(scole + "actuator_mass: 1e24}\n", {"scole.actuator_mass", "1e+24"}));
  EXPECT_TRUE(refused(scole + "reflector: {mass: 12.42, Ixx: 1e20, Iyy: 1e20, Izz: 1e20}}\n", {"scole.reflector.Ixx"}));
  // truth.overrides pass the same checks.
  EXPECT_TRUE(refused(scole + "}\ntruth: {overrides: {scole: {reflector_rx: 1e24}}}\n", {"reflector_rx", "1e+24"}));
}

TEST(Counts, OverridesGoThroughTheSameChecks) {
  Scenario s = parse_scenario(kBase, "s");
  s.truth.segments = 10000000;
  EXPECT_THROW(validate_scenario(s), InputError);
  s = parse_scenario(kBase, "s");
  s.truth.accuracy = std::nan("");
  EXPECT_THROW(validate_scenario(s), InputError);
  s.truth.accuracy = 1e-30;  // below double precision: Simbody stops at its first step
  EXPECT_THROW(validate_scenario(s), InputError);
  EXPECT_TRUE(refused(std::string(kBase) + "truth: {accuracy: 1e-20}\n", {"truth.accuracy", "1e-20"}));
  s = parse_scenario(kBase, "s");
  s.identification.max_iterations = -5;
  EXPECT_THROW(validate_scenario(s), InputError);
}

TEST(OneLine, ControlCharactersAreShownNotPrinted) {
  EXPECT_EQ(one_line("a\nb\tc\x01\n"), "a\\nb\\tc\\x01");
  EXPECT_EQ(one_line("plain"), "plain");
  // C1 controls (U+0085, a line break to many terminals) shown as \uNNNN; other text as it is.
  EXPECT_EQ(one_line("a\xC2\x85" "b\xC2\x80"), "a\\u0085b\\u0080");
  EXPECT_EQ(one_line("caf\xC3\xA9 \xC2\xA0x"), "caf\xC3\xA9 \xC2\xA0x");
  // A huge echo is cut in the middle, never inside a UTF-8 sequence; the ends stay.
  const std::string huge = "file.yaml: field runs[0].name must be at most 64 characters, got '" + std::string(1000000, 'x') +
                           std::string("\xC3\xA9", 2) + std::string(50000, 'y') + "' (end)";
  const std::string shown = one_line(huge);
  EXPECT_LT(shown.size(), 700u);
  EXPECT_EQ(shown.rfind("file.yaml: field runs[0].name", 0), 0u);
  EXPECT_EQ(shown.substr(shown.size() - 7), "' (end)");
  EXPECT_NE(shown.find("characters left out"), std::string::npos);
  std::string accent(300, 'a');
  for (int i = 0; i < 200; ++i) accent += "\xC3\xA9";  // é, two bytes each
  const std::string s = shorten(accent, 301);  // the cut falls inside an é: moved before it
  EXPECT_EQ(s.substr(0, 303), accent.substr(0, 300) + "...");
  EXPECT_EQ(s.find("\xC3..."), std::string::npos);
  EXPECT_NE(s.find("(700 characters)"), std::string::npos) << s;
  EXPECT_EQ(shorten("short"), "short");
  try {
    fail_field("f.yaml", "sensors[0].name", "must be at most 64 characters", std::string(100000, 'n'));
  } catch (const InputError& e) {
    EXPECT_LT(std::string(e.what()).size(), 250u);
    EXPECT_NE(std::string(e.what()).find("(100000 characters)"), std::string::npos);
  }
}

TEST(TruthMeta, NegativeNoiseOrTrueValuesAndDuplicateColumnsAreRefused) {
  const auto meta = [](const std::string& cols, const std::string& truth) {
    return nlohmann::json::parse(R"({"scenario": "x", "columns": [)" + cols + R"(], "true_parameters": {)" + truth + "}}");
  };
  const std::string w = R"({"name": "w", "kind": "output", "noise_std": 0.001})";
  EXPECT_NO_THROW(truth_meta_from_json(meta(w, R"("EI": 23000, "zeta": 0, "c_kv": 0)"), "truth.json"));
  try {
    truth_meta_from_json(meta(R"({"name": "w", "kind": "output", "noise_std": -1})", R"("EI": 1)"), "truth.json");
    ADD_FAILURE() << "negative noise accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("columns['w'].noise_std"), std::string::npos) << e.what();
  }
  try {
    truth_meta_from_json(meta(w, R"("EI": -23000)"), "truth.json");
    ADD_FAILURE() << "negative EI accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("true_parameters.EI"), std::string::npos) << e.what();
  }
  EXPECT_THROW(truth_meta_from_json(meta(w + "," + w, R"("EI": 1)"), "truth.json"), InputError);
}

TEST(Csv, HeaderMustBeUtf8) {
  EXPECT_THROW(read_csv_text("t,w\xFF\n0,1\n1,2\n", "x.csv"), InputError);
  EXPECT_NO_THROW(read_csv_text("t,w\n0,1\n1,2\n", "x.csv"));
}

// what() is read as a C string: a NUL inside a message (a key that holds one) would end it before
// the field and the value.
TEST(Validation, AnInputErrorShowsANulAndKeepsWhatFollows) {
  const scoleid::io::InputError e(std::string("f.yaml: a\0b is not a known field, got 'x'", 41));
  EXPECT_STREQ(e.what(), "f.yaml: a\\x00b is not a known field, got 'x'");
}
