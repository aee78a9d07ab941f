#include "core/finite_check.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

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

// first_non_finite sums x * 0 in blocks of four before it looks for the entry: every length, every
// position, each kind of bad value, and finite values at the ends of the range, which must not
// count.
TEST(FiniteCheck, FirstNonFiniteFindsEveryBadEntryAndNoFiniteOne) {
  const double bad[] = {std::numeric_limits<double>::quiet_NaN(), INFINITY, -INFINITY};
  for (int n = 0; n <= 13; ++n) {
    std::vector<double> x(n);
    for (int i = 0; i < n; ++i) x[i] = i % 2 ? std::numeric_limits<double>::max() : -4.9e-324;
    EXPECT_EQ(first_non_finite(x.data(), n), -1) << n;
    for (int at = 0; at < n; ++at)
      for (double b : bad) {
        std::vector<double> y = x;
        y[at] = b;
        if (at + 2 < n) y[at + 2] = b;  // a later one is not the first
        EXPECT_EQ(first_non_finite(y.data(), n), at) << "n " << n << " at " << at << " " << b;
      }
  }
}

}  // namespace
}  // namespace mbdae
