// Pattern recording, duplicate merging and slot-table value passes.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "core/klu_solver.h"
#include "core/sparse_assembler.h"

namespace mbdae {
namespace {

void fill(SparseAssembler& a, double s) {
  a.add(0, 0, 4 * s);
  a.add(2, 1, 1 * s);
  a.add(1, 1, 3 * s);
  a.add(0, 0, 1 * s);  // duplicate: summed
  a.add(2, 2, 2 * s);
  a.add(0, 2, -1 * s);
  a.add(1, 0, 0.0);    // structural entry with a zero value
}

TEST(SparseAssembler, PatternValuesAndSolve) {
  SparseAssembler a;
  a.begin_pattern(3, 3);
  fill(a, 1.0);
  a.finalize();
  const CscPattern& p = a.pattern();
  EXPECT_EQ(p.nnz(), 6);
  EXPECT_EQ(p.colptr, (std::vector<int>{0, 2, 4, 6}));
  EXPECT_EQ(p.rowind, (std::vector<int>{0, 1, 1, 2, 0, 2}));
  std::vector<double> v(p.nnz());
  a.begin_values(v.data());
  fill(a, 2.0);
  EXPECT_TRUE(a.complete());
  EXPECT_EQ(v, (std::vector<double>{10, 0, 6, 2, -2, 4}));
  // A = [10 0 -2; 0 6 0; 0 2 4]; solve A x = A * (1, 2, 3).
  const double x_true[3] = {1, 2, 3};
  double b[3];
  csc_multiply(p, v.data(), x_true, b);
  KluSolver klu;
  ASSERT_TRUE(klu.analyze(p));
  ASSERT_TRUE(klu.factor(v.data()));
  ASSERT_TRUE(klu.solve(b));
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(b[i], x_true[i], 1e-14);
  // A second numeric factorization reuses the pivot order.
  a.begin_values(v.data());
  fill(a, 3.0);
  ASSERT_TRUE(klu.factor(v.data()));
  EXPECT_EQ(klu.factorizations(), 2);
  EXPECT_EQ(klu.full_factorizations(), 1);
}

// A value pass that does not repeat the recorded calls (a bug of the assembling code) is found
// on every build type, not only by an assert: an extra call, a call at another entry or a
// missing call writes nothing out of place, and end_values() says which call differs.
TEST(SparseAssembler, ValuePassMustRepeatThePattern) {
  SparseAssembler a;
  a.begin_pattern(3, 3);
  fill(a, 1.0);
  a.finalize();
  // Guard values around the 6 entries: an out-of-bounds write would change them.
  std::vector<double> buffer(8, -7.0);
  double* v = buffer.data() + 1;
  a.begin_values(v);
  fill(a, 1.0);
  a.add(2, 2, 100.0);  // one call too many
  EXPECT_FALSE(a.complete());
  EXPECT_EQ(buffer.front(), -7.0);
  EXPECT_EQ(buffer.back(), -7.0);
  try {
    a.end_values();
    ADD_FAILURE() << "no error for an extra call";
  } catch (const std::logic_error& e) {
    EXPECT_NE(std::string(e.what()).find("add() call 8 of the value pass is at (2, 2), beyond the 7 recorded calls"),
              std::string::npos) << e.what();
  }
  // The same number of calls, one at another entry.
  a.begin_values(v);
  a.add(0, 0, 1.0);
  a.add(2, 0, 1.0);  // recorded: (2, 1)
  EXPECT_THROW(a.end_values(), std::logic_error);
  try {
    a.end_values();
  } catch (const std::logic_error& e) {
    EXPECT_NE(std::string(e.what()).find("add() call 2 of the value pass is at (2, 0), the recorded pattern has (2, 1) there"),
              std::string::npos) << e.what();
  }
  // Too few calls.
  a.begin_values(v);
  a.add(0, 0, 1.0);
  EXPECT_THROW(a.end_values(), std::logic_error);
  // A repeated pass is fine again.
  a.begin_values(v);
  fill(a, 1.0);
  EXPECT_NO_THROW(a.end_values());
  EXPECT_TRUE(a.complete());
  EXPECT_EQ(buffer.front(), -7.0);
  EXPECT_EQ(buffer.back(), -7.0);
}

}  // namespace
}  // namespace mbdae
