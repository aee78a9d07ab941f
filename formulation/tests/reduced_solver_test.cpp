// The reduced Newton solve (core/reduced_linear_solver.h) on real Newton matrices of the index-3
// formulation: its solution equals a direct KLU solve of the full matrix, and is as accurate
// against a long double solution (within 2x of KLU's error, or 1e-12), and
// problems without kinematic rows (GGL, whose rows q' - v carry the mu columns) get the full
// solver.
#include <gtest/gtest.h>

#include <nvector/nvector_serial.h>
#include <sunmatrix/sunmatrix_sparse.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "core/ida_driver.h"
#include "core/klu_solver.h"
#include "core/reduced_linear_solver.h"
#include "cases/scene/scene.h"
#include "core/sundials_compat.h"
#include "formulation/ggl_dae.h"
#include "formulation/index1_dae.h"
#include "formulation/index3_dae.h"
#include "formulation/mechanics.h"
#include "formulation/system.h"
#include "formulation/tests/integrate_model.h"
#include "formulation/tests/test_models.h"

namespace mbdae {
namespace {

// A pendulum (one constraint set, 7 coordinates) and the five-point suspension (49 coordinates,
// 47 constraint rows, as in its dynamics scenes).
std::vector<Model> models() {
  const std::string dir = std::string(MBDAE_SOURCE_DIR) + "/cases/five_point_suspension/";
  return {testing::pendulum(2.0, 0.5, 0.1, 0.3), load_scene(dir + "dynamics_poster.yaml").model};
}

// A CSC SUNSparseMatrix with the DAE's pattern and its Newton matrix at cj.
SUNMatrix newton_matrix(DaeProblem& dae, double cj, const std::vector<double>& y,
                        const std::vector<double>& yp, SUNContext ctx) {
  const CscPattern& p = dae.jacobian_pattern();
  SUNMatrix a = SUNSparseMatrix(p.rows, p.cols, p.nnz(), CSC_MAT, ctx);
  std::copy(p.colptr.begin(), p.colptr.end(), SUNSparseMatrix_IndexPointers(a));
  std::copy(p.rowind.begin(), p.rowind.end(), SUNSparseMatrix_IndexValues(a));
  dae.jacobian(0.3, cj, y.data(), yp.data(), SUNSparseMatrix_Data(a));
  return a;
}

// max |x - x_ref| / max |x_ref|.
double relative_difference(const double* x, const double* x_ref, int n) {
  double diff = 0, size = 0;
  for (int i = 0; i < n; ++i) {
    diff = std::max(diff, std::fabs(x[i] - x_ref[i]));
    size = std::max(size, std::fabs(x_ref[i]));
  }
  return diff / size;
}

// The solution of a x = b by dense LU with full pivoting in long double (64-bit mantissa): an
// independent reference, 2^11 times finer than double.
std::vector<double> long_double_solution(const SUNMatrix a, const CscPattern& p, const double* b) {
  using MatrixL = Eigen::Matrix<long double, Eigen::Dynamic, Eigen::Dynamic>;
  using VectorL = Eigen::Matrix<long double, Eigen::Dynamic, 1>;
  const int n = p.rows;
  MatrixL dense = MatrixL::Zero(n, n);
  const double* values = SUNSparseMatrix_Data(a);
  VectorL rhs(n);
  for (int c = 0; c < n; ++c) {
    for (int k = p.colptr[c]; k < p.colptr[c + 1]; ++k) dense(p.rowind[k], c) += values[k];
    rhs[c] = b[c];
  }
  const VectorL x = dense.fullPivLu().solve(rhs);
  return std::vector<double>(x.data(), x.data() + n);
}

// At steps h of 1e-6 to 3e-2 s (cj 37 to 1e6): the reduced solve against KLU on the full
// matrix, and its error against the long double solution beyond max(1e-12, 2 x KLU's error).
// At cj = 1 (a 1 s step, about the pendulum's period, far beyond any step IDA takes on these
// models) it is 9.5e-13 from KLU on the suspension (KLU's own error 1.4e-14): checked to 1e-11
// separately.
struct Differences {
  double to_full_klu = 0, excess = 0;
  double to_full_klu_unit_cj = 0;
};

// The reduced solve against KLU on the full matrix and against the long double solution, at
// several cj (steps from 1 s to 1e-6 s), for a random state and right side; the worst over cj.
Differences compare(DaeProblem& dae, const System& sys, unsigned seed) {
  SUNContext ctx = make_sun_context();
  const CscPattern& p = dae.jacobian_pattern();
  const int n = dae.size();
  SUNLinearSolver ls = make_newton_linear_solver(p, dae.kinematic_rows(), ctx);
  EXPECT_TRUE(is_reduced_linear_solver(ls));
  std::vector<double> y, yp;
  testing::dae_vectors(testing::random_state(sys, seed), n, false, y, yp);
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  N_Vector b = N_VNew_Serial(n, ctx), x = N_VNew_Serial(n, ctx);
  double* bd = N_VGetArrayPointer(b);
  double* xd = N_VGetArrayPointer(x);
  Differences out;
  for (double cj : {1.0, 37.0, 1e3, 1e5, 1e6}) {
    SUNMatrix a = newton_matrix(dae, cj, y, yp, ctx);
    for (int i = 0; i < n; ++i) bd[i] = u(gen);
    KluSolver full;
    full.analyze(p);
    EXPECT_TRUE(full.factor(SUNSparseMatrix_Data(a))) << "cj " << cj;
    std::vector<double> klu(bd, bd + n);
    EXPECT_TRUE(full.solve(klu.data()));
    const std::vector<double> exact = long_double_solution(a, p, bd);
    EXPECT_EQ(SUNLinSolSetup(ls, a), kLinSolSuccess) << "cj " << cj;
    EXPECT_EQ(SUNLinSolSolve(ls, a, x, b, 0.0), kLinSolSuccess);
    if (cj == 1.0) {
      out.to_full_klu_unit_cj = relative_difference(xd, klu.data(), n);
    } else {
      out.to_full_klu = std::max(out.to_full_klu, relative_difference(xd, klu.data(), n));
      const double bound = std::max(1e-12, 2 * relative_difference(klu.data(), exact.data(), n));
      out.excess = std::max(out.excess, relative_difference(xd, exact.data(), n) / bound);
    }
    // In place (x aliasing b): the same solution.
    EXPECT_EQ(SUNLinSolSolve(ls, a, b, b, 0.0), kLinSolSuccess);
    EXPECT_EQ(relative_difference(bd, xd, n), 0.0) << "cj " << cj;
    SUNMatDestroy(a);
  }
  EXPECT_GE(newton_linear_solver_fresh_factorizations(ls), 1);
  N_VDestroy(b);
  N_VDestroy(x);
  SUNLinSolFree(ls);
  SUNContext_Free(&ctx);
  return out;
}

void expect_equal_to_full_klu(DaeProblem& dae, const System& sys, const std::string& name) {
  const Differences d = compare(dae, sys, 5);
  EXPECT_LT(d.to_full_klu, 1e-12) << name;
  EXPECT_LE(d.excess, 1.0) << name;
  EXPECT_LT(d.to_full_klu_unit_cj, 1e-11) << name;
  ::testing::Test::RecordProperty("difference_to_full_klu_" + name, testing::sci(d.to_full_klu));
}

TEST(ReducedSolver, Index3EqualsFullKlu) {
  for (const Model& m : models()) {
    const System sys = build_system(m);
    Index3Dae dae(sys, 7.0);
    ASSERT_EQ(dae.kinematic_rows(), sys.nq());
    expect_equal_to_full_klu(dae, sys, m.name);
  }
}

// The pendulum of formulations_test through integrate() with and without the reduced solve.
// Index 3 does not control the velocities, so its period error is noise that jumps by 10x
// between neighbouring rtol (7.3e-7 at 1e-8, 5.2e-6 at 3e-9 with the full solver): the runs are
// compared over six rtol, by the geometric mean of the period error against the elliptic
// integral (measured 3.3e-7 full, 4.5e-7 reduced) and the total steps (22424, 22596).
testing::RunResult integrate_pendulum(bool reduced_newton, double rtol) {
  const System sys = build_system(testing::pendulum(2.0, 0.5, 0.05, 1.0));
  Index3Dae dae(sys, 2.0 / (1e-3 * 1e-3));
  IdaOptions o;
  o.t1 = 8.0;
  o.output_step = 1e-3;
  o.rtol = rtol;
  o.atol = 1e-2 * rtol;
  o.reduced_newton = reduced_newton;
  return testing::integrate_model(dae, o);
}

double period_error(const testing::RunResult& r) {
  const double m = 2.0, d = 0.5, ixx = 0.05, g = 9.81, i_pivot = ixx + m * d * d;
  const double exact = 4.0 * std::sqrt(i_pivot / (m * g * d)) * testing::elliptic_k(std::sin(0.5));
  const double period = testing::measured_period(r);
  return period > 0 ? std::fabs(period - exact) / exact : INFINITY;
}

TEST(ReducedSolver, PendulumRunsAsAccurate) {
  double log_full = 0, log_reduced = 0;
  long steps_full = 0, steps_reduced = 0;
  for (double rtol : {1e-8, 3e-9, 1e-9, 3e-10, 1e-10, 3e-11}) {
    const testing::RunResult full = integrate_pendulum(false, rtol), reduced = integrate_pendulum(true, rtol);
    ASSERT_TRUE(full.stats.ok) << full.stats.message;
    ASSERT_TRUE(reduced.stats.ok) << reduced.stats.message;
    EXPECT_GE(reduced.stats.fresh_factorizations, 1);
    log_full += std::log(period_error(full)) / 6;
    log_reduced += std::log(period_error(reduced)) / 6;
    steps_full += full.stats.steps;
    steps_reduced += reduced.stats.steps;
  }
  std::printf("  period error (geometric mean): full %.2e, reduced %.2e; steps %ld, %ld\n",
              std::exp(log_full), std::exp(log_reduced), steps_full, steps_reduced);
  EXPECT_LT(log_reduced - log_full, std::log(2.0));
  EXPECT_LT(std::fabs(steps_reduced - steps_full), 0.05 * steps_full);
}

// GGL's rows q' - v + Phi_q^T mu have more entries: the full solver, by the DAE's declaration
// and by the pattern check alike. Index-1 has the structure but keeps the full solver: the
// reduced right side b_r + A_rv b1 swamps b_r in its acceleration rows by cj s Phi_q b1
// (docs/formulation.md).
TEST(ReducedSolver, GglIndex1AndOtherPatternsFallBack) {
  const System sys = build_system(testing::four_bar(0.4));
  GglDae ggl(sys);
  EXPECT_EQ(ggl.kinematic_rows(), 0);
  EXPECT_EQ(Index1Dae(sys).kinematic_rows(), 0);
  EXPECT_TRUE(has_kinematic_rows(Index1Dae(sys).jacobian_pattern(), sys.nq()));
  EXPECT_FALSE(has_kinematic_rows(ggl.jacobian_pattern(), sys.nq()));
  SUNContext ctx = make_sun_context();
  SUNLinearSolver ls = make_newton_linear_solver(ggl.jacobian_pattern(), sys.nq(), ctx);
  EXPECT_FALSE(is_reduced_linear_solver(ls));
  EXPECT_EQ(newton_linear_solver_fresh_factorizations(ls), 0);
  SUNLinSolFree(ls);
  SUNContext_Free(&ctx);

  Index3Dae dae(sys);
  const CscPattern& p = dae.jacobian_pattern();
  EXPECT_TRUE(has_kinematic_rows(p, sys.nq()));
  EXPECT_FALSE(has_kinematic_rows(p, 0));
  EXPECT_FALSE(has_kinematic_rows(p, sys.nq() + 1));  // row nq is a momentum row
  CscPattern missing = p;  // (0, 0) removed: no cj dq_0 in row 0
  missing.rowind.erase(missing.rowind.begin());
  for (size_t j = 1; j < missing.colptr.size(); ++j) --missing.colptr[j];
  EXPECT_FALSE(has_kinematic_rows(missing, sys.nq()));
}

}  // namespace
}  // namespace mbdae
