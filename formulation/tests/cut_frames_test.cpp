// Weld and prismatic cuts hold the two cut frames given in the scene (z = axis, x = ref made
// perpendicular), not the bodies' own frames: the assembled relative rotation is the one given,
// and a body turned 180 degrees from it does not satisfy the equations.
#include <gtest/gtest.h>

#include <cmath>

#include "core/errors.h"
#include "formulation/augmented_solver.h"
#include "formulation/mechanics.h"
#include "formulation/system.h"
#include "formulation/tests/test_models.h"

namespace mbdae {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A free body "b" (chain T1 T2 T3 R1 R2 R3 from ground, rotation guess `rz` about z) held to
// ground by one cut.
Model free_body_with_cut(const CutSpec& cut, double rz) {
  Model m;
  m.bodies.push_back(testing::make_body("b", 2, Vec3::Zero(), Vec3(0.1, 0.2, 0.3)));
  m.joints.push_back(testing::make_joint("free", kGround, "b", Vec3::Zero(), "T1 T2 T3 R1 R2 R3 ",
                                         {"x", "y", "z", "rx", "ry", "rz"}));
  for (const char* c : {"x", "y", "z", "rx", "ry"}) testing::add_coordinate(m, c, 0.01);
  testing::add_coordinate(m, "rz", rz);
  m.cuts.push_back(cut);
  return m;
}

CutSpec ground_cut(CutSpec::Type type) {
  CutSpec c;
  c.name = "hold";
  c.type = type;
  c.body1 = kGround;
  c.body2 = "b";
  return c;
}

// World rotation of body b after assembling from the guess.
Mat3 assembled_rotation(const Model& m) {
  System sys = build_system(m);
  std::vector<double> q = sys.q0;
  AugmentedSolver projector(sys);
  EXPECT_TRUE(projector.positions(q.data(), 0.0, 1e-12, 50, 1e-10).converged);
  return rotation(Eigen::Map<const Vec4>(q.data() + 3)) * sys.frames.at("b").rotation;
}

// Weld with the body's cut frame turned by phi about z (x2 = (cos phi, sin phi, 0)): the body
// must end turned by -phi so that the two cut frames coincide.
TEST(CutFrames, WeldHoldsTheGivenRelativeRotation) {
  for (double phi : {0.5, kPi / 2, 2.5}) {
    CutSpec c = ground_cut(CutSpec::Type::kWeld);
    c.ref2 = Vec3(std::cos(phi), std::sin(phi), 0);
    const Mat3 r = assembled_rotation(free_body_with_cut(c, 0.0));
    const Mat3 expected = axis_rotation(2, -phi);
    EXPECT_LT((r - expected).norm(), 1e-9) << "phi " << phi << "\n" << r;
  }
}

// Tilted axes: the body's cut axis (axis2) ends on the ground's (axis1), and its reference on
// ground's reference.
TEST(CutFrames, WeldAlignsAxesAndReferences) {
  CutSpec c = ground_cut(CutSpec::Type::kWeld);
  c.axis1 = Vec3(0, 0, 1);
  c.ref1 = Vec3(1, 0, 0);
  c.axis2 = Vec3(0, std::sin(0.5), std::cos(0.5));  // turned 0.5 rad about x
  c.ref2 = Vec3(1, 0, 0);
  const Mat3 r = assembled_rotation(free_body_with_cut(c, 0.0));
  EXPECT_LT((r * c.axis2 - c.axis1).norm(), 1e-9);
  EXPECT_LT((r * c.ref2 - c.ref1).norm(), 1e-9);
  EXPECT_LT((r - axis_rotation(0, 0.5)).norm(), 1e-9) << r;  // axis2 = R_x(-0.5) z
}

// A body turned 180 degrees about z from the welded orientation violates the weld (three
// dot-1 equations x1.y2 = y1.z2 = z1.x2 = 0 are satisfied by such flips).
TEST(CutFrames, FlippedBodyViolatesTheWeld) {
  const System sys = build_system(free_body_with_cut(ground_cut(CutSpec::Type::kWeld), kPi));
  std::vector<double> q = sys.q0;
  for (int k = 0; k < 3; ++k) q[k] = 0;  // points coincide
  const std::vector<int> off = constraint_offsets(sys);
  std::vector<double> phi(off.back());
  constraint_values(sys, off, q.data(), 0.0, phi.data());
  EXPECT_GT(max_abs(phi.data(), off.back()), 0.9);
}

// Prismatic: the body's y axis slides along the world x axis, its -x on the world y axis.
TEST(CutFrames, PrismaticHoldsTheGivenFrames) {
  CutSpec c = ground_cut(CutSpec::Type::kPrismatic);
  c.axis1 = Vec3(1, 0, 0);
  c.ref1 = Vec3(0, 1, 0);
  c.axis2 = Vec3(0, 1, 0);
  c.ref2 = Vec3(-1, 0, 0);
  const Mat3 r = assembled_rotation(free_body_with_cut(c, 0.0));
  EXPECT_LT((r * Vec3::UnitY() - Vec3::UnitX()).norm(), 1e-9) << r;
  EXPECT_LT((r * Vec3::UnitX() + Vec3::UnitY()).norm(), 1e-9) << r;
}

TEST(CutFrames, ReferenceAlongTheAxisIsRefusedWithItsField) {
  CutSpec c = ground_cut(CutSpec::Type::kWeld);
  c.ref2 = Vec3(0, 0, 2);  // along axis2 = z
  try {
    build_system(free_body_with_cut(c, 0.0));
    FAIL() << "no error";
  } catch (const ModelError& e) {
    EXPECT_NE(std::string(e.what()).find("ref2"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace mbdae
