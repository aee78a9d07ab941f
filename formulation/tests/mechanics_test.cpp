#include "formulation/mechanics.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "core/finite_check.h"  // max_num

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

}  // namespace
}  // namespace mbdae
