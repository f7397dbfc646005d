// io/types.h: every closed choice has one name, and the name gives the value back.
#include <gtest/gtest.h>

#include <map>
#include <set>

#include "scoleid/io/error.h"
#include "scoleid/io/scenario.h"
#include "scoleid/io/types.h"

using namespace scoleid::io;

namespace {

template <class E>
void expect_round_trip(std::size_t count) {
  const auto all = names<E>();
  EXPECT_EQ(all.size(), count);
  std::set<std::string> seen;
  for (const auto& n : all) {
    const auto v = parse<E>(n);
    ASSERT_TRUE(v.has_value()) << n;
    EXPECT_EQ(to_string(*v), n);
    EXPECT_TRUE(seen.insert(n).second) << "name given twice: " << n;
  }
  EXPECT_FALSE(parse<E>("").has_value());
  EXPECT_FALSE(parse<E>("no-such-choice").has_value());
  EXPECT_FALSE(parse<E>(all.front() + " ").has_value()) << "names are exact";
}

}  // namespace

TEST(Types, EveryNameParsesBackToItsValue) {
  expect_round_trip<Method>(5);
  expect_round_trip<Start>(3);
  expect_round_trip<Model>(2);
  expect_round_trip<StepRule>(2);
}

TEST(Types, TheNamesAreTheScenarioFileSpellings) {
  EXPECT_EQ(names_joined<Method>(), "auto|gauss-newton|gauss-newton-krylov|lbfgs|steepest-descent");
  EXPECT_EQ(names_joined<Start>(", "), "auto, plain, coarse-to-fine");
  // The scenario reader takes exactly these names and refuses any other with the list.
  const std::string head = "structure: beam\ninputs: [{name: P, location: 5}]\nsensors: [{name: w, location: 5}]\n"
                           "identification:\n  estimate: [EI]\n";
  for (const auto& n : names<Method>())
    EXPECT_EQ(to_string(parse_scenario(head + "  method: " + n + "\n", "x").identification.method), n);
  try {
    parse_scenario(head + "  method: newton\n", "scenario 'x.yaml'");
    FAIL() << "an unknown method was accepted";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("identification.method"), std::string::npos) << m;
    EXPECT_NE(m.find(names_joined<Method>()), std::string::npos) << m;
    EXPECT_NE(m.find("'newton'"), std::string::npos) << m;
  }
}

TEST(Types, EverySensorKindIsReadBySomeStructureAndRefusedByNameElsewhere) {
  // The reader takes a sensor kind only where the structure's models read it (types.h, reads);
  // elsewhere one line names the field, the kind and the structures that do read it.
  const std::map<std::string, std::string> heads = {{"beam", "structure: beam\ninputs: [{name: P, location: 5}]\n"},
                                                    {"scole", "structure: scole\ninputs: [{name: F, direction: y}]\n"}};
  for (const auto& kind : names<SensorKind>()) {
    int readers = 0;
    for (const auto& [structure, head] : heads) {
      // The kind's own fields (types.h, kSensorKinds), each with a value its rule takes.
      std::string extra;
      for (const SensorField& f : sensor_traits(*parse<SensorKind>(kind)).fields)
        if (f.name) extra += std::string(", ") + f.name + (f.rule == SensorField::Rule::Station ? ": 2" : ": 0.01");
      const std::string yaml =
          head + "sensors: [{name: s, kind: " + kind + ", location: 5, direction: y" + extra + "}]\n";
      try {
        const Scenario sc = parse_scenario(yaml, "scenario 'x.yaml'");
        EXPECT_EQ(to_string(sc.sensors.at(0).kind), kind);
        ++readers;
      } catch (const InputError& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("sensors[0].kind"), std::string::npos) << m;
        EXPECT_NE(m.find("'" + kind + "'"), std::string::npos) << m;
        EXPECT_NE(m.find("not read on a " + structure + " structure"), std::string::npos) << m;
      }
    }
    EXPECT_GE(readers, 1) << kind << " is read by no structure";
  }
}
