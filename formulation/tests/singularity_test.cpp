// Singular configurations: the parallelogram four-bar of test_models.h folds flat at angle 0
// (crank, coupler and rocker on the x axis), where its in-plane constraint Jacobian loses one
// rank: the three bars can carry a self-stressed tension along x that moves nothing.
#include <gtest/gtest.h>

#include <cmath>

#include "formulation/augmented_solver.h"
#include "formulation/redundancy.h"
#include "formulation/singularity.h"
#include "formulation/system.h"
#include "formulation/tests/test_models.h"

namespace mbdae {
namespace {

// The four-bar at `angle` with its three structural redundancies (out of plane) removed.
struct Folded {
  System sys;
  std::vector<double> q;
};
Folded four_bar_at(double angle) {
  Folded f{build_system(testing::four_bar(0.5)), {}};
  f.q = f.sys.q0;
  AugmentedSolver projector(f.sys);
  EXPECT_TRUE(projector.positions(f.q.data(), 0.0, 1e-12, 50, 1e-10).converged);
  f.sys = without_redundant_constraints(f.sys, find_redundant_constraints(f.sys, f.q.data(), 0.0));
  // The exact configuration at `angle`: crank and rocker at angle, coupler parallel to x.
  const System at = build_system(testing::four_bar(angle));
  f.q = at.q0;
  return f;
}

TEST(Singularity, RegularConfigurationIsFarFromSingular) {
  const Folded f = four_bar_at(1.0);
  const SingularityReport r = diagnose_singularity(f.sys, f.q.data(), 0.0);
  EXPECT_EQ(r.rank, r.equations);
  EXPECT_GT(r.smallest_singular_value / r.largest_singular_value, 0.05);
}

// Near the flat configuration the smallest singular value is proportional to the angle (the
// height of the parallelogram), and the dependent combination is the bars' tension along x:
// the x rows of the joints and the cut, no other joint equation.
TEST(Singularity, NearlyFlatFourBarNamesTheBarsAlongTheLine) {
  const Folded a = four_bar_at(1e-3), b = four_bar_at(1e-4);
  const SingularityReport ra = diagnose_singularity(a.sys, a.q.data(), 0.0);
  const SingularityReport rb = diagnose_singularity(b.sys, b.q.data(), 0.0);
  ASSERT_EQ(ra.rank, ra.equations);
  EXPECT_NEAR(ra.smallest_singular_value / rb.smallest_singular_value, 10.0, 0.05);
  EXPECT_LT(rb.smallest_singular_value / rb.largest_singular_value, 1e-4);
  ASSERT_FALSE(rb.dependent.empty());
  // (Euler-parameter norms take part too: a bar's point rows have a component along p, A s being
  // quadratic in p, that the norm's multiplier balances. They are bodies, not joints.)
  for (const auto& d : rb.dependent) {
    if (d.label.rfind("body ", 0) == 0) continue;
    EXPECT_NE(d.label.find("[x]"), std::string::npos) << d.label << " " << d.weight;
  }
  for (const char* name : {"joint j1", "joint j2", "joint j3", "cut close"})
    EXPECT_NE(std::find(rb.constraints.begin(), rb.constraints.end(), name), rb.constraints.end()) << name;
}

// Exactly flat: the rank drops by one and the dependent equation is named.
TEST(Singularity, FlatFourBarLosesOneRank) {
  const Folded f = four_bar_at(0.0);
  const SingularityReport r = diagnose_singularity(f.sys, f.q.data(), 0.0);
  EXPECT_EQ(r.rank, r.equations - 1);
  ASSERT_EQ(r.dependent.size(), 1u);
  EXPECT_NE(r.dependent[0].label.find("[x]"), std::string::npos) << r.dependent[0].label;
}

// What each equation belongs to comes from the constraint, not from its label: names with ':'
// and ' (' (which a label parser splits) are reported whole.
TEST(Singularity, GroupsKeepNamesWithColonsAndParentheses) {
  Model m = testing::four_bar(1e-4);
  m.joints[0].name = "j1 (crank)";
  m.joints[1].name = "j2: mid";
  m.cuts[0].name = "close (loop): end";
  Folded f{build_system(m), {}};
  f.q = f.sys.q0;
  AugmentedSolver projector(f.sys);
  ASSERT_TRUE(projector.positions(f.q.data(), 0.0, 1e-12, 50, 1e-10).converged);
  f.sys = without_redundant_constraints(f.sys, find_redundant_constraints(f.sys, f.q.data(), 0.0));
  const SingularityReport r = diagnose_singularity(f.sys, build_system(m).q0.data(), 0.0);
  for (const char* name : {"joint j1 (crank)", "joint j2: mid", "joint j3", "cut close (loop): end"})
    EXPECT_NE(std::find(r.constraints.begin(), r.constraints.end(), name), r.constraints.end()) << name;
  for (const auto& d : r.dependent) EXPECT_EQ(d.label.rfind(d.group, 0), 0u) << d.label << " / " << d.group;
}

TEST(Singularity, ConstraintGroups) {
  const System sys = build_system(testing::four_bar(0.5));
  std::vector<std::string> groups;
  for (const auto& c : sys.constraints) groups.push_back(constraint_group(c));
  for (const char* name : {"body crank", "joint j1", "joint j2", "joint j3", "cut close"})
    EXPECT_NE(std::find(groups.begin(), groups.end(), name), groups.end()) << name;
  EXPECT_EQ(hold_constraint(sys, 0, 0.0).owner, Constraint::Owner::kHold);
  EXPECT_EQ(constraint_group(hold_constraint(sys, sys.coordinate_index("b"), 0.0)), "hold b");
}

}  // namespace
}  // namespace mbdae
