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

namespace mbdae {
namespace {

std::string compile_error(const std::string& e) {
  try {
    Expression::compile(e, lookup);
  } catch (const ExpressionError& err) {
    return err.what();
  }
  return "no error";
}

// Reproductions of issue 14: these overflowed the C++ stack of the recursive parser.
TEST(Expression, DeepNestingIsAnErrorNotACrash) {
  const std::string parens = std::string(20000, '(') + "x" + std::string(20000, ')');
  EXPECT_NE(compile_error(parens).find("nested too deeply (more than 200"), std::string::npos)
      << compile_error(parens).substr(0, 200);
  const std::string minus = std::string(500000, '-') + "x";
  EXPECT_NE(compile_error(minus).find("nested too deeply"), std::string::npos);
  const std::string calls = [] {
    std::string s;
    for (int k = 0; k < 5000; ++k) s += "sin(";
    return s + "x" + std::string(5000, ')');
  }();
  EXPECT_NE(compile_error(calls).find("nested too deeply"), std::string::npos);
  // The message shows a shortened source, not 20000 characters.
  EXPECT_LT(compile_error(parens).size(), 300u);
  // 200 levels are accepted (signs do not use evaluation stack slots).
  EXPECT_DOUBLE_EQ(eval(std::string(200, '-') + "x"), 0.3);
  EXPECT_NE(compile_error(std::string(201, '-') + "x").find("nested too deeply"), std::string::npos);
}

TEST(Expression, ReservedNames) {
  for (const char* n : {"pi", "t", "sin", "atan2", "max", "log"}) EXPECT_TRUE(Expression::is_reserved(n)) << n;
  for (const char* n : {"x", "pi2", "time", "theta", "e"}) EXPECT_FALSE(Expression::is_reserved(n)) << n;
  EXPECT_NE(Expression::reserved_list().find("pi, t, sin"), std::string::npos);
}

TEST(Expression, VariablesAreListedOnce) {
  const Expression e = Expression::compile("spin.z * x + x / spin.z - 2", lookup);
  EXPECT_EQ(e.variables, (std::vector<int>{0, 2}));
}

// The forward-mode derivative against a central difference (step 1e-6, error ~1e-10) and, for a
// few, against the derivative written out by hand.
TEST(Expression, GradientMatchesFiniteDifferences) {
  const char* cases[] = {"x * y - 1 / 4 + x ^ 2", "sin(x) * cos(y) + tan(x)", "asin(x) + acos(spin.z) + atan(y)",
                         "atan2(x, y) * 180 / pi", "sqrt(spin.z) + exp(x * y) - log(spin.z)",
                         "x ^ y + spin.z ^ 3", "abs(y) * max(x, y) + min(x, spin.z)", "-(x - y) / (x + spin.z) ^ 2",
                         "2 ^ x", "(x * x) ^ 0.5"};
  const double v[3] = {0.3, -2.0, 0.5};
  for (const char* c : cases) {
    const Expression e = Expression::compile(c, lookup);
    double g[3] = {0, 0, 0};
    EXPECT_DOUBLE_EQ(e.gradient(v, g), e.evaluate(v)) << c;
    for (int k = 0; k < 3; ++k) {
      double p[3] = {v[0], v[1], v[2]}, m[3] = {v[0], v[1], v[2]};
      const double h = 1e-6;
      p[k] += h;
      m[k] -= h;
      const double fd = (e.evaluate(p) - e.evaluate(m)) / (2 * h);
      EXPECT_NEAR(g[k], fd, 1e-7 * (1 + std::fabs(fd))) << c << " d/dvar " << k;
    }
  }
  // A motor law T0 (1 - w / w0): dT/dw = -T0 / w0 exactly.
  auto motor = [](const std::string& n) { return n == "w" ? 0 : n == "T0" ? 1 : n == "w0" ? 2 : -1; };
  const Expression m = Expression::compile("T0 * (1 - w / w0)", motor);
  const double mv[3] = {40.0, 2.5, 100.0};
  double mg[3] = {0, 0, 0};
  EXPECT_DOUBLE_EQ(m.gradient(mv, mg), 2.5 * 0.6);
  EXPECT_DOUBLE_EQ(mg[0], -2.5 / 100.0);
  EXPECT_DOUBLE_EQ(mg[1], 0.6);
  EXPECT_DOUBLE_EQ(mg[2], 2.5 * 40.0 / (100.0 * 100.0));
  // Gradients accumulate into the caller's array.
  double acc[3] = {1, 1, 1};
  Expression::compile("3 * x", lookup).gradient(v, acc);
  EXPECT_DOUBLE_EQ(acc[0], 4);
  EXPECT_DOUBLE_EQ(acc[1], 1);
}

}  // namespace
}  // namespace mbdae
