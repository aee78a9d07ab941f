// The force-type table: one row per force type, in the manner of SUNDIALS' tables of
// operations. A row gives the type's scene name and fields, its numeric parameters (unit, range,
// where they are kept), its generalized force with exact Jacobians, its potential energy, its
// switching function (events), its length and magnitude for sensors and its animation glyph.
// The loader, the scene validation, the parameter units, the build, the sensors and the animation
// read the rows; formulation/forces.cpp dispatches through them. Each built-in law is one file in
// formulation/forces/; adding a type is one such file and one line in force_types.cpp
// (docs/architecture.md, "Adding a force type").
#pragma once

#include <string>
#include <vector>

#include "formulation/forces.h"

namespace mbdae {

// What a force acts on. It decides the scene fields that name bodies, points or a coordinate
// (body1/point1/body2/point2, body/point, body, coordinate), how the build resolves them and which
// reference checks the validation makes.
enum class ForceAttach { kTwoPoints, kBodyPoint, kBody, kCoordinate };

// How the animation draws a force: not at all (torques, loads on coordinates), as a line between
// its points carrying its value, as a vector at its point, or as a vector plus the ground under it.
enum class ForceGlyph { kNone, kLine, kVector, kWheel };

enum class ParameterRange { kAny, kNonNegative, kPositive };

// A numeric scene field of a force type, and the value the build gives its Force.
struct ForceParameter {
  const char* name;              // scene field; `force.name` for equilibrium unknowns and overrides
  const char* unit;              // SI unit (on a coordinate: for a rotation coordinate)
  const char* unit_translation;  // on a coordinate: for a translation coordinate (else unused)
  ParameterRange range;
  bool required;
  bool solvable;                 // may be an equilibrium step's unknown
  double* (*spec)(ForceSpec&);   // where the loader puts it
  double* (*value)(Force&);      // where the build puts it (and force_parameter finds it)
};

using ForceEvalFn = void (*)(const Force& f, const LocalState& x, const LocalState& v, double t, bool in_contact,
                             Vec14& q, Mat14* dq_dx, Mat14* dq_dv, const LoadInput* in, Mat14x3* dq_din);
using ForceLengthFn = double (*)(const Force& f, const LocalState& x, double t);
using ForceMagnitudeFn = double (*)(const Force& f, const LocalState& x, const LocalState& v, double t,
                                    bool in_contact, const LoadInput* in);
using ForcePotentialFn = double (*)(const Force& f, const LocalState& x, double t, bool in_contact,
                                    const LoadInput* in);
using ForceSwitchFn = double (*)(const Force& f, const LocalState& x, double t);

struct ForceType {
  const char* name;                     // the scene's `type`
  ForceAttach attach;
  std::vector<std::string> fields;      // every scene field it takes (name and type included)
  std::vector<ForceParameter> parameters;
  const char* components[3];            // fields of its expression components (null: none)
  ForceGlyph glyph;
  const char* length_unit;              // sensors force_length and force_value (on a coordinate:
  const char* value_unit;               //   for a rotation; m and N for a translation)
  ForceEvalFn eval;                     // generalized force and exact Jacobians (forces.h)
  ForceLengthFn length;
  ForceMagnitudeFn magnitude;
  ForcePotentialFn potential;           // null: stores no energy
  ForceSwitchFn switch_value;           // null: no events (a mode switched by the root of this)
};

// The rows, in ForceKind order (a built-in ForceKind is its row's index).
const std::vector<const ForceType*>& force_types();
const ForceType& force_type(ForceKind kind);
// The kind whose scene name is `name`; id -1 if none.
ForceKind find_force_type(const std::string& name);
// "a, b, c": the scene names, for messages.
std::string force_type_names();
// The unit of a force_length (length) or force_value sensor of f.
std::string force_sensor_unit(const Force& f, bool length);
// The parameter of the row named `name`, or null.
const ForceParameter* find_force_parameter(const ForceType& type, const std::string& name);

}  // namespace mbdae
