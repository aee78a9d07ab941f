// Force sensors of a wheel contact: its length is the penetration e = radius - (z - ground(t))
// at the sensor's time, consistent with its force stiffness e.
#include <gtest/gtest.h>

#include "formulation/mechanics.h"
#include "formulation/sensors.h"
#include "formulation/system.h"
#include "formulation/tests/test_models.h"

namespace mbdae {
namespace {

// A wheel of radius 0.3 resting on the ground (z = radius) whose ground steps up by 0.1 m at
// t = 0.2 s; sensors: the contact's length and force.
Model wheel_on_a_step() {
  Model m;
  m.bodies.push_back(testing::make_body("wheel", 10, Vec3::Zero(), Vec3(0.3, 0.5, 0.3)));
  m.joints.push_back(testing::make_joint("slider", kGround, "wheel", Vec3::Zero(), "T3 ", {"z"}));
  testing::add_coordinate(m, "z", 0.3);
  ForceSpec w;
  w.name = "tyre";
  w.type = ForceSpec::Type::kWheelContact;
  w.body1 = "wheel";
  w.stiffness = 2e5;
  w.radius = 0.3;
  w.axis = Vec3(0, 1, 0);
  w.ground.kind = TimeFunction::Kind::kStep;
  w.ground.a = 0.0;
  w.ground.b = 0.1;
  w.ground.t0 = 0.2;
  m.forces.push_back(w);
  for (auto type : {SensorSpec::Type::kForceLength, SensorSpec::Type::kForceValue}) {
    SensorSpec s;
    s.name = type == SensorSpec::Type::kForceLength ? "length" : "force";
    s.type = type;
    s.target = "tyre";
    m.sensors.push_back(s);
  }
  return m;
}

TEST(ForceSensors, WheelContactLengthFollowsTheGroundAtTheSampleTime) {
  const System sys = build_system(wheel_on_a_step());
  const std::vector<double> q = sys.q0, v(sys.nq(), 0.0), a(sys.nq(), 0.0);
  std::vector<double> out(2);
  for (double t : {0.0, 0.5}) {
    const std::vector<char> modes = initial_modes(sys, q.data(), t);
    evaluate_sensors(sys, modes, q.data(), v.data(), a.data(), t, out.data());
    const double e = t < 0.2 ? 0.0 : 0.1;
    EXPECT_NEAR(out[0], e, 1e-12) << "t = " << t;
    EXPECT_NEAR(out[1], 2e5 * e, 1e-6) << "t = " << t;
  }
}

}  // namespace
}  // namespace mbdae
