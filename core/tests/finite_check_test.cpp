#include "core/finite_check.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace mbdae {
namespace {

// max_num and min_num stand in for std::fmax and std::fmin in the step's loops: the same value,
// NaN arguments included, for every pair of these.
TEST(FiniteCheck, MaxNumAndMinNumAreFmaxAndFmin) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = INFINITY;
  const double values[] = {0.0, 1.0, -1.0, 2.5e-300, -7e12, inf, -inf, nan};
  for (double a : values)
    for (double b : values) {
      const double mx = std::fmax(a, b), mn = std::fmin(a, b);
      if (std::isnan(mx)) EXPECT_TRUE(std::isnan(max_num(a, b)));
      else EXPECT_EQ(max_num(a, b), mx) << a << " " << b;
      if (std::isnan(mn)) EXPECT_TRUE(std::isnan(min_num(a, b)));
      else EXPECT_EQ(min_num(a, b), mn) << a << " " << b;
    }
}

TEST(FiniteCheck, FirstNonFiniteNamesTheFirstBadEntry) {
  double x[6] = {1, 2, 3, 4, 5, 6};
  EXPECT_EQ(first_non_finite(x, 6), -1);
  x[4] = -INFINITY;
  x[5] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(first_non_finite(x, 6), 4);
  x[1] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(first_non_finite(x, 6), 1);
  EXPECT_EQ(first_non_finite(x, 1), -1);
}

}  // namespace
}  // namespace mbdae
