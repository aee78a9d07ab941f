// Euler-parameter algebra: A(p) is a rotation, B, K and L against finite differences, and the
// round trip through a rotation matrix.
#include <gtest/gtest.h>

#include "formulation/euler_parameters.h"

namespace mbdae {
namespace {

const Vec4 kP = Vec4(0.8, -0.3, 0.4, 0.33).normalized();
const Vec3 kS(0.3, -0.7, 1.1);

TEST(EulerParameters, RotationIsOrthonormal) {
  const Mat3 a = rotation(kP);
  EXPECT_NEAR((a.transpose() * a - Mat3::Identity()).norm(), 0, 1e-15);
  EXPECT_NEAR(a.determinant(), 1, 1e-15);
  EXPECT_NEAR((rotate(kP, kS) - a * kS).norm(), 0, 1e-15);
  const Vec4 back = euler_parameters_from_rotation(a);
  EXPECT_NEAR((back - kP).norm(), 0, 1e-15);
  EXPECT_NEAR((axis_rotation(0, 0.3) - rotation(Vec4(std::cos(0.15), std::sin(0.15), 0, 0))).norm(), 0, 1e-15);
}

TEST(EulerParameters, DerivativesAgainstFiniteDifferences) {
  const double h = 1e-6;
  const Mat34 b = B_matrix(kP, kS);
  const Vec3 w(0.2, 0.9, -0.4);
  const Vec4 x(0.1, -0.2, 0.5, 0.3);
  for (int k = 0; k < 4; ++k) {
    const Vec4 e = Vec4::Unit(k) * h;
    // B = d(A(p) s)/dp
    const Vec3 fd = (rotate(kP + e, kS) - rotate(kP - e, kS)) / (2 * h);
    EXPECT_NEAR((b.col(k) - fd).norm(), 0, 1e-9);
    // K(s, w) = d(B(p, s)^T w)/dp
    const Vec4 kd = (B_matrix(kP + e, kS).transpose() * w - B_matrix(kP - e, kS).transpose() * w) / (2 * h);
    EXPECT_NEAR((K_matrix(kS, w).col(k) - kd).norm(), 0, 1e-9);
    // d(B(p, s) x)/dp = B(x, s)
    const Vec3 bx = (B_matrix(kP + e, kS) * x - B_matrix(kP - e, kS) * x) / (2 * h);
    EXPECT_NEAR((B_matrix(x, kS).col(k) - bx).norm(), 0, 1e-9);
    // P(w) = d(L(p)^T w)/dp
    const Vec4 pd = (L_matrix(kP + e).transpose() * w - L_matrix(kP - e).transpose() * w) / (2 * h);
    EXPECT_NEAR((P_matrix(w).col(k) - pd).norm(), 0, 1e-9);
  }
  EXPECT_NEAR((K_matrix(kS, w) - K_matrix(kS, w).transpose()).norm(), 0, 1e-14);
  EXPECT_NEAR((b * kP - 2 * rotate(kP, kS)).norm(), 0, 1e-14);
}

TEST(EulerParameters, AngularVelocityFromTheRateOfTheParameters) {
  // p(t) for a rotation at constant body rate omega: p' = 1/2 L(p)^T omega, omega = 2 L p'.
  const Vec3 omega(0.3, -1.2, 0.7);
  const Vec4 pd = 0.5 * L_matrix(kP).transpose() * omega;
  EXPECT_NEAR((2 * L_matrix(kP) * pd - omega).norm(), 0, 1e-14);
  EXPECT_NEAR(kP.dot(pd), 0, 1e-15);  // stays on the unit sphere
  // A' = A [omega]x
  const double h = 1e-6;
  const Mat3 ad = (rotation(kP + h * pd) - rotation(kP - h * pd)) / (2 * h);
  EXPECT_NEAR((ad - rotation(kP) * skew(omega)).norm(), 0, 1e-8);
}

}  // namespace
}  // namespace mbdae
