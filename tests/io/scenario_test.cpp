#include "common/test_data.h"
#include "scoleid/io/scenario.h"

#include <gtest/gtest.h>

#include <cmath>

#include <nlohmann/json.hpp>

#include "scoleid/io/error.h"
#include "scoleid/io/scenario_fields.h"
#include "scoleid/io/validation.h"

using namespace scoleid::io;

namespace {
std::string error_of(const std::string& yaml) { return scoleid::test::scenario_error(yaml, "scenario 'x.yaml'"); }

// The message of the InputError loading the built-in or file `name` throws; "" if it loads.
std::string load_error(const std::string& name) {
  try {
    load_scenario(name);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// Each `head + tail` is refused with exactly `message`.
void expect_errors(const std::string& head, std::initializer_list<std::pair<std::string, std::string>> cases) {
  for (const auto& [tail, message] : cases) EXPECT_EQ(error_of(head + tail), message) << tail;
}
}  // namespace

TEST(Scenario, EveryBuiltinParsesAndHasInputsAndSensors) {
  ASSERT_FALSE(builtin_scenario_names().empty());
  for (const auto& name : builtin_scenario_names()) {
    const Scenario s = load_scenario(name);
    EXPECT_EQ(s.name, name);
    EXPECT_FALSE(s.inputs.empty()) << name;
    EXPECT_FALSE(s.sensors.empty()) << name;
    EXPECT_FALSE(builtin_scenario_description(name).empty()) << name;
  }
}

TEST(Scenario, PaperBeamOneHoldsThePaperValues) {
  const Scenario s = load_scenario("paper-beam-1");
  EXPECT_EQ(s.beam.left, EndCondition::Pinned);
  EXPECT_DOUBLE_EQ(s.beam.rho_A, 67.0);
  EXPECT_DOUBLE_EQ(s.beam.EI.at(0), 23000.0);
  EXPECT_DOUBLE_EQ(s.identification.initial.at("rho_A"), 63.0);
  EXPECT_DOUBLE_EQ(s.inputs.at(0).signal(0.1), 10.0);
}

TEST(Scenario, JsonEchoRoundTripsKeyFields) {
  const Scenario s = load_scenario("paper-beam-3");
  const auto j = to_json(s);
  EXPECT_EQ(j["beam"]["EI"].size(), 2u);
  EXPECT_EQ(j["sensors"][1]["location"].get<double>(), 7.5);
}

TEST(Scenario, UnknownBuiltinNamesTheChoices) {
  const std::string e = load_error("paper-beam-9");
  EXPECT_NE(e.find("paper-beam-9"), std::string::npos) << e;
  EXPECT_NE(e.find("paper-beam-1"), std::string::npos) << e;
}

TEST(Scenario, MissingFileIsNamed) {
  const std::string e = load_error("/nonexistent/s.yaml");
  EXPECT_NE(e.find("/nonexistent/s.yaml"), std::string::npos) << e;
}

TEST(Scenario, MalformedYamlGivesLine) {
  const std::string e = error_of("beam: {length: 10\ninputs: [");
  EXPECT_NE(e.find("malformed YAML at line"), std::string::npos) << e;
}

TEST(Scenario, NegativeStiffnessNamesFieldAndValue) {
  EXPECT_EQ(error_of("beam: {EI: -3}"), "scenario 'x.yaml': beam.EI must be > 0, got -3");
  EXPECT_EQ(error_of("beam: {EI: [1, 0]}"), "scenario 'x.yaml': beam.EI[1] must be > 0, got 0");
  EXPECT_EQ(error_of("beam: {rho_A: -1}"), "scenario 'x.yaml': beam.rho_A must be > 0, got -1");
}

TEST(Scenario, ScoleDampingAndActuatorHardwareAreChecked) {
  EXPECT_EQ(error_of("structure: scole\nscole: {zeta: -0.1}"), "scenario 'x.yaml': scole.zeta must be >= 0, got -0.1");
  EXPECT_EQ(error_of("structure: scole\nscole: {actuator_stiffness: -2}"),
            "scenario 'x.yaml': scole.actuator_stiffness must be >= 0, got -2");
  EXPECT_EQ(error_of("structure: scole\nscole: {actuator_damping: -0.5}"),
            "scenario 'x.yaml': scole.actuator_damping must be >= 0, got -0.5");
  EXPECT_EQ(error_of("structure: scole\nscole: {actuator_stroke: 0}"),
            "scenario 'x.yaml': scole.actuator_stroke must be > 0, got 0");
  EXPECT_NE(error_of("structure: scole\nscole: {bending_rotary_inertia: maybe}").find("scole.bending_rotary_inertia"),
            std::string::npos);
  // The defaults: the section's rotary inertia on, free sliders.
  const Scenario sc = parse_scenario("structure: scole\n", "x");
  EXPECT_TRUE(sc.scole.bending_rotary_inertia);
  EXPECT_EQ(sc.scole.actuator_stiffness, 0.0);
  EXPECT_EQ(sc.scole.actuator_damping, 0.0);
}

TEST(Scenario, NanAndTextAreRejected) {
  EXPECT_EQ(error_of("beam: {EI: .nan}"), "scenario 'x.yaml': beam.EI must be a finite number, got '.nan'");
  EXPECT_EQ(error_of("beam: {length: ten}"), "scenario 'x.yaml': beam.length must be a decimal number, got 'ten'");
}

TEST(Scenario, UnknownFieldIsRejected) {
  EXPECT_EQ(error_of("beam: {lenght: 3}"),
            "scenario 'x.yaml': beam.lenght is not a known field (did you mean 'length'? known here: EI, attachments, c_kv, left, "
            "length, rho_A, right, supports, tip_inertia, tip_mass, zeta), got 'lenght'");
}

TEST(Scenario, SensorOutsideBeamIsRejected) {
  EXPECT_EQ(error_of("beam: {length: 10}\nsensors: [{name: a, location: 12}]"),
            "scenario 'x.yaml': sensors[0].location must lie on the beam [0, 10], got 12");
}

TEST(Scenario, BadEndConditionListsChoices) {
  EXPECT_EQ(error_of("beam: {left: hinged}"),
            "scenario 'x.yaml': beam.left must be one of pinned|clamped|free, got 'hinged'");
}

TEST(Scenario, TableSignalNeedsIncreasingTimes) {
  const std::string e = error_of(
      "inputs: [{name: f, location: 1, signal: {type: table, times: [0, 2, 1], values: [0, 1, 2]}}]");
  EXPECT_EQ(e, "scenario 'x.yaml': inputs[0].signal.times[2] must be increasing, got 1");
}

// truth.overrides: structure fields in which the truth differs from the identifier's model.
TEST(TruthOverrides, ChangeTheTruthOnlyAndAreEchoed) {
  const Scenario s = parse_scenario(R"(name: mismatch
structure: scole
scole: {reflector_rx: 18.75, actuator_locations: [40, 90]}
truth:
  segments: 10
  overrides:
    scole: {reflector_rx: 19.6875, reflector: {mass: 13.041}}
)", "scenario 'm.yaml'");
  EXPECT_DOUBLE_EQ(s.scole.reflector_rx, 18.75);  // the identifier's model
  EXPECT_DOUBLE_EQ(s.scole.reflector.mass, 12.42);
  const Scenario t = truth_scenario(s);
  EXPECT_DOUBLE_EQ(t.scole.reflector_rx, 19.6875);
  EXPECT_DOUBLE_EQ(t.scole.reflector.mass, 13.041);
  EXPECT_DOUBLE_EQ(t.scole.reflector.Ixx, s.scole.reflector.Ixx);            // untouched fields kept
  EXPECT_EQ(t.scole.actuator_locations, (std::vector<double>{40, 90}));       // not reset to L/3, 2L/3
  EXPECT_TRUE(has_truth_overrides(s));
  const nlohmann::json j = to_json(s)["truth"]["overrides"]["scole"];
  EXPECT_EQ(j, (nlohmann::json{{"reflector_rx", 19.6875}, {"reflector", {{"mass", 13.041}}}}));
  // Applied on demand: a programmatic change to the structure shows through in the truth.
  Scenario s2 = s;
  s2.scole.GJ = 1.0e7;
  EXPECT_DOUBLE_EQ(truth_scenario(s2).scole.GJ, 1.0e7);
  EXPECT_FALSE(has_truth_overrides(parse_scenario("name: plain\n", "s")));
}

TEST(TruthOverrides, UnknownFieldsOrTheOtherStructureAreRefused) {
  EXPECT_NE(error_of("name: m\nstructure: scole\ntruth: {overrides: {scole: {reflektor_rx: 1}}}\n")
                .find("truth.overrides.scole.reflektor_rx is not a known field"),
            std::string::npos);
  EXPECT_NE(error_of("name: m\nstructure: scole\ntruth: {overrides: {beam: {EI: 1}}}\n")
                .find("truth.overrides.beam must match the structure"),
            std::string::npos);
  EXPECT_NE(error_of("name: m\ntruth: {overrides: {beam: {EI: -1}}}\n").find("truth.overrides.beam.EI must be > 0, got -1"),
            std::string::npos);
  EXPECT_NE(error_of("name: m\ntruth: {overrides: {plate: {}}}\n").find("truth.overrides.plate"), std::string::npos);
}

// A SCOLE scenario with two sensors, open at truth.overrides.sensors for entries.
const std::string kSensorOverridesHead = R"(name: sensors
structure: scole
sensors:
  - {name: roll_tip, at: mast, location: 130, direction: y}
  - {name: yaw_tip, at: reflector, kind: rotation, direction: z}
truth:
  overrides:
    sensors:
)";

// truth.overrides.sensors: partial entries named after the scenario's sensors (location,
// direction, bias, drift) for the truth alone; echoed as overrides.sensors = [{name, fields that
// differ}], which alone make has_truth_overrides true.
TEST(TruthOverrides, SensorEntriesChangeTheTruthsSensorsOnlyAndAreEchoed) {
  const std::string head = scoleid::test::replaced(
      kSensorOverridesHead, "truth:\n", "  - {name: roll_mid, at: mast, location: 65, direction: y}\ntruth:\n");
  const Scenario s = parse_scenario(head + R"(      - {name: roll_tip, direction: [0, 0.99985, 0.01745], bias: 1.0e-3}
      - {name: roll_mid, location: 80, drift: -2.0e-4}
)", "scenario 'm.yaml'");
  EXPECT_EQ(s.sensors[0].direction, (std::vector<double>{0, 1, 0}));  // the identifier's sensors
  EXPECT_EQ(s.sensors[0].bias, 0.0);
  EXPECT_EQ(s.sensors[2].location, 65.0);
  const Scenario t = truth_scenario(s);
  const auto& d = t.sensors[0].direction;
  const double n = std::hypot(0.99985, 0.01745);
  EXPECT_EQ(d, (std::vector<double>{0, 0.99985 / n, 0.01745 / n}));  // normalised
  EXPECT_EQ(t.sensors[0].bias, 1.0e-3);
  EXPECT_EQ(t.sensors[0].drift, 0.0);
  EXPECT_EQ(t.sensors[2].location, 80.0);
  EXPECT_EQ(t.sensors[2].drift, -2.0e-4);
  EXPECT_EQ(t.sensors[1].direction, s.sensors[1].direction);  // untouched sensor
  EXPECT_EQ(t.scole.EI_roll, s.scole.EI_roll);
  EXPECT_TRUE(has_truth_overrides(s));
  const nlohmann::json j = to_json(s)["truth"]["overrides"];
  EXPECT_EQ(j, (nlohmann::json{{"sensors",
                                {{{"name", "roll_tip"}, {"direction", d}, {"bias", 1.0e-3}},
                                 {{"name", "roll_mid"}, {"location", 80.0}, {"drift", -2.0e-4}}}}}));
  // An entry that changes nothing is no override.
  EXPECT_FALSE(has_truth_overrides(parse_scenario(head + "      - {name: roll_mid, location: 65, bias: 0}\n", "s")));
}

TEST(TruthOverrides, SensorEntryErrorsNameTheField) {
  const std::string head = kSensorOverridesHead;
  expect_errors(
      head,
      {{"      - {name: roll_tpi, bias: 1}\n",
        "scenario 'x.yaml': truth.overrides.sensors[0].name must name a sensor of the scenario (roll_tip, yaw_tip), "
        "got 'roll_tpi'"},
       {"      - {bias: 1}\n",
        "scenario 'x.yaml': truth.overrides.sensors[0].name must name a sensor of the scenario, got none"},
       {"      - {name: roll_tip, bias: 1}\n      - {name: roll_tip, drift: 1}\n",
        "scenario 'x.yaml': truth.overrides.sensors[1].name must be unique, got 'roll_tip'"},
       {"      - {name: roll_tip, drift: .nan}\n",
        "scenario 'x.yaml': truth.overrides.sensors[0].drift must be a finite number, got '.nan'"},
       {"      - {name: roll_tip, bias: -.inf}\n",
        "scenario 'x.yaml': truth.overrides.sensors[0].bias must be a finite number, got '-.inf'"},
       {"      - {name: roll_tip, location: 131}\n",
        "scenario 'x.yaml': truth.overrides.sensors[0].location must lie on the mast [0, 130], got 131"},
       {"      - {name: roll_tip, direction: [0, 0, 0]}\n",
        "scenario 'x.yaml': truth.overrides.sensors[0].direction must be non-zero, got [0, 0, 0]"},
       {"      - {name: yaw_tip, location: 100}\n",
        "scenario 'x.yaml': truth.overrides.sensors[0].location applies to beam and mast sensors only (sensor "
        "'yaw_tip' is at reflector), got 100"},
       {"      - {name: roll_tip, noise_std: 1}\n",
        "scenario 'x.yaml': truth.overrides.sensors[0].noise_std is not a known field (known here: bias, direction, drift, "
        "location, name), got 'noise_std'"},
       {"      {name: roll_tip}\n", "scenario 'x.yaml': truth.overrides.sensors must be a list, got map"}});
  // The main section refuses them: the identifier models an ideal sensor plus noise.
  EXPECT_EQ(error_of("name: b\nsensors:\n  - {name: w, location: 5, bias: 0.001}\n"),
            "scenario 'x.yaml': sensors[0].bias is refused here: bias and drift describe the truth's sensor errors: "
            "set them under truth.overrides.sensors, got '0.001'");
  EXPECT_NE(error_of("name: b\nsensors:\n  - {name: w, location: 5, drift: 0}\n").find("sensors[0].drift is refused here"),
            std::string::npos);
  // A beam's sensors measure w or w_s: a direction would be ignored, so it is refused.
  EXPECT_EQ(error_of("name: b\nsensors:\n  - {name: w, location: 5}\ntruth:\n  overrides:\n    sensors:\n"
                     "      - {name: w, direction: y}\n"),
            "scenario 'x.yaml': truth.overrides.sensors[0].direction does not apply to a beam sensor (it measures w or "
            "w_s), got 'y'");
}

// scole.actuator_lag: seconds, >= 0 and finite, default 0; echoed; overridable for the truth.
TEST(Scenario, ActuatorLagIsParsedCheckedAndEchoed) {
  EXPECT_EQ(parse_scenario("name: d\nstructure: scole\n", "s").scole.actuator_lag, 0.0);
  const Scenario s = parse_scenario("name: l\nstructure: scole\nscole: {actuator_lag: 0.05}\n", "s");
  EXPECT_EQ(s.scole.actuator_lag, 0.05);
  EXPECT_EQ(to_json(s)["scole"]["actuator_lag"], 0.05);
  EXPECT_EQ(error_of("name: l\nstructure: scole\nscole: {actuator_lag: -0.1}\n"),
            "scenario 'x.yaml': scole.actuator_lag must be >= 0, got -0.1");
  EXPECT_EQ(error_of("name: l\nstructure: scole\nscole: {actuator_lag: .nan}\n"),
            "scenario 'x.yaml': scole.actuator_lag must be a finite number, got '.nan'");
  EXPECT_EQ(error_of("name: l\nstructure: scole\nscole: {actuator_lag: .inf}\n"),
            "scenario 'x.yaml': scole.actuator_lag must be a finite number, got '.inf'");
  const Scenario o = parse_scenario("name: o\nstructure: scole\ntruth:\n  overrides:\n    scole: {actuator_lag: 0.02}\n", "s");
  EXPECT_EQ(o.scole.actuator_lag, 0.0);
  EXPECT_EQ(truth_scenario(o).scole.actuator_lag, 0.02);
  EXPECT_EQ(to_json(o)["truth"]["overrides"], (nlohmann::json{{"scole", {{"actuator_lag", 0.02}}}}));
  EXPECT_EQ(error_of("name: o\nstructure: scole\ntruth: {overrides: {scole: {actuator_lag: -1}}}\n"),
            "scenario 'x.yaml': truth.overrides.scole.actuator_lag must be >= 0, got -1");
}

// The plausibility guards' fields (docs/truth-guards.md): scole.actuator_stroke (> 0, default
// 0.5) and truth.large_motion (a boolean, default false), parsed, checked, echoed, overridable.
TEST(Scenario, GuardFieldsAreParsedCheckedAndEchoed) {
  const Scenario d = parse_scenario("name: d\nstructure: scole\n", "s");
  EXPECT_DOUBLE_EQ(d.scole.actuator_stroke, 0.5);
  EXPECT_FALSE(d.truth.large_motion);
  const auto jd = to_json(d);
  EXPECT_EQ(jd["scole"]["actuator_stroke"], 0.5);
  EXPECT_EQ(jd["truth"]["large_motion"], false);

  const Scenario s = parse_scenario(
      "name: g\nstructure: scole\nscole: {actuator_stroke: 0.25}\ntruth: {large_motion: true}\n", "s");
  EXPECT_DOUBLE_EQ(s.scole.actuator_stroke, 0.25);
  EXPECT_TRUE(s.truth.large_motion);
  EXPECT_EQ(to_json(s)["scole"]["actuator_stroke"], 0.25);
  EXPECT_EQ(to_json(s)["truth"]["large_motion"], true);

  EXPECT_EQ(error_of("name: g\nstructure: scole\nscole: {actuator_stroke: 0}\n"),
            "scenario 'x.yaml': scole.actuator_stroke must be > 0, got 0");
  EXPECT_EQ(error_of("name: g\nstructure: scole\nscole: {actuator_stroke: -0.5}\n"),
            "scenario 'x.yaml': scole.actuator_stroke must be > 0, got -0.5");
  EXPECT_EQ(error_of("name: g\ntruth: {large_motion: yes}\n"),
            "scenario 'x.yaml': truth.large_motion must be true or false, got 'yes'");
  EXPECT_EQ(error_of("name: g\ntruth: {large_motion: [true]}\n"),
            "scenario 'x.yaml': truth.large_motion must be true or false, got a list");

  // Set for the truth alone: the identifier's scenario keeps the default, the echo names the override.
  const Scenario o = parse_scenario(
      "name: o\nstructure: scole\ntruth:\n  overrides:\n    scole: {actuator_stroke: 0.3}\n", "s");
  EXPECT_DOUBLE_EQ(o.scole.actuator_stroke, 0.5);
  EXPECT_DOUBLE_EQ(truth_scenario(o).scole.actuator_stroke, 0.3);
  EXPECT_EQ(to_json(o)["truth"]["overrides"]["scole"], (nlohmann::json{{"actuator_stroke", 0.3}}));
  EXPECT_NE(error_of("name: o\nstructure: scole\ntruth: {overrides: {scole: {actuator_stroke: -1}}}\n")
                .find("truth.overrides.scole.actuator_stroke must be > 0, got -1"),
            std::string::npos);
}

TEST(Scenario, OnlyTheSlewsAreLargeMotionStudies) {
  // scole-slew and scole-slew-case1 (the same slew, paper Case I's sensors and parameters).
  for (const auto& name : builtin_scenario_names())
    EXPECT_EQ(load_scenario(name).truth.large_motion, name.rfind("scole-slew", 0) == 0) << name;
}

// identification.uncertain: declared tolerances name a scenario quantity by path; the parsed
// values reach the spec, and a path that names nothing, a tolerance that is not > 0, or a switch
// set to the model's own setting is one line naming the field.
TEST(Scenario, UncertainToleranceNamesAQuantityOfTheScenario) {
  const std::string head = R"(structure: scole
inputs:
  - {name: F, at: reflector, kind: force, direction: x, signal: {type: step, amplitude: 1}}
sensors:
  - {name: roll_tip, at: mast, location: 130, direction: y}
identification:
  estimate: [EI]
  uncertain: )";
  const Scenario sc = parse_scenario(head + "{scole.reflector.mass: 0.6, sensors.roll_tip.location: 1.3, scole.bending_rotary_inertia: false}\n",
                                     "scenario 'x.yaml'");
  ASSERT_EQ(sc.identification.uncertain.size(), 3u);
  EXPECT_EQ(sc.identification.uncertain[0].field, "scole.reflector.mass");
  EXPECT_DOUBLE_EQ(sc.identification.uncertain[0].tolerance, 0.6);
  EXPECT_EQ(sc.identification.uncertain[1].field, "sensors.roll_tip.location");
  EXPECT_TRUE(sc.identification.uncertain[2].is_switch);
  EXPECT_FALSE(sc.identification.uncertain[2].alternative);
  Scenario copy = sc;
  ASSERT_NE(numeric_field(copy, "scole.reflector.mass"), nullptr);
  EXPECT_DOUBLE_EQ(*numeric_field(copy, "scole.reflector.mass"), 12.42);
  EXPECT_EQ(to_json(sc)["identification"]["uncertain"]["sensors.roll_tip.location"].get<double>(), 1.3);
  EXPECT_NE(error_of(head + "{scole.reflector.weight: 1}\n").find("identification.uncertain.scole.reflector.weight names no number"),
            std::string::npos);
  EXPECT_NE(error_of(head + "{sensors.nobody.location: 1}\n").find("names no number"), std::string::npos);
  expect_errors(
      head,
      {{"{scole.GJ: -1}\n", "scenario 'x.yaml': identification.uncertain.scole.GJ must be a tolerance > 0, got -1"},
       {"{scole.bending_rotary_inertia: true}\n",
        "scenario 'x.yaml': identification.uncertain.scole.bending_rotary_inertia must name the alternative to the "
        "model's setting, got true"}});
  EXPECT_NE(error_of(head + "[1, 2]\n").find("identification.uncertain must be a map"), std::string::npos);
  // An estimated quantity is refused at the door, naming the parameter that sets it (EI sets both
  // bending planes' stiffness); one the fit holds fixed is accepted.
  EXPECT_EQ(error_of(head + "{scole.EI_roll: 1e5}\n"),
            "scenario 'x.yaml': identification.uncertain.scole.EI_roll is estimated (identification.estimate names EI): a quantity is "
            "estimated or declared uncertain, not both, got 100000");
  EXPECT_NO_THROW(parse_scenario(head + "{scole.GJ: 1e5}\n", "scenario 'x.yaml'"));
  const std::string beam = R"(structure: beam
beam: {length: 0.5, rho_A: 0.6, EI: 11, attachments: [{name: shaker, location: 0.4, mass: 0.06}]}
inputs:
  - {name: F, location: 0.4, signal: {type: step, amplitude: 1}}
sensors:
  - {name: a, location: 0.45}
identification:
  estimate: [EI, attachments.shaker.mass]
  uncertain: )";
  EXPECT_NE(error_of(beam + "{beam.attachments.shaker.mass: 0.001}\n").find("is estimated (identification.estimate names attachments.shaker.mass)"),
            std::string::npos)
      << error_of(beam + "{beam.attachments.shaker.mass: 0.001}\n");
  EXPECT_NO_THROW(parse_scenario(beam + "{beam.attachments.shaker.location: 0.002, beam.rho_A: 0.01}\n", "scenario 'x.yaml'"));
}

TEST(Scenario, ModelErrorAndRestartsAreReadAndChecked) {
  const std::string head = R"(structure: beam
inputs:
  - {name: P, location: 5, signal: {type: step, amplitude: 10}}
sensors:
  - {name: w, location: 5}
identification:
  estimate: [EI]
)";
  const Scenario automatic = parse_scenario(head, "scenario 'x.yaml'");
  EXPECT_LT(automatic.identification.model_error, 0.0);  // automatic
  EXPECT_EQ(automatic.identification.restarts, 2);
  EXPECT_EQ(to_json(automatic)["identification"]["model_error"].get<std::string>(), "auto");
  const Scenario given = parse_scenario(head + "  model_error: 0.005\n  restarts: 0\n", "scenario 'x.yaml'");
  EXPECT_DOUBLE_EQ(given.identification.model_error, 0.005);
  EXPECT_EQ(given.identification.restarts, 0);
  EXPECT_DOUBLE_EQ(to_json(given)["identification"]["model_error"].get<double>(), 0.005);
  EXPECT_NE(error_of(head + "  model_error: -0.01\n").find("identification.model_error"), std::string::npos);
  EXPECT_NE(error_of(head + "  model_error: .nan\n").find("identification.model_error"), std::string::npos);
  EXPECT_NE(error_of(head + "  restarts: 11\n").find("identification.restarts"), std::string::npos);
  // The smoothness prior: off by default, a weight, or the discrepancy principle.
  EXPECT_EQ(automatic.identification.smoothness, 0.0);
  const Scenario weight = parse_scenario(head + "  smoothness: 0.01\n", "scenario 'x.yaml'");
  EXPECT_DOUBLE_EQ(weight.identification.smoothness, 0.01);
  const Scenario morozov = parse_scenario(head + "  smoothness: discrepancy\n", "scenario 'x.yaml'");
  EXPECT_LT(morozov.identification.smoothness, 0.0);
  EXPECT_EQ(to_json(morozov)["identification"]["smoothness"].get<std::string>(), "discrepancy");
  EXPECT_NE(error_of(head + "  smoothness: -1\n").find("identification.smoothness"), std::string::npos);
  EXPECT_NE(error_of(head + "  smoothness: lots\n").find("identification.smoothness"), std::string::npos);
  // How the first attempt starts: auto, plain or coarse-to-fine.
  EXPECT_EQ(automatic.identification.start, Start::Auto);
  const Scenario ladder = parse_scenario(head + "  start: coarse-to-fine\n", "scenario 'x.yaml'");
  EXPECT_EQ(ladder.identification.start, Start::CoarseToFine);
  EXPECT_EQ(to_json(ladder)["identification"]["start"].get<std::string>(), "coarse-to-fine");
  EXPECT_NE(error_of(head + "  start: random\n").find("identification.start"), std::string::npos);
  // The automatic step's rule: parameters by default, or data.
  EXPECT_EQ(automatic.identification.step_rule, StepRule::Parameters);
  const Scenario by_data = parse_scenario(head + "  step_rule: data\n", "scenario 'x.yaml'");
  EXPECT_EQ(by_data.identification.step_rule, StepRule::Data);
  EXPECT_EQ(to_json(by_data)["identification"]["step_rule"].get<std::string>(), "data");
  EXPECT_NE(error_of(head + "  step_rule: sometimes\n").find("identification.step_rule"), std::string::npos);
  // The identifier's model: linear by default; nonlinear is SCOLE's only.
  EXPECT_EQ(automatic.identification.model, Model::Linear);
  EXPECT_EQ(to_json(automatic)["identification"]["model"].get<std::string>(), "linear");
  EXPECT_NE(error_of(head + "  model: nonlinear\n").find("identification.model"), std::string::npos);
  EXPECT_NE(error_of(head + "  model: quadratic\n").find("identification.model"), std::string::npos);
  const std::string scole = R"(structure: scole
inputs:
  - {name: M, at: shuttle, kind: moment, direction: x, signal: {type: bangbang, amplitude: 100, t0: 0, width: 2}}
sensors:
  - {name: tip, at: mast, location: 130, direction: y}
identification:
  estimate: [EI]
  model: nonlinear
)";
  const Scenario nonlinear = parse_scenario(scole, "scenario 'x.yaml'");
  EXPECT_EQ(nonlinear.identification.model, Model::Nonlinear);
  EXPECT_EQ(to_json(nonlinear)["identification"]["model"].get<std::string>(), "nonlinear");
}

// Values in range that mean nothing are refused with their reason: a damping ratio above 1, a
// model error larger than the signal, tolerances every start already meets.
TEST(Scenario, MeaninglessMagnitudesAreRefusedWithTheirReason) {
  EXPECT_NE(error_of("beam: {zeta: 1.0e20}").find("beam.zeta must be at most 1: a damping ratio"), std::string::npos)
      << error_of("beam: {zeta: 1.0e20}");
  EXPECT_NE(error_of("structure: scole\nscole: {zeta: 1000}").find("scole.zeta must be at most 1"), std::string::npos);
  EXPECT_NE(error_of("identification: {model_error: 1.0e20}").find("identification.model_error must be at most 1"),
            std::string::npos);
  EXPECT_NE(error_of("identification: {gradient_tolerance: 1.0e20}").find("identification.gradient_tolerance must be below 1"),
            std::string::npos);
  EXPECT_NE(error_of("identification: {step_tolerance: 2}").find("identification.step_tolerance must be below 1"),
            std::string::npos);
  EXPECT_EQ(error_of("beam: {zeta: 1}\nidentification: {model_error: 1, gradient_tolerance: 0.5}"), "");
}

// Numbers are decimal: yaml-cpp and strtod would read 0x10 as 16.
TEST(Scenario, HexadecimalNumbersAreRefused) {
  EXPECT_EQ(error_of("identification: {elements: '0x10'}"),
            "scenario 'x.yaml': identification.elements must be a decimal number, got '0x10'");
  EXPECT_EQ(error_of("beam: {EI: 0x1p10}"), "scenario 'x.yaml': beam.EI must be a decimal number, got '0x1p10'");
  EXPECT_EQ(error_of("beam: {length: 1e400}"), "scenario 'x.yaml': beam.length must be a finite number, got '1e400'");
}

// The other structure's section would be read and ignored: refused, naming it.
TEST(Scenario, TheOtherStructuresSectionIsRefused) {
  EXPECT_EQ(error_of("structure: scole\nbeam: {length: 10}"),
            "scenario 'x.yaml': beam describes a beam, but the scenario's structure is scole (remove the section, or set "
            "structure: beam), got a beam section");
  EXPECT_NE(error_of("scole: {zeta: 0.01}").find("scole describes SCOLE, but the scenario's structure is beam"), std::string::npos);
}

// identify.json echoes the default model error as "auto"; the echo reads back.
TEST(Scenario, ModelErrorAutoIsTheDefault) {
  EXPECT_EQ(error_of("identification: {model_error: auto}"), "");
  EXPECT_LT(parse_scenario("identification: {model_error: auto}", "x").identification.model_error, 0.0);
  EXPECT_EQ(parse_scenario("identification: {model_error: 0.02}", "x").identification.model_error, 0.02);
  EXPECT_NE(error_of("identification: {model_error: automatic}").find("identification.model_error"), std::string::npos);
}

// A tolerance as large as the quantity it qualifies (that cannot be negative) is refused.
TEST(Scenario, AnUncertaintyAsLargeAsItsValueIsRefused) {
  EXPECT_EQ(error_of("beam: {length: 10}\nidentification: {uncertain: {beam.length: 1e24}}"),
            "scenario 'x.yaml': identification.uncertain.beam.length must be smaller than the value it is a tolerance of "
            "(10): a quantity known no better than that is unknown (estimate it instead), got 1e+24");
  EXPECT_EQ(error_of("beam: {length: 10}\nidentification: {uncertain: {beam.length: 0.1}}"), "");
}

TEST(Scenario, AnActuatorLagLongerThanTheRecordIsRefused) {
  EXPECT_NE(error_of("structure: scole\nsimulation: {duration: 2}\ntruth: {overrides: {scole: {actuator_lag: 1e24}}}")
                .find("truth.overrides.scole.actuator_lag must be shorter than simulation.duration (2)"),
            std::string::npos);
}

TEST(Scenario, AnUnknownBuiltinNamesNoCommandLineOption) {
  std::string msg;
  try {
    builtin_scenario_text("nope");
  } catch (const InputError& e) {
    msg = e.what();
  }
  EXPECT_EQ(msg.rfind("'nope' is not a built-in scenario (paper-beam-1", 0), 0u) << msg;
}

// A name echoed in a refusal says how long it really is.
TEST(Scenario, AHugeNameIsCountedWhole) {
  const std::string name(1000000, 'a');
  const std::string msg = error_of("sensors: [{name: " + name + ", location: 5}]");
  EXPECT_NE(msg.find("(1000000 characters)"), std::string::npos) << msg.substr(0, 300);
}

// conditioning: parsed, checked, and written back by to_json so that the echo reads back.
TEST(Scenario, ConditioningParsesChecksAndRoundTrips) {
  const std::string head = "inputs: [{name: P, location: 5, signal: {type: step, amplitude: 1}, conditioning: ";
  const std::string tail = "}]\nsensors: [{name: w, location: 5}]";
  const Scenario s = parse_scenario(head + "{offset: {mean_before: 0.1}, sign: -1, scale: 2, detrend: true}" + tail, "x");
  const auto& c = s.inputs[0].conditioning;
  EXPECT_EQ(c.offset, Conditioning::Offset::MeanBefore);
  EXPECT_EQ(c.offset_value, 0.1);
  EXPECT_EQ(c.sign, -1.0);
  EXPECT_EQ(c.scale, 2.0);
  EXPECT_TRUE(c.detrend);
  EXPECT_EQ(to_json(s)["inputs"][0]["conditioning"],
            nlohmann::json::parse(R"({"offset": {"mean_before": 0.1}, "sign": -1.0, "scale": 2.0, "detrend": true})"));
  EXPECT_FALSE(to_json(s)["sensors"][0].contains("conditioning"));
  EXPECT_EQ(parse_scenario(head + "{offset: mean}" + tail, "x").inputs[0].conditioning.offset, Conditioning::Offset::Mean);
  EXPECT_EQ(parse_scenario(head + "{offset: -23}" + tail, "x").inputs[0].conditioning.offset_value, -23.0);
  EXPECT_EQ(error_of(head + "{sign: 2}" + tail), "scenario 'x.yaml': inputs[0].conditioning.sign must be 1 or -1, got 2");
  EXPECT_NE(error_of(head + "{scale: 0}" + tail).find("inputs[0].conditioning.scale must be > 0"), std::string::npos);
  EXPECT_NE(error_of(head + "{remove_mean: true}" + tail).find("inputs[0].conditioning.remove_mean is not a known field"),
            std::string::npos);
  EXPECT_NE(error_of(head + "{offset: {median: 1}}" + tail).find("inputs[0].conditioning.offset as a map must be {mean_before: T}"),
            std::string::npos);
}

// A data section that states only the time column leaves the sample rate unstated (0), and a
// stated rate must be positive.
TEST(Scenario, DataSectionWithoutSampleRateLeavesItUnstated) {
  const std::string base = "name: s\nstructure: beam\nbeam: {length: 1, EI: 1, rho_A: 1}\n"
                           "sensors: [{name: a, at: beam, kind: displacement, location: 1}]\n";
  const Scenario sc = parse_scenario(base + "data: {time_column: \"Time [ms]\"}\n", "s.yaml");
  EXPECT_EQ(sc.data.time_column, "Time [ms]");
  EXPECT_EQ(sc.data.sample_rate, 0.0);
  EXPECT_EQ(parse_scenario(base + "data: {sample_rate: 2048}\n", "s.yaml").data.sample_rate, 2048.0);
  try {
    parse_scenario(base + "data: {sample_rate: -1}\n", "s.yaml");
    FAIL() << "a negative rate was taken";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("data.sample_rate"), std::string::npos) << e.what();
  }
}

// What each structure's models read is checked once, by the kind's own check in validate_scenario
// (parse_scenario's last step, and every program after its command-line overrides): a site,
// direction or setting the models cannot read is one line naming the field, before any model.
TEST(Scenario, EachKindRefusesSitesAndSettingsItsModelsDoNotRead) {
  const std::string beam = "name: b\nbeam: {length: 2, EI: [1], rho_A: 1}\ninputs: [{at: beam, location: 1}]\n";
  expect_errors(beam, {
      {"sensors: [{at: mast, location: 1}]\n", "scenario 'x.yaml': sensors[0].at must be 'beam' for a beam structure, got 'mast'"},
      {"sensors: [{location: 2.5}]\n", "scenario 'x.yaml': sensors[0].location must lie on the beam [0, 2], got 2.5"},
  });
  EXPECT_NE(error_of(beam + "sensors: [{location: 1, kind: line_of_sight}]\n")
                .find("sensors[0].kind is not read on a beam structure"),
            std::string::npos);
  expect_errors("name: b\nbeam: {length: 2, EI: [1], rho_A: 1, left: clamped, right: clamped}\ninputs: [{location: 1}]\n"
                "sensors: [{location: 1}]\n",
                {{"identification: {elements: 1}\n",
                  "scenario 'x.yaml': identification.elements must be >= 2 for a beam clamped at both ends (one element "
                  "leaves no free degree of freedom), got 1"}});
  const std::string scole = "name: s\nstructure: scole\n";
  expect_errors(scole, {
      {"inputs: [{at: beam, direction: x}]\nsensors: [{at: reflector, direction: x}]\n",
       "scenario 'x.yaml': inputs[0].at must be shuttle, reflector, mast, actuator1 or actuator2 for a scole structure, got 'beam'"},
      {"inputs: [{at: reflector}]\nsensors: [{at: reflector, direction: x}]\n",
       "scenario 'x.yaml': inputs[0].direction must be given (x, y, z or a 3-vector), got none"},
      {"inputs: [{at: actuator1, direction: z}]\nsensors: [{at: reflector, direction: x}]\n",
       "scenario 'x.yaml': inputs[0].direction must lie in the actuator plane (x, y), got [0, 0, 1]"},
      {"inputs: [{at: actuator1, kind: moment, direction: x}]\nsensors: [{at: reflector, direction: x}]\n",
       "scenario 'x.yaml': inputs[0].kind must be 'force' for a proof-mass actuator, got 'moment'"},
      {"inputs: [{at: reflector, direction: x}]\nsensors: [{at: mast, location: 0, kind: line_of_sight, direction: x}]\n",
       "scenario 'x.yaml': sensors[0].location must be > 0 for a line of sight (the line starts at the root), got 0"},
      {"inputs: [{at: reflector, direction: x}]\nsensors: [{at: shuttle, kind: line_of_sight, direction: x}]\n",
       "scenario 'x.yaml': sensors[0].kind is defined for the mast and the reflector, not the shuttle, got 'line_of_sight'"},
      {"inputs: [{at: reflector, direction: x}]\nsensors: [{at: reflector, direction: x}]\nidentification: {sections: 2}\n",
       "scenario 'x.yaml': identification.sections must be 0 or 1 for a scole structure (uniform mast), got 2"},
  });
  // After a program's override, the same checks (validate_scenario), e.g. --model nonlinear.
  Scenario b = parse_scenario(beam + "sensors: [{location: 1}]\n", "b.yaml");
  b.identification.model = Model::Nonlinear;
  try {
    validate_scenario(b);
    ADD_FAILURE() << "a nonlinear beam was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "b.yaml: identification.model 'nonlinear' is a SCOLE model (structure: scole), got 'nonlinear'");
  }
  Scenario f = load_scenario("frame-4storey");
  f.sensors[0].at = Site::Beam;
  EXPECT_THROW(validate_scenario(f), InputError);
  f = load_scenario("frame-4storey");
  f.identification.sections = 2;
  EXPECT_THROW(validate_scenario(f), InputError);
}
