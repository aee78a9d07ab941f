// The expression language of derived sensors.
#include <gtest/gtest.h>

#include <cmath>

#include "core/expression.h"

namespace mbdae {
namespace {

int lookup(const std::string& n) { return n == "x" ? 0 : n == "y" ? 1 : n == "spin.z" ? 2 : -1; }

double eval(const std::string& e, double x = 0.3, double y = -2.0, double z = 0.5) {
  const double v[3] = {x, y, z};
  return Expression::compile(e, lookup).evaluate(v);
}

TEST(Expression, PrecedenceAndFunctions) {
  EXPECT_DOUBLE_EQ(eval("1 + 2 * 3"), 7);
  EXPECT_DOUBLE_EQ(eval("(1 + 2) * 3"), 9);
  EXPECT_DOUBLE_EQ(eval("-2 ^ 2"), -4);
  EXPECT_DOUBLE_EQ(eval("2 ^ 3 ^ 2"), 512);
  EXPECT_DOUBLE_EQ(eval("x * y - 1 / 4"), 0.3 * -2.0 - 0.25);
  EXPECT_DOUBLE_EQ(eval("asin(spin.z)"), std::asin(0.5));
  EXPECT_DOUBLE_EQ(eval("atan2(x, y) * 180 / pi"), std::atan2(0.3, -2.0) * 180 / M_PI);
  EXPECT_DOUBLE_EQ(eval("max(x, y) + min(x, y) + abs(y) + sqrt(4) + exp(0) + log(1)"), 0.3 - 2.0 + 2 + 2 + 1);
  EXPECT_DOUBLE_EQ(eval("1e-3 * 2"), 2e-3);
}

TEST(Expression, ErrorsNameThePosition) {
  auto message = [](const std::string& e) {
    try {
      Expression::compile(e, lookup);
    } catch (const ExpressionError& err) {
      return std::string(err.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("x + q").find("unknown name 'q' at position 5"), std::string::npos) << message("x + q");
  EXPECT_NE(message("foo(x)").find("unknown function 'foo'"), std::string::npos);
  EXPECT_NE(message("(x + y").find("expected ')'"), std::string::npos);
  EXPECT_NE(message("x y").find("unexpected text"), std::string::npos);
  EXPECT_NE(message("").find("unexpected end"), std::string::npos);
}

TEST(Expression, DepthBeyondTheEvaluationStackIsRefused) {
  std::string deep;
  for (int k = 0; k < 70; ++k) deep += "x+(";
  deep += "x";
  for (int k = 0; k < 70; ++k) deep += ")";
  EXPECT_THROW(Expression::compile(deep, lookup), ExpressionError);
  std::string ok;
  for (int k = 0; k < 60; ++k) ok += "x+(";
  ok += "x";
  for (int k = 0; k < 60; ++k) ok += ")";
  EXPECT_NEAR(eval(ok), 61 * 0.3, 1e-12);
}

}  // namespace
}  // namespace mbdae
