// Pattern recording, duplicate merging and slot-table value passes.
#include <gtest/gtest.h>

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

}  // namespace
}  // namespace mbdae
