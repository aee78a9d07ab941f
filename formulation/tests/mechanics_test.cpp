#include "formulation/mechanics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "core/finite_check.h"

namespace mbdae {
namespace {

// max_abs runs four maxima at once: the largest |x| for every length (the tail after the blocks of
// four included) and every position of the largest entry, NaN entries skipped as max_num skips
// them, the same value as one running max_num.
TEST(Mechanics, MaxAbsIsTheRunningMaxNumForEveryLengthAndPosition) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (int n = 0; n <= 13; ++n)
    for (int big = 0; big < std::max(n, 1); ++big)
      for (double bad : {0.0, nan}) {
        std::vector<double> x(n);
        for (int i = 0; i < n; ++i) x[i] = (i % 3 - 1) * (0.5 + i);  // both signs, and zeros
        if (n > 0) x[big] = -1e300;
        if (n > 1 && bad != 0.0) x[(big + 1) % n] = bad;
        double expected = 0;
        for (double v : x) expected = max_num(expected, std::fabs(v));
        EXPECT_EQ(max_abs(x.data(), n), expected) << "n " << n << " largest at " << big;
        if (n > 0) {
          EXPECT_EQ(max_abs(x.data(), n), 1e300);
        }
      }
  const double inf[] = {1, -INFINITY, 2, 3, 4};
  EXPECT_EQ(max_abs(inf, 5), INFINITY);
}

// first_non_finite sums x * 0 in blocks of four before it looks for the entry: every length, every
// position, each kind of bad value, and finite values at the ends of the range, which must not
// count.
TEST(Mechanics, FirstNonFiniteFindsEveryBadEntryAndNoFiniteOne) {
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
