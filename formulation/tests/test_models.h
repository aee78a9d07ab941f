// Small models shared by the formulation tests, built in code (no scene files).
#pragma once

#include "formulation/model.h"

namespace mbdae::testing {

inline BodySpec make_body(const std::string& name, double mass, const Vec3& com, const Vec3& diag,
                          const Vec3& offdiag = Vec3::Zero()) {
  BodySpec b;
  b.name = name;
  b.mass = mass;
  b.com = com;
  b.inertia << diag[0], offdiag[0], offdiag[2], offdiag[0], diag[1], offdiag[1], offdiag[2],
      offdiag[1], diag[2];
  return b;
}

inline JointSpec make_joint(const std::string& name, const std::string& parent,
                            const std::string& child, const Vec3& anchor, const std::string& chain,
                            const std::vector<std::string>& coords) {
  JointSpec j;
  j.name = name;
  j.parent = parent;
  j.child = child;
  j.anchor = anchor;
  for (size_t k = 0; k < coords.size(); ++k) {
    ElementaryJoint e;
    e.rotation = chain[3 * k] == 'R';
    e.axis = chain[3 * k + 1] - '1';
    e.coordinate = coords[k];
    j.chain.push_back(e);
  }
  return j;
}

inline void add_coordinate(Model& m, const std::string& name, double initial,
                           CoordinateSpec::Mode mode = CoordinateSpec::Mode::kFree) {
  CoordinateSpec c;
  c.name = name;
  c.initial = initial;
  c.mode = mode;
  m.coordinates[name] = c;
}

// A compound pendulum on a revolute joint (R1) at the origin, centre of mass at (0, 0, -d).
inline Model pendulum(double mass, double d, double ixx, double theta0) {
  Model m;
  m.name = "pendulum";
  m.bodies.push_back(make_body("bob", mass, Vec3(0, 0, -d), Vec3(ixx, ixx, 0.3 * ixx)));
  m.joints.push_back(make_joint("pivot", kGround, "bob", Vec3::Zero(), "R1 ", {"theta"}));
  add_coordinate(m, "theta", theta0);
  return m;
}

}  // namespace mbdae::testing
