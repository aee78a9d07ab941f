// The loads of issue 13 (torque, follower force, joint spring-damper, bushing, expression
// components of sensors) against central finite differences: each element's local Jacobians, the
// gradients of the load inputs, and the whole index-3 Newton matrix (which holds the couplings of
// expression loads to the bodies their sensors read).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "formulation/force_types.h"
#include "formulation/forces.h"
#include "formulation/ggl_dae.h"
#include "formulation/index3_dae.h"
#include "formulation/mechanics.h"
#include "formulation/sensors.h"
#include "formulation/system.h"
#include "formulation/tests/test_models.h"

namespace mbdae {
namespace {

using testing::random_state;
using testing::RandomState;

SensorSpec sensor(const std::string& name, SensorSpec::Type type, const std::string& body_or_target,
                  int component = 0) {
  SensorSpec s;
  s.name = name;
  s.type = type;
  if (type == SensorSpec::Type::kPosition || type == SensorSpec::Type::kVelocity || type == SensorSpec::Type::kAxis)
    s.body = body_or_target;
  else
    s.target = body_or_target;
  s.component = component;
  s.point = type == SensorSpec::Type::kAxis ? "" : "com";
  s.axis = Vec3(0.3, -0.2, 0.9);
  return s;
}

// all_types_model() plus one load of every new kind; the expression loads read sensors of every
// kind a load may read, on bodies other than the one they push.
Model loads_model() {
  Model m = testing::all_types_model();
  m.ground_points["anchor"] = Vec3(0.2, -0.3, 0.5);
  auto add = [&](ForceSpec f) { m.forces.push_back(f); };
  ForceSpec f;
  f.name = "torque_world";
  f.type = ForceSpec::Type::kTorque;
  f.body1 = "b";
  f.axis = Vec3(0.2, 0.5, 0.8);
  f.fx = TimeFunction::constant(1.7);
  add(f);
  f.name = "torque_body";
  f.body1 = "e";
  f.body_frame = true;
  add(f);
  ForceSpec fo;
  fo.name = "follower";
  fo.type = ForceSpec::Type::kPointForce;
  fo.body1 = "a";
  fo.point1 = "p";
  fo.body_frame = true;
  fo.fx = TimeFunction::constant(0.5);
  fo.fy = TimeFunction::constant(-1.5);
  fo.fz = TimeFunction::constant(2.5);
  add(fo);
  for (const char* c : {"qa", "qb2", "qd", "qe2", "qf1"}) {
    ForceSpec j;
    j.name = std::string("spring_") + c;
    j.type = ForceSpec::Type::kJointSpringDamper;
    j.coordinate = c;
    j.stiffness = 40;
    j.damping = 3;
    j.free_length = 0.1;
    add(j);
  }
  ForceSpec bu;
  bu.name = "bush_ce";
  bu.type = ForceSpec::Type::kBushing;
  bu.body1 = "c";
  bu.at_xyz1 = true;
  bu.xyz1 = Vec3(0.1, 0.0, 0.2);
  bu.body2 = "e";
  bu.translational_stiffness = Vec3(100, 200, 300);
  bu.translational_damping = Vec3(1, 2, 3);
  bu.rotational_stiffness = Vec3(10, 20, 30);
  bu.rotational_damping = Vec3(0.1, 0.2, 0.3);
  add(bu);
  bu.name = "bush_ground";
  bu.body1 = kGround;
  bu.at_xyz1 = false;
  bu.point1 = "anchor";
  bu.body2 = "d";
  add(bu);
  using T = SensorSpec::Type;
  m.sensors.push_back(sensor("w", T::kCoordinateRate, "qb2"));
  m.sensors.push_back(sensor("th", T::kCoordinate, "qc3"));
  m.sensors.push_back(sensor("z", T::kPosition, "g", 2));
  m.sensors.push_back(sensor("vy", T::kVelocity, "f", 1));
  m.sensors.push_back(sensor("ax", T::kAxis, "c", 0));
  m.sensors.push_back(sensor("len", T::kForceLength, "spring"));
  m.sensors.push_back(sensor("ten", T::kForceValue, "spring"));
  m.sensors.push_back(sensor("bush", T::kForceValue, "bush_ce"));
  // Issue 25: angular velocity (world and body axes) and a body's angular momentum about a point.
  m.sensors.push_back(sensor("spin", T::kAngularVelocity, "e", 2));
  m.sensors.back().body = "e";
  m.sensors.push_back(sensor("spin_b", T::kAngularVelocity, "b", 1));
  m.sensors.back().body = "b";
  m.sensors.back().body_frame = true;
  m.sensors.push_back(sensor("mom", T::kAngularMomentum, "c", 0));
  m.sensors.back().body = "c";
  m.sensors.back().about = Vec3(0.3, -0.1, 0.2);
  m.sensors.push_back(sensor("twist", T::kCoordinate, "qa"));
  ForceSpec motor;
  motor.name = "motor";
  motor.type = ForceSpec::Type::kTorque;
  motor.body1 = "d";
  motor.axis = Vec3(0, 0, 1);
  motor.expression[0] = "T0 * (1 - w / w0) + sin(th) * z + 0.3 * vy * ax - 0.01 * len * ten + 0.02 * bush * t"
                        " + 0.2 * spin * spin_b - 0.1 * mom + 0.05 * twist";
  motor.parameters = {{"T0", 2.0}, {"w0", 5.0}};
  add(motor);
  ForceSpec push;
  push.name = "expression_push";
  push.type = ForceSpec::Type::kPointForce;
  push.body1 = "a";
  push.point1 = "p";
  push.body_frame = true;
  push.expression[0] = "-k * z - c * vy";
  push.expression[2] = "th ^ 2 + ax";
  push.fy = TimeFunction::constant(0.3);
  push.parameters = {{"k", 30.0}, {"c", 2.0}};
  add(push);
  return m;
}

TEST(LoadsJacobian, ElementJacobiansMatchFiniteDifferences) {
  const System sys = build_system(loads_model());
  const RandomState st = random_state(sys, 5);
  int checked = 0;
  for (const Force& f : sys.forces) {
    if (f.type != ForceSpec::Type::kTorque && f.type != ForceSpec::Type::kPointForce &&
        f.type != ForceSpec::Type::kJointSpringDamper && f.type != ForceSpec::Type::kBushing)
      continue;
    if (f.has_expression()) continue;  // whole-system check below
    const testing::ForceCheck check =
        testing::check_force_jacobians(f, gather(st.q.data(), f.bi, f.bj), gather(st.v.data(), f.bi, f.bj));
    EXPECT_GT(check.force_norm, 0) << f.name;
    EXPECT_LT(check.worst, 1e-6) << check.where;
    RecordProperty("worst_relative_error_" + f.name, testing::sci(check.worst));
    ++checked;
  }
  EXPECT_EQ(checked, 11);  // with all_types_model's world point force
}

// The load inputs' gradients (sensor gradients through the expression's exact derivative).
TEST(LoadsJacobian, LoadInputGradientsMatchFiniteDifferences) {
  const System sys = build_system(loads_model());
  const RandomState st = random_state(sys, 6);
  const std::vector<char> modes(sys.forces.size(), 1);
  for (const Force& f : sys.forces) {
    if (!f.has_expression()) continue;
    ASSERT_GE(f.reads.size(), 4u) << f.name;
    const LoadInput in = load_input(sys, f, modes, st.q.data(), st.v.data(), 0.4, true);
    for (size_t r = 0; r < f.reads.size(); ++r)
      for (int m = 0; m < 7; ++m)
        for (int which = 0; which < 2; ++which) {
          const int g = 7 * f.reads[r] + m;
          const double eps = 1e-6;
          std::vector<double> qp = st.q, qm = st.q, vp = st.v, vm = st.v;
          (which ? vp : qp)[g] += eps;
          (which ? vm : qm)[g] -= eps;
          const LoadInput ip = load_input(sys, f, modes, qp.data(), vp.data(), 0.4, false);
          const LoadInput im = load_input(sys, f, modes, qm.data(), vm.data(), 0.4, false);
          for (int c = 0; c < 3; ++c) {
            if (f.expression[c].empty()) continue;
            const double fd = (ip.value[c] - im.value[c]) / (2 * eps);
            const double an = which ? in.dv[c][7 * r + m] : in.dq[c][7 * r + m];
            EXPECT_NEAR(an, fd, 1e-6 * (1 + std::fabs(fd))) << f.name << " component " << c << " body "
                                                            << f.reads[r] << (which ? " dv " : " dq ") << m;
          }
        }
  }
}

TEST(LoadsJacobian, Index3NewtonMatrixWithLoads) {
  const System sys = build_system(loads_model());
  Index3Dae dae(sys, 7.0);
  const testing::NewtonCheck check = testing::check_newton_matrix(dae, random_state(sys, 7), false);
  EXPECT_LT(check.worst, 1e-6) << check.where;
  RecordProperty("worst_relative_error", testing::sci(check.worst));
}

// index2-ggl's F_y x without the assembly (GglDae::jacobian_times: the forces' local Jacobians
// times the local x, and the expression loads' chain to the bodies their sensors read) against
// its assembled Newton matrix at cj = 0 times x, for two x at once.
TEST(LoadsJacobian, GglJacobianTimesWithLoadsIsTheAssembledMatrixTimesX) {
  const System sys = build_system(loads_model());
  GglDae dae(sys, 7.0);
  const int n = dae.size();
  std::vector<double> y, yp, values(dae.jacobian_pattern().nnz());
  testing::dae_vectors(random_state(sys, 9), n, true, y, yp);
  ASSERT_EQ(dae.jacobian(0.3, 0.0, y.data(), yp.data(), values.data()), 0);
  std::vector<double> x[2], out[2], ref[2];
  for (int i = 0; i < 2; ++i) {
    x[i].resize(n);
    for (int k = 0; k < n; ++k) x[i][k] = std::sin(1.0 + k * (i + 2.0));
    out[i].assign(n, 0.0);
    ref[i].assign(n, 0.0);
    csc_multiply(dae.jacobian_pattern(), values.data(), x[i].data(), ref[i].data());
  }
  const double* xs[2] = {x[0].data(), x[1].data()};
  double* outs[2] = {out[0].data(), out[1].data()};
  dae.jacobian_times(0.3, y.data(), yp.data(), 2, xs, outs);
  double worst = 0, largest = 0;
  for (int i = 0; i < 2; ++i)
    for (int k = 0; k < n; ++k) {
      worst = std::max(worst, std::fabs(out[i][k] - ref[i][k]) / (1 + std::fabs(ref[i][k])));
      largest = std::max(largest, std::fabs(ref[i][k]));
    }
  EXPECT_LT(worst, 1e-12);
  EXPECT_GT(largest, 1.0);
  RecordProperty("worst_relative_difference", testing::sci(worst));
}

// Loads may read only sensors with a known gradient, and not each other.
TEST(LoadsJacobian, LoadExpressionsAreChecked) {
  auto message = [](Model m) {
    try {
      build_system(m);
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  Model m = loads_model();
  m.forces.back().expression[0] = "unknown_sensor * 2";
  EXPECT_NE(message(m).find("unknown name 'unknown_sensor'"), std::string::npos) << message(m);
  m = loads_model();
  m.sensors.push_back(sensor("motor_torque", SensorSpec::Type::kForceValue, "motor"));
  m.forces.back().expression[0] = "motor_torque";
  EXPECT_NE(message(m).find("measures a load given by an expression"), std::string::npos) << message(m);
  m = loads_model();
  m.sensors.push_back(sensor("energy", SensorSpec::Type::kKineticEnergy, ""));
  m.forces.back().expression[0] = "energy";
  EXPECT_NE(message(m).find("cannot drive a load"), std::string::npos) << message(m);
  m = loads_model();
  m.sensors.push_back(sensor("pi", SensorSpec::Type::kCoordinate, "qa"));
  EXPECT_NE(message(m).find("reserved"), std::string::npos) << message(m);
}

// The worked example of the force-type table (formulation/forces/joint_friction.cpp): smooth
// Coulomb friction on rotation and translation coordinates, slip rates at which the random rates
// (order 1) fall on the curved part of tanh, against central differences: each element's
// Jacobians and the whole index-3 Newton matrix.
Model friction_model() {
  Model m = testing::all_types_model();
  double level = 2.0;
  for (const char* c : {"qa", "qb2", "qd", "qe2", "qf1"}) {
    ForceSpec j;
    j.name = std::string("friction_") + c;
    j.type = find_force_type("joint_friction");
    j.coordinate = c;
    j.coefficient[0] = level;  // friction
    j.coefficient[1] = 0.7;    // slip_rate
    level += 0.5;
    m.forces.push_back(j);
  }
  return m;
}

TEST(LoadsJacobian, JointFrictionJacobiansMatchFiniteDifferences) {
  const System sys = build_system(friction_model());
  int checked = 0;
  for (unsigned seed : {11u, 12u, 13u}) {
    const RandomState st = random_state(sys, seed);
    for (const Force& f : sys.forces) {
      if (f.type != find_force_type("joint_friction")) continue;
      const testing::ForceCheck check =
          testing::check_force_jacobians(f, gather(st.q.data(), f.bi, f.bj), gather(st.v.data(), f.bi, f.bj));
      EXPECT_GT(check.force_norm, 0) << f.name;
      EXPECT_LT(check.worst, 1e-6) << check.where;
      RecordProperty("worst_relative_error_" + f.name + "_" + std::to_string(seed), testing::sci(check.worst));
      ++checked;
    }
  }
  EXPECT_EQ(checked, 15);
  Index3Dae dae(sys, 7.0);
  const testing::NewtonCheck check = testing::check_newton_matrix(dae, random_state(sys, 14), false);
  EXPECT_LT(check.worst, 1e-6) << check.where;
}

}  // namespace
}  // namespace mbdae
