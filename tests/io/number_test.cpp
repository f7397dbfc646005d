// Numbers as written in files (io/number.h): decimal only. strtod would read "0x10" as 16 and
// "0x1p-10" as 0.0009765625; here they are not numbers.
#include "scoleid/io/number.h"

#include <gtest/gtest.h>

#include <cmath>

using scoleid::io::parse_decimal;

TEST(Number, DecimalFormsAreReadExactlyAsStrtodReadsThem) {
  for (const char* s : {"0", "-0", "1", "+1", "-2.5", ".5", "5.", "1e3", "1E-3", "-1.25e+2", "6.02214076e23", "0.1"}) {
    double v = NAN;
    EXPECT_TRUE(parse_decimal(s, v)) << s;
    EXPECT_EQ(v, std::strtod(s, nullptr)) << s;
  }
}

TEST(Number, HexInfNanBlanksAndFragmentsAreNotNumbers) {
  for (const char* s : {"0x10", "0X1A", "0x1p-10", "1p3", "inf", "-inf", "nan", "infinity", " 1", "1 ", "1e", "e3", ".", "-",
                        "+", "", "1.2.3", "1e3.5", "--1", "+-1", "1,5", "12abc", "0o17", "1_000"}) {
    double v = 42.0;
    EXPECT_FALSE(parse_decimal(s, v)) << "'" << s << "'";
  }
}

TEST(Number, BeyondDoublesRangeReadsAsInfinityOrZero) {
  double v = 0;
  EXPECT_TRUE(parse_decimal("1e400", v));
  EXPECT_TRUE(std::isinf(v) && v > 0);
  EXPECT_TRUE(parse_decimal("-1e400", v));
  EXPECT_TRUE(std::isinf(v) && v < 0);
  EXPECT_TRUE(parse_decimal("1e-400", v));
  EXPECT_EQ(v, 0.0);
}
