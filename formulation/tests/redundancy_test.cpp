// Redundant constraints: a planar four-bar built from 3D revolute joints has 3 redundant
// equations at every configuration (Gruebler in space: 3 x 6 - 4 x 5 = -2, actual mobility 1).
#include <gtest/gtest.h>

#include <cmath>

#include "formulation/augmented_solver.h"
#include "formulation/redundancy.h"
#include "formulation/system.h"
#include "formulation/tests/test_models.h"

namespace mbdae {
namespace {

using testing::add_coordinate;
using testing::four_bar;
using testing::make_body;
using testing::make_joint;

TEST(Redundancy, PlanarFourBarHasThreeRedundantEquations) {
  for (double angle : {0.3, 1.2, 2.5}) {
    System sys = build_system(four_bar(angle));
    const int before = sys.num_constraint_rows();
    std::vector<double> q = sys.q0;
    AugmentedSolver projector(sys);
    ASSERT_TRUE(projector.positions(q.data(), 0.0, 1e-12, 50, 1e-10).converged);
    const RedundancyReport r = find_redundant_constraints(sys, q.data(), 0.0);
    EXPECT_EQ(sys.num_constraint_rows(), before);  // the analysis does not change the system
    sys = without_redundant_constraints(sys, r);
    EXPECT_EQ(r.equations, before);
    EXPECT_EQ(r.rank, before - 3) << "angle " << angle;
    ASSERT_EQ(r.redundant.size(), 3u);
    for (const auto& label : r.redundant) EXPECT_NE(label.find("cut close"), std::string::npos) << label;
    EXPECT_EQ(sys.num_constraint_rows(), before - 3);
    // The reduced system has full rank: nothing more is found.
    EXPECT_TRUE(find_redundant_constraints(sys, q.data(), 0.0).redundant.empty());
  }
}

TEST(Redundancy, BallCutOnAPlanarLoopHasOneRedundantEquation) {
  // With a ball at the closing joint, every point still moves in its plane z = const: the
  // ball's z equation is implied by the revolute joints.
  Model m = four_bar(0.7);
  m.cuts[0].type = CutSpec::Type::kBall;
  System sys = build_system(m);
  std::vector<double> q = sys.q0;
  AugmentedSolver projector(sys);
  ASSERT_TRUE(projector.positions(q.data(), 0.0, 1e-12, 50, 1e-10).converged);
  const RedundancyReport r = find_redundant_constraints(sys, q.data(), 0.0);
  ASSERT_EQ(r.redundant.size(), 1u);
  EXPECT_EQ(r.redundant[0], "cut close: coincident points [z]");
}

TEST(Redundancy, IndependentConstraintsAreKept) {
  // A spatial loop: the coupler on a spherical joint (R1 R2 R3) at the crank, closed on the
  // rocker by a universal cut (coupler y _|_ rocker z). Mobility 1, no redundant equation.
  Model m = four_bar(0.7);
  m.joints[1].chain = {{true, 0, "b1"}, {true, 1, "b2"}, {true, 2, "b"}};
  add_coordinate(m, "b1", 0.0);
  add_coordinate(m, "b2", 0.0);
  m.cuts[0].type = CutSpec::Type::kUniversal;
  m.cuts[0].axis1 = Vec3::UnitY();
  m.cuts[0].axis2 = Vec3::UnitZ();
  System sys = build_system(m);
  std::vector<double> q = sys.q0;
  AugmentedSolver projector(sys);
  ASSERT_TRUE(projector.positions(q.data(), 0.0, 1e-12, 50, 1e-10).converged);
  const RedundancyReport r = find_redundant_constraints(sys, q.data(), 0.0);
  EXPECT_TRUE(r.redundant.empty());
  EXPECT_EQ(r.rank, r.equations);
}

}  // namespace
}  // namespace mbdae
