// The mechanism in absolute coordinates: what the solvers work on.
//
// build_system() turns a Model into moving bodies (each with 7 coordinates: centre of mass r and
// Euler parameters p), scalar constraint equations, force elements and sensors. Tree joints whose
// coordinates are all locked (and welds) are not constraints: the child is merged into its parent
// (a rigid composite; a body merged into ground is not a body at all). Every other joint chain
// becomes the equivalent Cartesian constraints, plus a coordinate constraint for each locked or
// driven coordinate of the chain.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/expression.h"
#include "formulation/constraints.h"
#include "formulation/model.h"

namespace mbdae {

struct SystemBody {
  std::string name;  // the host's name (its merged bodies listed in `merged`)
  double mass = 0;
  Mat3 inertia = Mat3::Zero();  // about the centre of mass, in the body's axes
  std::vector<std::string> merged;
};

// Where an original body of the model lives: on host body `body` (-1 = ground), with
// x_local = rotation * x_body + offset (local = host centre-of-mass coordinates, world for ground).
struct BodyFrame {
  int body = -1;
  Mat3 rotation = Mat3::Identity();
  Vec3 offset = Vec3::Zero();
  Vec3 local_point(const Vec3& s) const { return rotation * s + offset; }
  Vec3 local_vector(const Vec3& a) const { return rotation * a; }
};

// A joint coordinate: measured from the bodies (a function), or constant if its joint was merged.
struct JointCoordinate {
  std::string name, joint;
  bool merged = false;
  double value_if_merged = 0;
  CoordinateFunction function;
  CoordinateSpec spec;
};

struct UserForceLaw;  // formulation/forces.h

struct Force {
  ForceSpec::Type type = ForceSpec::Type::kSpringDamper;
  std::string name;
  int bi = -1, bj = -1;
  Vec3 si = Vec3::Zero(), sj = Vec3::Zero();
  double stiffness = 0, damping = 0, free_length = 0;
  TimeFunction fx, fy, fz, ground;
  double radius = 0;
  Vec3 axis = Vec3::UnitY();  // wheel spin axis in local coordinates
  const UserForceLaw* law = nullptr;
  std::vector<double> parameters;
  // Point force and torque: components in body axes (frame_i: body1's axes in local coordinates).
  bool body_frame = false;
  Mat3 frame_i = Mat3::Identity(), frame_j = Mat3::Identity();
  // Joint spring-damper: the coordinate it acts on (bi = its parent body, bj = its child body),
  // its index in System::coordinates, and whether q - rest is wrapped to (-pi, pi] (`wrap`) or
  // counted over whole turns (the default; CoordinateTurns).
  CoordinateFunction coordinate;
  int coordinate_index = -1;
  bool wrap = false;
  // Bushing: stiffness and damping per frame-1 axis (si, sj: the frames' origins).
  Vec3 kt = Vec3::Zero(), ct = Vec3::Zero(), kr = Vec3::Zero(), cr = Vec3::Zero();
  double coefficient[kForceCoefficients] = {0, 0, 0, 0};  // the type's other numbers (model.h)
  // Components given by expressions (empty: fx, fy, fz). Their variables are t (index 0), the
  // parameters (1 ...) and then the values of the sensors `inputs` (indices into System::sensors);
  // `reads` lists the bodies those sensors depend on (ascending, at most kMaxLoadReads).
  Expression expression[3];
  std::vector<std::string> parameter_names;
  std::vector<int> inputs, reads;
  bool has_expression() const {
    return !expression[0].empty() || !expression[1].empty() || !expression[2].empty();
  }
};
inline constexpr int kMaxLoadReads = 8;
inline constexpr int kMaxLoadVariables = 48;  // t, parameters and sensors of one load

struct Sensor {
  SensorSpec::Type type = SensorSpec::Type::kPosition;
  std::string name;
  int body = -1;
  Vec3 point = Vec3::Zero(), axis = Vec3::UnitX();
  int component = 0;
  int target = -1;  // coordinate or force index
  Expression expression;
  // Rotation coordinate sensors: continuous along a run (multi-turn) unless the scene asks for
  // `wrap`; without a previous sample the value is taken nearest to `reference` (the initial value).
  bool unwrap = false;
  double reference = 0;
  // Angular velocity: the value is axis . omega, omega in world axes, or in the body's local axes
  // (body_frame; axis then maps them to the named body's own axes). Angular momentum: about the
  // world point `point`, world component `component`, of body `body` or of every body (whole_system).
  bool body_frame = false, whole_system = false;
};

struct System {
  std::string name;
  Vec3 gravity = Vec3::Zero();
  std::vector<SystemBody> bodies;
  std::map<std::string, BodyFrame> frames;  // every original body (and "ground")
  std::vector<Constraint> constraints;
  std::vector<JointCoordinate> coordinates;
  std::vector<Force> forces;
  std::vector<Sensor> sensors;
  std::vector<double> q0;  // initial guess from the joint coordinates' initial values
  // The coordinates whose turns a run tracks (update_turns): those counting turns that a joint
  // force (not wrapped) or an unwrapped coordinate sensor reads. Set by build_system.
  std::vector<int> turn_coordinates;

  int num_bodies() const { return static_cast<int>(bodies.size()); }
  int nq() const { return 7 * num_bodies(); }
  int num_constraint_rows() const;
  int coordinate_index(const std::string& name) const;  // -1 if none
  int force_index(const std::string& name) const;
  // Every time at which a driver, force or ground profile is not smooth.
  std::vector<double> breakpoints() const;
};

// Throws ModelError (with the scene location) at the first problem check_model() finds
// (formulation/model_rules.h: the rules the loader reports in full).
System build_system(const Model& model);

// A constraint holding joint coordinate `k` at `value` (for assembly with independent
// coordinates held, and for equilibrium).
Constraint hold_constraint(const System& sys, int k, double value);

// The current value of a joint coordinate (a rotation measured in (-pi, pi]: see CoordinateTurns).
double coordinate_value(const System& sys, int k, const double* q);
double coordinate_rate(const System& sys, int k, const double* q, const double* v);

// Whole turns of rotation coordinates. Euler parameters repeat after two turns, so a rotation
// coordinate measured from them (coordinate_jet) is known only modulo 2 pi. The continuous
// (multi-turn) value is the branch nearest to value[k] + rate[k] (t - time), the continuous
// value and rate at the last accepted step (MultibodyDae::turns, updated after every accepted
// step and restart): right while the coordinate moves less than pi away from that prediction
// within one step. Without a CoordinateTurns the branch nearest to the coordinate's initial
// value is taken (static analyses, the initial state).
struct CoordinateTurns {
  std::vector<double> value, rate;  // per System::coordinates entry
  double time = 0;
  bool timed = false;  // false: the prediction is value[k] (no rate yet)
};
// Whether coordinate k is a rotation whose turns are counted (atan2 angles: the first and last of a
// chain's rotations; the middle one, an asin, stays within [-pi/2, pi/2]).
bool counts_turns(const System& sys, int k);
// System::turn_coordinates of sys as it stands (its forces and sensors).
std::vector<int> coordinates_with_turns(const System& sys);
// The continuous value of coordinate k from its measured value `raw` at time t.
double continuous_coordinate(const System& sys, int k, double raw, double t, const CoordinateTurns* turns);
// Turns at the start (value: the coordinates' initial values, no rate).
CoordinateTurns initial_turns(const System& sys);
// The continuous values and rates at an accepted state (q, v) at t.
void update_turns(const System& sys, const double* q, const double* v, double t, CoordinateTurns& turns);

}  // namespace mbdae
