// Issue 25: joint coordinates that count whole turns (a torsion spring wound several turns, a load
// reading a wound coordinate) and the sensors of rotating machines (angular velocity, angular
// momentum), against closed forms.
#include <gtest/gtest.h>

#include <cmath>

#include "core/ida_driver.h"
#include "formulation/index3_dae.h"
#include "formulation/mechanics.h"
#include "formulation/sensors.h"
#include "formulation/system.h"
#include "formulation/tests/test_models.h"

namespace mbdae {
namespace {

using testing::add_coordinate;
using testing::make_body;
using testing::make_joint;

// A disc on a revolute joint about the world z axis (R3) through its centre of mass, no gravity:
// polar inertia j, a torsion spring of stiffness k (rest 0) on the joint coordinate `th`.
Model torsion_pendulum(double j, double k, double theta0, bool wrap = false) {
  Model m;
  m.name = "torsion";
  m.gravity = Vec3::Zero();
  m.bodies.push_back(make_body("disc", 2.0, Vec3::Zero(), Vec3(0.7, 0.7, j)));
  m.joints.push_back(make_joint("axle", kGround, "disc", Vec3::Zero(), "R3 ", {"th"}));
  add_coordinate(m, "th", theta0);
  ForceSpec f;
  f.name = "spring";
  f.type = ForceSpec::Type::kJointSpringDamper;
  f.coordinate = "th";
  f.stiffness = k;
  f.wrap = wrap;
  m.forces.push_back(f);
  SensorSpec s;
  s.type = SensorSpec::Type::kForceValue;
  s.name = "spring_torque";
  s.target = "spring";
  m.sensors.push_back(s);
  s = SensorSpec();
  s.type = SensorSpec::Type::kCoordinate;
  s.name = "angle";
  s.target = "th";
  m.sensors.push_back(s);
  return m;
}

std::vector<double> sensors_at_q0(const System& sys) {
  std::vector<double> out(sys.sensors.size()), v(sys.nq(), 0.0);
  evaluate_sensors(sys, initial_modes(sys, sys.q0.data(), 0), sys.q0.data(), v.data(), nullptr, 0, out.data());
  return out;
}

// A run tracks the turns of the coordinates that something reads with its turns: the spring
// (not wrapped) or an unwrapped coordinate sensor; a wrapped spring and a wrapped sensor do not.
TEST(Turns, TrackedOnlyWhereRead) {
  EXPECT_EQ(build_system(torsion_pendulum(0.5, 1.0, 1.0)).turn_coordinates, std::vector<int>{0});
  Model wrapped = torsion_pendulum(0.5, 1.0, 1.0, true);
  EXPECT_EQ(build_system(wrapped).turn_coordinates, std::vector<int>{0});  // the sensor unwraps
  wrapped.sensors.back().wrap = true;
  EXPECT_TRUE(build_system(wrapped).turn_coordinates.empty());
}

// Wound 10 rad with unit stiffness the spring gives -10 N m (wrapped, it saw 10 - 4 pi: +2.57).
TEST(Turns, SpringWoundTenRadians) {
  const System sys = build_system(torsion_pendulum(0.5, 1.0, 10.0));
  const std::vector<double> s = sensors_at_q0(sys);
  EXPECT_NEAR(s[0], -10.0, 1e-12);
  EXPECT_NEAR(s[1], 10.0, 1e-12);
  // The generalized force on the disc about z: Q_p = 2 E^T n, n = (0, 0, -10).
  std::vector<double> q = sys.q0, v(sys.nq(), 0.0), f(sys.nq());
  generalized_forces(sys, initial_modes(sys, q.data(), 0), q.data(), v.data(), 0, f.data());
  const Vec4 p = Eigen::Map<const Vec4>(q.data() + 3), qp = Eigen::Map<const Vec4>(f.data() + 3);
  Mat34 e;
  e.col(0) = -p.tail<3>();
  e.rightCols<3>() = skew(p.tail<3>()) + p[0] * Mat3::Identity();
  // n = 1/2 (E E^T)^-1 E Q_p = 1/2 E Q_p for unit p.
  const Vec3 n = 0.5 * e * qp;
  EXPECT_NEAR(n.z(), -10.0, 1e-12);
  // `wrap: true` keeps the old meaning: q - rest wrapped to (-pi, pi].
  const System wrapped = build_system(torsion_pendulum(0.5, 1.0, 10.0, true));
  EXPECT_NEAR(sensors_at_q0(wrapped)[0], -(10.0 - 4 * M_PI), 1e-12);
}

// A load reading a coordinate wound to 10 rad sees 10 (it saw -2.57), and a torque -k th from it
// is the spring's.
TEST(Turns, LoadReadsWoundCoordinate) {
  Model m = torsion_pendulum(0.5, 1.0, 10.0);
  m.forces[0].stiffness = 0;
  ForceSpec t;
  t.name = "motor";
  t.type = ForceSpec::Type::kTorque;
  t.body1 = "disc";
  t.axis = Vec3::UnitZ();
  t.expression[0] = "-k * angle";
  t.parameters = {{"k", 1.0}};
  m.forces.push_back(t);
  SensorSpec s;
  s.type = SensorSpec::Type::kForceValue;
  s.name = "motor_torque";
  s.target = "motor";
  m.sensors.push_back(s);
  const System sys = build_system(m);
  EXPECT_NEAR(sensors_at_q0(sys)[2], -10.0, 1e-12);
}

struct Trace {
  IdaStats stats;
  double worst = 0, worst_torque = 0, min_angle = 1e300, energy_drift = 0;
};

// Integrates `m` (sensors: spring torque, angle) and compares the angle with a(t) and the spring
// torque with -k a(t).
template <class F>
Trace integrate_against(const Model& m, double k, double t1, double rtol, F exact) {
  const System sys = build_system(m);
  Index3Dae dae(sys);
  std::vector<double> y(dae.size(), 0.0), yp(dae.size(), 0.0);
  std::copy(sys.q0.begin(), sys.q0.end(), y.begin());
  dae.consistent_initial_values(0.0, y, yp);
  IdaOptions o;
  o.t1 = t1;
  o.rtol = rtol;
  o.atol = 1e-3 * rtol;
  o.output_step = 0.01;
  Trace tr;
  std::vector<double> q, v, a, s(sys.sensors.size());
  tr.stats = integrate(dae, o, y, yp, [&](double t, const double* yy, const double* yyp) {
    dae.consistent_output(t, yy, yyp, q, v, a, true);
    evaluate_sensors(sys, dae.state().modes, q.data(), v.data(), nullptr, t, s.data(), nullptr, &dae.state().turns);
    tr.worst = std::fmax(tr.worst, std::fabs(s[1] - exact(t)));
    tr.worst_torque = std::fmax(tr.worst_torque, std::fabs(s[0] + k * exact(t)));
    tr.min_angle = std::fmin(tr.min_angle, s[1]);
    return true;
  });
  return tr;
}

// A torsion pendulum wound 10 rad (1.6 turns) swings through -10 rad and back: theta = 10 cos(w t),
// w = sqrt(k / J), over 2.5 periods (eight passes through half a turn each way). Its error falls
// with rtol (a turn counted wrong would be an error of 2 pi at any rtol).
TEST(Turns, TorsionPendulumWoundSeveralTurns) {
  const double j = 0.5, k = 2.0, w = std::sqrt(k / j), theta0 = 10.0;
  const double t1 = 2.5 * 2 * M_PI / w;
  double relative[2];
  for (int tight = 0; tight < 2; ++tight) {
    const Trace tr = integrate_against(torsion_pendulum(j, k, theta0), k, t1, tight ? 1e-10 : 1e-8,
                                       [&](double t) { return theta0 * std::cos(w * t); });
    ASSERT_TRUE(tr.stats.ok) << tr.stats.message;
    EXPECT_LT(tr.min_angle, -0.999 * theta0);
    EXPECT_LT(tr.worst_torque, 1.0001 * k * tr.worst) << "the spring's torque is -k times the angle";
    relative[tight] = tr.worst / theta0;
  }
  std::printf("relative angle errors: rtol 1e-8 %.3g, rtol 1e-10 %.3g\n", relative[0], relative[1]);
  EXPECT_LT(relative[1], 1e-5);  // against the closed form (measured 1.4e-6)
  EXPECT_LT(relative[1], 0.1 * relative[0]);
  RecordProperty("relative_error_rtol_1e-8", testing::sci(relative[0]));
  RecordProperty("relative_error_rtol_1e-10", testing::sci(relative[1]));
}

// Spinning up: a constant torque T on the spring-free disc from rest winds it T t^2 / (2 J), 36
// turns by t = 3; the coordinate read by a torque -c th (c small) stays continuous.
TEST(Turns, DiscSpunUpManyTurns) {
  const double j = 0.5, torque = 50.0;
  Model m = torsion_pendulum(j, 0.0, 0.0);
  ForceSpec t;
  t.name = "motor";
  t.type = ForceSpec::Type::kTorque;
  t.body1 = "disc";
  t.axis = Vec3::UnitZ();
  t.fx = TimeFunction::constant(torque);
  m.forces.push_back(t);
  const Trace tr = integrate_against(m, 0.0, 3.0, 1e-10, [&](double t) { return 0.5 * torque / j * t * t; });
  ASSERT_TRUE(tr.stats.ok) << tr.stats.message;
  EXPECT_LT(tr.worst, 1e-5 * 450) << "angle error (450 rad at the end)";
  EXPECT_LT(tr.worst_torque, 1e-12);  // zero stiffness: no spring torque however far wound
}

// --- Angular velocity and angular momentum ------------------------------------------------

SensorSpec rotation_sensor(const std::string& name, SensorSpec::Type type, const std::string& body, int component,
                           bool body_frame = false, const Vec3& about = Vec3::Zero()) {
  SensorSpec s;
  s.name = name;
  s.type = type;
  s.body = body;
  s.component = component;
  s.body_frame = body_frame;
  s.about = about;
  return s;
}

// A compound pendulum (revolute about x through the origin, centre of mass at (0, 0, -d)) turned
// by theta and turning at rate w: omega = (w, 0, 0) in world and body axes; about the origin
// H_x = (I_xx + m d^2) w, about c = (0, 0, -d) only I_xx w.
TEST(RotationSensors, PendulumAtKnownSpeed) {
  const double mass = 2.0, d = 0.4, ixx = 0.3, theta = 0.7, w = 3.0;
  Model m = testing::pendulum(mass, d, ixx, theta);
  using T = SensorSpec::Type;
  for (int c = 0; c < 3; ++c) {
    m.sensors.push_back(rotation_sensor("w" + std::to_string(c), T::kAngularVelocity, "bob", c));
    m.sensors.push_back(rotation_sensor("wb" + std::to_string(c), T::kAngularVelocity, "bob", c, true));
    m.sensors.push_back(rotation_sensor("h" + std::to_string(c), T::kAngularMomentum, "bob", c));
  }
  // About the centre of mass (0, d sin theta, -d cos theta): only the spin part I_xx w.
  m.sensors.push_back(rotation_sensor("hc", T::kAngularMomentum, "bob", 0, false,
                                      Vec3(0, d * std::sin(theta), -d * std::cos(theta))));
  m.sensors.push_back(rotation_sensor("hsys", T::kAngularMomentum, "", 0));
  const System sys = build_system(m);
  const std::vector<double>& q = sys.q0;
  const Vec4 p = Eigen::Map<const Vec4>(q.data() + 3);
  // Body state at rate w about world x: r' = w x r, p' = 1/2 E(p)^T omega.
  std::vector<double> v(sys.nq(), 0.0);
  const Vec3 omega(w, 0, 0), r = Eigen::Map<const Vec3>(q.data());
  Eigen::Map<Vec3>(v.data()) = omega.cross(r);
  Mat34 e;
  e.col(0) = -p.tail<3>();
  e.rightCols<3>() = skew(p.tail<3>()) + p[0] * Mat3::Identity();
  Eigen::Map<Vec4>(v.data() + 3) = 0.5 * e.transpose() * omega;
  std::vector<double> s(sys.sensors.size());
  evaluate_sensors(sys, initial_modes(sys, q.data(), 0), q.data(), v.data(), nullptr, 0, s.data());
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(s[3 * c], omega[c], 1e-14) << "world omega " << c;
    EXPECT_NEAR(s[3 * c + 1], omega[c], 1e-14) << "body omega " << c;  // x is the joint axis in both
  }
  EXPECT_NEAR(s[2], (ixx + mass * d * d) * w, 1e-13);
  EXPECT_NEAR(s[5], 0.0, 1e-13);
  EXPECT_NEAR(s[8], 0.0, 1e-13);
  EXPECT_NEAR(s[9], ixx * w, 1e-13);
  EXPECT_NEAR(s[10], s[2], 1e-13);  // the only body is the system
}

// A free asymmetric body spinning about no principal axis (a ball joint at its centre of mass, no
// gravity): its angular momentum in world axes is conserved, its angular velocity is not.
TEST(RotationSensors, FreeSpinningBodyConservesAngularMomentum) {
  Model m;
  m.name = "spinner";
  m.gravity = Vec3::Zero();
  m.bodies.push_back(make_body("top", 1.0, Vec3::Zero(), Vec3(1.0, 2.0, 3.0)));
  m.joints.push_back(make_joint("ball", kGround, "top", Vec3::Zero(), "R1 R2 R3 ", {"a", "b", "c"}));
  add_coordinate(m, "a", 0.1);
  add_coordinate(m, "b", 0.2);
  add_coordinate(m, "c", 0.3);
  using T = SensorSpec::Type;
  for (int c = 0; c < 3; ++c) {
    m.sensors.push_back(rotation_sensor("h" + std::to_string(c), T::kAngularMomentum, "", c));
    m.sensors.push_back(rotation_sensor("w" + std::to_string(c), T::kAngularVelocity, "top", c));
  }
  const System sys = build_system(m);
  Index3Dae dae(sys);
  std::vector<double> y(dae.size(), 0.0), yp(dae.size(), 0.0);
  std::copy(sys.q0.begin(), sys.q0.end(), y.begin());
  const Vec4 p = Eigen::Map<const Vec4>(y.data() + 3);
  const Vec3 omega(1.0, 2.0, -0.5);
  Mat34 e;
  e.col(0) = -p.tail<3>();
  e.rightCols<3>() = skew(p.tail<3>()) + p[0] * Mat3::Identity();
  Eigen::Map<Vec4>(y.data() + sys.nq() + 3) = 0.5 * e.transpose() * omega;
  dae.consistent_initial_values(0.0, y, yp);
  // H(0) = A J A^T omega.
  const Mat3 a = rotation(p), jb = Vec3(1.0, 2.0, 3.0).asDiagonal();
  const Vec3 h0 = a * jb * a.transpose() * omega;
  double drift[2];
  for (int tight = 0; tight < 2; ++tight) {
    Index3Dae run_dae(sys);
    std::vector<double> yy0 = y, yyp0 = yp;
    IdaOptions o;
    o.t1 = 5.0;
    o.rtol = tight ? 1e-10 : 1e-8;
    o.atol = 1e-3 * o.rtol;
    o.output_step = 0.05;
    double worst = 0, omega_change = 0, first_omega = 0;
    bool first = true;
    std::vector<double> q, v, acc, s(sys.sensors.size());
    const IdaStats st = integrate(run_dae, o, yy0, yyp0, [&](double t, const double* yy, const double* yyp) {
      run_dae.consistent_output(t, yy, yyp, q, v, acc, true);
      evaluate_sensors(sys, run_dae.state().modes, q.data(), v.data(), nullptr, t, s.data(), nullptr, &run_dae.state().turns);
      if (first) {
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(s[2 * c + 1], omega[c], 1e-9);
        first_omega = s[1];
        first = false;
      }
      for (int c = 0; c < 3; ++c) worst = std::fmax(worst, std::fabs(s[2 * c] - h0[c]));
      omega_change = std::fmax(omega_change, std::fabs(s[1] - first_omega));
      return true;
    });
    ASSERT_TRUE(st.ok) << st.message;
    EXPECT_GT(omega_change, 0.1);  // the angular velocity itself wanders (not a trivial spin)
    drift[tight] = worst / h0.norm();
  }
  std::printf("angular momentum drift: rtol 1e-8 %.3g, rtol 1e-10 %.3g\n", drift[0], drift[1]);
  EXPECT_LT(drift[1], 1e-5);
  EXPECT_LT(drift[1], 0.1 * drift[0]);  // it is integration error: it falls with rtol
  RecordProperty("angular_momentum_drift_rtol_1e-10", testing::sci(drift[1]));
}

}  // namespace
}  // namespace mbdae
