// The mechanism as a user describes it (names, joint chains, points), before it is turned
// into Cartesian coordinates and constraints by build_system(). Plain data: the scene loader
// (cases/) fills it, tests build it directly.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "core/time_function.h"
#include "formulation/euler_parameters.h"

namespace mbdae {

// Where a value came from in a scene file, for error messages.
struct SourceLocation {
  std::string file;
  int line = 0;  // 1-based; 0 if unknown
};

inline constexpr const char* kGround = "ground";

struct BodySpec {
  std::string name;
  double mass = 0;
  Vec3 com = Vec3::Zero();              // in the body frame
  Mat3 inertia = Mat3::Zero();          // about the centre of mass, body axes
  std::map<std::string, Vec3> points;   // named points in the body frame
  SourceLocation where;
};

// One elementary joint of a Robotran chain: R1 R2 R3 rotate about the current x, y, z axis;
// T1 T2 T3 translate along it.
struct ElementaryJoint {
  bool rotation = true;
  int axis = 0;            // 0, 1, 2
  std::string coordinate;  // name of its joint coordinate
};

struct JointSpec {
  std::string name, parent, child;
  std::string anchor_point;            // a named point of the parent, or empty:
  Vec3 anchor = Vec3::Zero();          // anchor in the parent frame (used if no name)
  std::vector<ElementaryJoint> chain;  // empty chain = weld
  SourceLocation where;
};

struct CoordinateSpec {
  enum class Mode { kFree, kLocked, kDriven };
  std::string name;
  double initial = 0;  // SI units (rad or m); initial guess for assembly
  Mode mode = Mode::kFree;
  TimeFunction drive;  // for kDriven
  SourceLocation where;
};

// Loop-closure (cut) constraint between two bodies; "ground" is allowed as a body.
struct CutSpec {
  enum class Type { kBall, kRevolute, kUniversal, kPrismatic, kWeld, kDistance, kCylindrical };
  std::string name;
  Type type = Type::kBall;
  std::string body1, point1, body2, point2;
  Vec3 axis1 = Vec3::UnitZ(), axis2 = Vec3::UnitZ();  // body-frame axes (revolute: axis; ...)
  // Weld, prismatic: reference directions that complete the cut frames (z = axis, x = ref made
  // perpendicular to it); zero: the body axis most perpendicular to the cut's axis.
  Vec3 ref1 = Vec3::Zero(), ref2 = Vec3::Zero();
  double distance = 0;                                 // kDistance
  SourceLocation where;
};

// A force type: a handle to its row of the force-type table (formulation/force_types.h), which
// gives its scene fields, parameters, generalized force, potential, events, sensors and glyph.
// The built-in types have names here; a type added later is found by its scene name
// (find_force_type) and needs no line in this file.
struct ForceKind {
  int id = 0;  // its row in force_types()
  static const ForceKind kSpringDamper, kPointForce,
      kTorque,             // applied torque on a body about a world or body-fixed axis
      kJointSpringDamper,  // torque (force) k (q - q0) + c q' on a joint coordinate q
      kBushing,            // linear 6-DOF spring-damper between two body frames
      kWheelContact, kUser;
  bool operator==(const ForceKind& o) const { return id == o.id; }
  bool operator!=(const ForceKind& o) const { return id != o.id; }
};
inline constexpr ForceKind ForceKind::kSpringDamper{0}, ForceKind::kPointForce{1}, ForceKind::kTorque{2},
    ForceKind::kJointSpringDamper{3}, ForceKind::kBushing{4}, ForceKind::kWheelContact{5}, ForceKind::kUser{6};
// Numbers of a force type that has no named field below, placed by its table row.
inline constexpr int kForceCoefficients = 4;

struct ForceSpec {
  using Type = ForceKind;
  std::string name;
  Type type = Type::kSpringDamper;
  std::string body1, point1, body2, point2;
  // A point given as [x, y, z] in the body frame instead of a name (at_xyz1 / at_xyz2 set).
  Vec3 xyz1 = Vec3::Zero(), xyz2 = Vec3::Zero();
  bool at_xyz1 = false, at_xyz2 = false;
  // Spring-damper: tension = stiffness (length - free_length) + damping d(length)/dt.
  // Joint spring-damper: generalized force -(stiffness (q - free_length) + damping q') on q.
  double stiffness = 0, damping = 0, free_length = 0;
  // Point force: components fx fy fz in world axes, or in body1's axes if body_frame (a follower
  // force). Torque: magnitude fx about `axis` (world axes, or body1's axes if body_frame).
  TimeFunction fx, fy, fz;
  bool body_frame = false;
  // A component given as an expression (of t, sensors and `parameters`) instead of a function of
  // time: expression[k] not empty replaces fx / fy / fz.
  std::string expression[3];
  // Wheel contact: vertical force max(0, stiffness e), e = radius cos(camber) - (z - ground(t)),
  // at point1 of body1; axis = wheel spin axis in the body frame.
  double radius = 0;
  Vec3 axis = Vec3::UnitY();
  TimeFunction ground;
  // Joint spring-damper: the joint coordinate, and whether q - rest is wrapped to (-pi, pi]
  // (`wrap`; by default a rotation counts whole turns: formulation/system.h, CoordinateTurns).
  std::string coordinate;
  bool wrap = false;
  // Bushing: frame 1 at point1 with body1's axes, frame 2 at point2 with body2's axes; stiffness
  // and damping per frame-1 axis, translational (N/m, N s/m) and rotational (N m/rad, N m s/rad).
  Vec3 translational_stiffness = Vec3::Zero(), translational_damping = Vec3::Zero();
  Vec3 rotational_stiffness = Vec3::Zero(), rotational_damping = Vec3::Zero();
  // User force law: registered name and numeric parameters. Expression loads: named constants.
  std::string law;
  std::map<std::string, double> parameters;
  double coefficient[kForceCoefficients] = {0, 0, 0, 0};  // see kForceCoefficients
  SourceLocation where;
};

struct SensorSpec {
  enum class Type {
    kPosition, kVelocity, kAcceleration,  // of a body point, world component
    kAxis,                                // world component of a body-fixed unit vector
    kCoordinate, kCoordinateRate,         // joint coordinate and its rate
    kForceLength, kForceValue,            // length / tension of a force element
    kExpression,                          // derived from other sensors
    kKineticEnergy, kPotentialEnergy,     // whole system (formulation/sensors.cpp)
    kAngularVelocity,                     // of a body, world or body-axes component
    kAngularMomentum                      // of a body or the whole system about a world point
  };
  std::string name;
  Type type = Type::kPosition;
  std::string body, point, target;  // target: coordinate or force name
  Vec3 xyz = Vec3::Zero();          // the point as [x, y, z] in the body frame (if at_xyz)
  bool at_xyz = false;
  bool wrap = false;                // coordinate sensors: wrapped to (-pi, pi] instead of unwrapped
  bool body_frame = false;          // angular velocity: component in the body's axes (else world)
  Vec3 about = Vec3::Zero();        // angular momentum: the world point it is taken about
  // body empty for angular momentum: of the whole system.
  Vec3 axis = Vec3::UnitX();
  int component = 0;
  std::string expression;
  SourceLocation where;
};

struct Model {
  std::string name;
  Vec3 gravity = Vec3(0, 0, -9.81);
  std::vector<BodySpec> bodies;
  std::vector<JointSpec> joints;
  std::vector<CutSpec> cuts;
  std::vector<ForceSpec> forces;
  std::vector<SensorSpec> sensors;
  std::map<std::string, CoordinateSpec> coordinates;
  std::map<std::string, Vec3> ground_points;  // named points fixed in the world
};

}  // namespace mbdae
