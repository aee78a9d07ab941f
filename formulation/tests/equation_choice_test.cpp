// The choice of independent equations in a mechanism that moves (issue 23): a four-bar on a
// turntable (verification/redundancy/turntable_four_bar.yaml), whose loop's normal turns in the
// world. Set aside by world components (find_redundant_constraints alone) the kept equations go
// singular a quarter turn later; re-expressed in a body frame (choose_independent_equations)
// they stay well conditioned through the turn. check_equation_choice tells the degraded choice
// from a true singular configuration (the parallelogram four-bar folding flat).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "cases/mbdae.h"
#include "formulation/augmented_solver.h"
#include "formulation/redundancy.h"
#include "formulation/singularity.h"
#include "formulation/system.h"
#include "formulation/tests/test_models.h"

namespace mbdae {
namespace {

// s_min / s_max of the row-normalized constraint Jacobian (0 when rank deficient).
double ratio(const System& sys, const std::vector<double>& q, double t) {
  const SingularityReport r = diagnose_singularity(sys, q.data(), t);
  return r.rank < r.equations ? 0.0 : r.smallest_singular_value / r.largest_singular_value;
}

struct Turntable {
  System all;
  std::vector<double> q;  // consistent at t = 0
};
Turntable turntable() {
  const Scene s = load_scene(std::string(MBDAE_SOURCE_DIR) + "/verification/redundancy/turntable_four_bar.yaml");
  Turntable f{build_system(s.model), {}};
  f.q = f.all.q0;
  AugmentedSolver projector(f.all);
  EXPECT_TRUE(projector.positions(f.q.data(), 0.0, 1e-12, 100, 1e-10).converged);
  return f;
}

TEST(EquationChoice, BodyFrameChoiceStaysValidThroughATurn) {
  Turntable f = turntable();
  const EquationChoice body = choose_independent_equations(f.all, f.q.data(), 0.0);
  ASSERT_EQ(body.report.redundant.size(), 3u);
  EXPECT_EQ(body.report.redundant[0], "cut close: coincident points [along axis1]");
  EXPECT_EQ(body.report.redundant[1], "cut close: axis1 _|_ n1");
  EXPECT_EQ(body.report.redundant[2], "cut close: axis1 _|_ n2");
  ASSERT_EQ(body.reexpressed, std::vector<std::string>{"close"});
  const System world = without_redundant_constraints(f.all, find_redundant_constraints(f.all, f.q.data(), 0.0));
  EXPECT_EQ(world.num_constraint_rows(), body.system.num_constraint_rows());
  // One turn of the table (2 pi rad/s) in 1/64 s steps, each configuration projected from the last.
  AugmentedSolver projector(f.all);
  double body_min = 1, world_min = 1, world_min_t = -1;
  for (int k = 0; k <= 64; ++k) {
    const double t = k / 64.0;
    ASSERT_TRUE(projector.positions(f.q.data(), t, 1e-12, 100, 1e-10).converged) << t;
    body_min = std::fmin(body_min, ratio(body.system, f.q, t));
    const double w = ratio(world, f.q, t);
    if (w < world_min) world_min = w, world_min_t = t;
  }
  std::printf("s_min / s_max through a turn: body-frame choice >= %.3g, world choice down to %.3g at t = %g\n",
              body_min, world_min, world_min_t);
  EXPECT_GT(body_min, 1e-2);
  EXPECT_LT(world_min, 1e-8);
  EXPECT_NEAR(std::fmod(world_min_t, 0.5), 0.25, 1e-12);  // the normal along world x
}

TEST(EquationChoice, DegradedChoiceIsToldFromTheMechanism) {
  Turntable f = turntable();
  const System world = without_redundant_constraints(f.all, find_redundant_constraints(f.all, f.q.data(), 0.0));
  const System body = choose_independent_equations(f.all, f.q.data(), 0.0).system;
  AugmentedSolver projector(f.all);
  ASSERT_TRUE(projector.positions(f.q.data(), 0.25, 1e-12, 100, 1e-10).converged);
  const EquationChoiceCheck w = check_equation_choice(f.all, world, f.q.data(), 0.25, 1e-4);
  EXPECT_TRUE(w.degraded);
  EXPECT_LT(w.kept_ratio, 1e-8);
  EXPECT_GT(w.rechosen_ratio, 1e-2);
  EXPECT_EQ(w.set_aside, 3);
  EXPECT_EQ(w.set_aside_again, 3);
  const EquationChoiceCheck b = check_equation_choice(f.all, body, f.q.data(), 0.25, 1e-4);
  EXPECT_FALSE(b.degraded);
  EXPECT_GT(b.kept_ratio, 1e-2);
}

// Close to the quarter turn, where the world choice is nearly singular, and off the constraints by
// 1e-10 (an integrated state), the new choice still sets aside three equations and is well
// conditioned: where the rank decision at the default tolerance keeps a nearly dependent row,
// check_equation_choice chooses again at looser tolerances.
TEST(EquationChoice, DegradedChoiceIsToldCloseToTheQuarterTurn) {
  Turntable f = turntable();
  const System world = without_redundant_constraints(f.all, find_redundant_constraints(f.all, f.q.data(), 0.0));
  AugmentedSolver projector(f.all);
  for (const double before : {3e-3, 3e-4, 3e-5, 3e-6, 3e-7, 3e-8}) {
    const double t = 0.25 - before;
    ASSERT_TRUE(projector.positions(f.q.data(), t, 1e-12, 100, 1e-10).converged) << t;
    std::vector<double> q = f.q;  // off the constraints by 1e-10, as an integrated state can be
    for (size_t i = 0; i < q.size(); ++i) q[i] += 1e-10 * std::sin(1.0 + 7.0 * i);
    const EquationChoiceCheck w = check_equation_choice(f.all, world, q.data(), t, 1e-2);
    EXPECT_TRUE(w.degraded) << t;
    EXPECT_EQ(w.set_aside_again, 3) << t;
    EXPECT_GT(w.rechosen_ratio, 1e-2) << t;
    EXPECT_LT(w.kept_ratio, 1e-2) << t;
  }
}

// The parallelogram four-bar folding flat is singular whatever equations are kept.
TEST(EquationChoice, FoldingFourBarIsASingularConfiguration) {
  System all = build_system(testing::four_bar(0.5));
  std::vector<double> q = all.q0;
  AugmentedSolver projector(all);
  ASSERT_TRUE(projector.positions(q.data(), 0.0, 1e-12, 50, 1e-10).converged);
  const System kept = choose_independent_equations(all, q.data(), 0.0).system;
  // Nearly flat: both choices nearly singular.
  const std::vector<double> near = build_system(testing::four_bar(1e-6)).q0;
  const EquationChoiceCheck c = check_equation_choice(all, kept, near.data(), 0.0, 1e-4);
  EXPECT_FALSE(c.degraded);
  EXPECT_LT(c.kept_ratio, 1e-4);
  EXPECT_LT(c.rechosen_ratio, 1e-4);
  EXPECT_EQ(c.set_aside_again, c.set_aside);
  // Flat: the mechanism lost a rank, and the new choice sets aside one more equation.
  const std::vector<double> flat = build_system(testing::four_bar(0.0)).q0;
  const EquationChoiceCheck f = check_equation_choice(all, kept, flat.data(), 0.0, 1e-4);
  EXPECT_FALSE(f.degraded);
  EXPECT_EQ(f.kept_ratio, 0.0);
  EXPECT_EQ(f.set_aside_again, f.set_aside + 1);
}

}  // namespace
}  // namespace mbdae
