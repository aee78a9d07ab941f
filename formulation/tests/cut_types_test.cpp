// The cut-type table (formulation/cut_types.h): every CutSpec::Type has one row, found by its
// scene name, and each row's equations remove the degrees of freedom its joint removes (ball 3,
// universal 4, revolute 5, prismatic 5, weld 6, distance 1, cylindrical 4), with a Jacobian of
// that rank at a generic configuration.
#include <gtest/gtest.h>

#include <map>
#include <set>

#include <Eigen/LU>

#include "formulation/cut_types.h"

namespace mbdae {
namespace {

TEST(CutTypes, EveryTypeHasOneRowFoundByItsName) {
  std::set<std::string> names;
  for (const CutType& row : cut_types()) {
    EXPECT_TRUE(names.insert(row.name).second) << row.name << " twice";
    ASSERT_EQ(find_cut_type(row.name), &row) << row.name;
    EXPECT_EQ(&cut_type(row.type), &row) << row.name;
    EXPECT_NE(row.equations, nullptr) << row.name;
  }
  using T = CutSpec::Type;
  for (T t : {T::kBall, T::kRevolute, T::kUniversal, T::kPrismatic, T::kWeld, T::kDistance, T::kCylindrical})
    EXPECT_EQ(cut_type(t).type, t);
  EXPECT_EQ(find_cut_type("hinge"), nullptr);
}

TEST(CutTypes, EquationsRemoveTheJointsDegreesOfFreedom) {
  const std::map<std::string, int> removed = {{"ball", 3}, {"universal", 4}, {"revolute", 5},
                                              {"prismatic", 5}, {"weld", 6}, {"distance", 1}, {"cylindrical", 4}};
  // Two free bodies at generic poses; the cut's points and axes in their frames.
  Vec4 p1(0.9, 0.1, -0.3, 0.2), p2(0.8, -0.2, 0.4, 0.1);
  p1.normalize();
  p2.normalize();
  LocalState x;
  x.ri = Vec3(0.1, 0.2, 0.3);
  x.pi = p1;
  x.rj = Vec3(0.4, -0.1, 0.5);
  x.pj = p2;
  BodyFrame f1, f2;
  f1.body = 0;
  f2.body = 1;
  for (const CutType& row : cut_types()) {
    CutSpec cut;
    cut.name = "c";
    cut.type = row.type;
    cut.axis1 = Vec3(0.2, 0.3, 1.0);
    cut.axis2 = Vec3(-0.1, 0.4, 1.0);
    cut.ref1 = Vec3(1.0, 0.1, 0.0);
    cut.ref2 = Vec3(0.9, -0.3, 0.2);
    cut.distance = 0.7;
    System sys;
    row.equations(cut, CutSides{&f1, &f2, Vec3(0.1, 0, 0), Vec3(0, 0.2, 0)}, CutEquations{cut, sys});
    Eigen::MatrixXd jac(0, 14);
    for (const Constraint& c : sys.constraints) {
      EXPECT_EQ(c.owner, Constraint::Owner::kCut);
      EXPECT_EQ(c.label.rfind("cut c: ", 0), 0u) << c.label;
      Row14 rows[3];
      constraint_jacobian(c, x, rows);
      for (int r = 0; r < c.rows(); ++r) {
        jac.conservativeResize(jac.rows() + 1, 14);
        jac.row(jac.rows() - 1) = rows[r];
      }
    }
    EXPECT_EQ(jac.rows(), removed.at(row.name)) << row.name;
    // Rank within the rigid-body motions (the Euler-parameter norm directions excluded).
    Eigen::FullPivLU<Eigen::MatrixXd> lu(jac);
    lu.setThreshold(1e-9);
    EXPECT_EQ(lu.rank(), removed.at(row.name)) << row.name;
  }
}

}  // namespace
}  // namespace mbdae
