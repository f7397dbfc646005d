#include "scoleid/io/units.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

using namespace scoleid::io::units;

namespace {
double scale(const std::string& from, const std::string& to, Quantity q) { return conversion(from, to, q).scale; }
}  // namespace

// The factors UDUNITS-2 gives, against the units' definitions: the international inch and foot
// (1959), standard gravity (CGPM 1901), the pound-force (0.45359237 kg x standard gravity).
TEST(Units, ConversionsAreTheDefinitions) {
  EXPECT_NEAR(scale("g", "m/s^2", Quantity::Acceleration), 9.80665, 1e-14 * 9.80665);
  EXPECT_NEAR(scale("g", "ft/s^2", Quantity::Acceleration), 9.80665 / 0.3048, 1e-14 * 32.2);
  EXPECT_NEAR(scale("mm", "m", Quantity::Length), 1e-3, 1e-18);
  EXPECT_NEAR(scale("in", "m", Quantity::Length), 0.0254, 1e-17);
  EXPECT_NEAR(scale("ft", "m", Quantity::Length), 0.3048, 1e-16);
  EXPECT_NEAR(scale("in", "ft", Quantity::Length), 1.0 / 12.0, 1e-16);
  EXPECT_NEAR(scale("lbf", "N", Quantity::Force), 0.45359237 * 9.80665, 1e-14 * 4.45);
  EXPECT_NEAR(scale("lb", "N", Quantity::Force), 0.45359237 * 9.80665, 1e-14 * 4.45);  // a force's lb is lbf
  EXPECT_NEAR(scale("lb ft", "N m", Quantity::Moment), 0.45359237 * 9.80665 * 0.3048, 1e-14 * 1.36);
  EXPECT_NEAR(scale("deg", "rad", Quantity::Angle), M_PI / 180.0, 1e-17);
  EXPECT_NEAR(scale("µε", "1", Quantity::Strain), 1e-6, 1e-21);
  EXPECT_NEAR(scale("ue", "1", Quantity::Strain), 1e-6, 1e-21);
  EXPECT_NEAR(scale("ms", "s", Quantity::Time), 1e-3, 1e-18);
  EXPECT_NEAR(1.0 / conversion("N", "lbf", Quantity::Force).scale, 4.4482216152605, 1e-12);
  // The slug as UDUNITS-2 defines it: 14.5939 kg, its database's rounding of lbf s^2/ft
  // (14.5939029 kg), so that a slug ft/s^2 is 2e-7 short of a pound-force there. No sensor or input
  // quantity is a mass: no data column is converted through it (docs/data.md §3).
  EXPECT_NEAR(scale("slug ft/s^2", "N", Quantity::Force), 14.5939 * 0.3048, 1e-12);
  EXPECT_NEAR(scale("slug ft/s^2", "lbf", Quantity::Force), 14.5939 / 14.593902937206362, 1e-12);
  EXPECT_TRUE(conversion("ft/s^2", "ft/s2", Quantity::Acceleration).identity());
  EXPECT_TRUE(conversion("lb ft", "lbf.ft", Quantity::Moment).identity());
  EXPECT_DOUBLE_EQ(conversion("g", "m/s^2", Quantity::Acceleration).apply(2.0), 2.0 * 9.80665);
}

TEST(Units, WrongDimensionsAndUnknownUnitsAreRefusedWithBothNamed) {
  try {
    conversion("g", "N", Quantity::Force);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "'g' is not a unit of force");  // a force's g is the gram
  }
  try {
    conversion("furlongs per fortnightly", "m", Quantity::Length);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "'furlongs per fortnightly' is not a unit UDUNITS-2 knows");
  }
  EXPECT_EQ(*problem_with("m", Quantity::Acceleration), "'m' is not a unit of acceleration");
  EXPECT_FALSE(problem_with("mm", Quantity::Length));
  EXPECT_FALSE(problem_with("rad", Quantity::Angle));
  EXPECT_TRUE(problem_with("m/s", Quantity::Angle));
}

TEST(Units, SystemsGiveEachQuantityItsUnit) {
  EXPECT_EQ(system_unit(System::SI, Quantity::Acceleration), "m/s^2");
  EXPECT_EQ(system_unit(System::SlugFtS, Quantity::Moment), "lbf.ft");
  EXPECT_EQ(system_unit(System::None, Quantity::Length), "");
  for (auto s : {System::SI, System::SlugFtS})
    for (auto q : {Quantity::Length, Quantity::Angle, Quantity::Velocity, Quantity::Acceleration, Quantity::Strain,
                   Quantity::Force, Quantity::Moment, Quantity::Time})
      EXPECT_FALSE(problem_with(system_unit(s, q), q)) << system_name(s) << " " << quantity_name(q);
  EXPECT_EQ(parse_system("slug-ft-s"), System::SlugFtS);
  EXPECT_FALSE(parse_system("cgs"));
  EXPECT_EQ(quantity_of_kind("acceleration"), Quantity::Acceleration);
  EXPECT_EQ(quantity_of_kind("line_of_sight"), Quantity::Angle);
  EXPECT_FALSE(quantity_of_kind("temperature"));
}

TEST(Units, HeaderSuffixes) {
  EXPECT_EQ(bracketed_unit("Acc1 @0.30m [g]"), "g");
  EXPECT_EQ(bracketed_unit("Time [ s ]  "), "s");
  EXPECT_EQ(bracketed_unit("Time (ms)"), "ms");
  EXPECT_EQ(bracketed_unit("Acc (tip)"), "");  // parentheses hold a unit only when it is one
  EXPECT_EQ(bracketed_unit("Acc1"), "");
  EXPECT_EQ(bracketed_unit("]"), "");
  EXPECT_EQ(bracketed_unit(""), "");
}

// UDUNITS-2 calls reciprocals convertible (Hz and s); numbers alone parse as dimensionless factors,
// which an angle would accept. Neither is a unit of the quantity.
TEST(Units, ReciprocalsAndBareNumbersAreNoUnits) {
  EXPECT_EQ(*problem_with("Hz", Quantity::Time), "'Hz' is not a unit of time");
  EXPECT_EQ(*problem_with("s/m", Quantity::Velocity), "'s/m' is not a unit of velocity");
  EXPECT_THROW(conversion("1/m", "m", Quantity::Length), std::invalid_argument);
  EXPECT_EQ(*problem_with("2", Quantity::Angle), "'2' is not a unit UDUNITS-2 knows");
  EXPECT_FALSE(problem_with("1", Quantity::Strain));
  EXPECT_FALSE(problem_with("%", Quantity::Strain));
  // Parentheses hold a unit when it is one through the aliases too; a number is none.
  EXPECT_EQ(bracketed_unit("Rot (deg)"), "deg");
  EXPECT_EQ(bracketed_unit("Strain (µε)"), "µε");
  EXPECT_EQ(bracketed_unit("Gyro (2)"), "");
}
