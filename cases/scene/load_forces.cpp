// Reading forces: the fields of each type from its row of the force-type table
// (formulation/force_types.h), read here by the type's reader or from the row alone.
#include "cases/scene/loader.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <unordered_map>
#include <sstream>
#include "cases/scene/field_ranges.h"
#include "cases/scene/analysis_types.h"
#include "cases/scene/scene.h"
#include "cases/scene/scene_overrides.h"
#include "cases/scene/scene_validation.h"
#include "core/errors.h"
#include "core/expression.h"
#include "formulation/formulation_registry.h"

namespace mbdae::scene_load {

// A load component: a function of time (number or mapping) or an expression (other text).
void Loader::load_component(const YAML::Node& n, const char* key, TimeFunction& f, std::string& expression) {
  if (!has(n, key)) return;
  const YAML::Node v = n[key];
  record(n, key, v);
  if (v.IsScalar()) {
    const std::string& text = v.Scalar();
    char* end = nullptr;
    std::strtod(text.c_str(), &end);
    const bool number = !text.empty() && end == text.c_str() + text.size() &&
                        !std::isspace(static_cast<unsigned char>(text[0]));
    const bool special = !text.empty() && text[0] == '.';  // .nan, .inf: reported as numbers
    if (!number && !special && !text.empty()) {
      expression = text;
      return;
    }
  }
  f = function(v, key);
}

void Loader::three(const YAML::Node& n, const char* key, Vec3& out, const char* unit) {
  if (!has(n, key)) return;
  out = vec3(n, key, Vec3::Zero());
  if (out.minCoeff() < 0) error(n[key], key, std::string("must not be negative (") + unit + ")");
}

void Loader::force_parameters(const YAML::Node& n, ForceSpec& f) {
  if (!has(n, "parameters")) return;
  const YAML::Node p = n["parameters"];
  record(n, "parameters", p);
  if (!p.IsMap()) {
    error(p, "parameters", "expected a mapping name: number, got " + describe(p));
    return;
  }
  for (const auto& kv : p) {
    const auto pname = key_of(kv.first, "parameters");
    if (!pname) continue;
    lines->add(f.where, "parameters." + *pname, line_of(kv.first));
    if (f.parameters.count(*pname)) error(kv.first, "parameters." + *pname, "given twice");
    else if (f.type != ForceSpec::Type::kUser && Expression::is_reserved(*pname))
      error(kv.first, "parameters." + *pname, quote(*pname) + " is reserved in expressions (reserved: " +
                                                  Expression::reserved_list() + ")");
    else if (const auto x = to_number(kv.second, "parameters." + *pname)) f.parameters[*pname] = *x;
  }
}

void Loader::frame(const YAML::Node& n, ForceSpec& f) {
  const std::string fr = text(n, "frame", "world");
  if (fr == "body") f.body_frame = true;
  else if (fr != "world" && n["frame"].IsScalar()) error(n["frame"], "frame", "expected world or body, got " + quote(fr));
}


// Number fields of a force, checked as they are read.
void Loader::non_negative(const YAML::Node& n, const char* key, double& out, bool required) {
  const auto x = opt_number(n, key, required);
  if (x) out = *x;
  if (x && *x < 0) error(n[key], key, "must not be negative, got " + format_number(*x));
}

void Loader::positive(const YAML::Node& n, const char* key, double& out) {
  const auto x = opt_number(n, key, true);
  if (x) out = *x;
  if (x && !(*x > 0)) error(n[key], key, "must be positive, got " + format_number(*x));
}

void Loader::two_points(const YAML::Node& n, ForceSpec& f) {
  f.body1 = name(n, "body1");
  body_point(n, "point1", f.point1, f.xyz1, f.at_xyz1);
  f.body2 = name(n, "body2");
  body_point(n, "point2", f.point2, f.xyz2, f.at_xyz2);
}


// The readers of the built-in types (force_readers() below).
void Loader::spring_damper(const YAML::Node& n, ForceSpec& f) {
  two_points(n, f);
  non_negative(n, "stiffness", f.stiffness, true);
  non_negative(n, "damping", f.damping, false);
  non_negative(n, "free_length", f.free_length, false);
}

void Loader::point_force(const YAML::Node& n, ForceSpec& f) {
  f.body1 = name(n, "body");
  body_point(n, "point", f.point1, f.xyz1, f.at_xyz1);
  frame(n, f);
  load_component(n, "fx", f.fx, f.expression[0]);
  load_component(n, "fy", f.fy, f.expression[1]);
  load_component(n, "fz", f.fz, f.expression[2]);
  force_parameters(n, f);
}

void Loader::torque(const YAML::Node& n, ForceSpec& f) {
  f.body1 = name(n, "body");
  frame(n, f);
  f.axis = vec3(n, "axis", Vec3::UnitZ(), true);
  if (has(n, "axis") && f.axis.norm() == 0) error(n["axis"], "axis", "must not be zero");
  if (!has(n, "torque")) error(n, "torque", "missing (a number, a function of time or an expression)");
  load_component(n, "torque", f.fx, f.expression[0]);
  force_parameters(n, f);
}

void Loader::joint_spring_damper(const YAML::Node& n, ForceSpec& f) {
  f.coordinate = name(n, "coordinate");
  non_negative(n, "stiffness", f.stiffness, true);
  non_negative(n, "damping", f.damping, false);
  if (has(n, "rest") && has(n, "rest_deg")) error(n["rest_deg"], "rest_deg", "give rest or rest_deg, not both");
  if (has(n, "rest")) f.free_length = number(n, "rest", 0.0);
  else if (has(n, "rest_deg")) f.free_length = number(n, "rest_deg", 0.0) * kDeg;
  flag(n, "wrap", f.wrap);
}

void Loader::bushing(const YAML::Node& n, ForceSpec& f) {
  two_points(n, f);
  if (!has(n, "stiffness") && !has(n, "rotational_stiffness"))
    error(n, "stiffness", "missing (a bushing needs stiffness and/or rotational_stiffness, [x, y, z] each)");
  three(n, "stiffness", f.translational_stiffness, "N/m per frame-1 axis");
  three(n, "damping", f.translational_damping, "N s/m per frame-1 axis");
  three(n, "rotational_stiffness", f.rotational_stiffness, "N m/rad per frame-1 axis");
  three(n, "rotational_damping", f.rotational_damping, "N m s/rad per frame-1 axis");
}

void Loader::wheel_contact(const YAML::Node& n, ForceSpec& f) {
  f.body1 = name(n, "body");
  body_point(n, "point", f.point1, f.xyz1, f.at_xyz1);
  positive(n, "stiffness", f.stiffness);
  positive(n, "radius", f.radius);
  f.axis = vec3(n, "axis", Vec3::UnitY());
  if (f.axis.norm() == 0) error(n["axis"], "axis", "must not be zero");
  if (has(n, "ground")) f.ground = function(n["ground"], "ground");
}

void Loader::user_force(const YAML::Node& n, ForceSpec& f) {
  two_points(n, f);
  f.law = name(n, "law");
  force_parameters(n, f);
}

void Loader::table_force(const YAML::Node& n, const ForceType& row, ForceSpec& f) {
  switch (row.attach) {
    case ForceAttach::kTwoPoints: two_points(n, f); break;
    case ForceAttach::kBodyPoint:
      f.body1 = name(n, "body");
      body_point(n, "point", f.point1, f.xyz1, f.at_xyz1);
      break;
    case ForceAttach::kBody: f.body1 = name(n, "body"); break;
    case ForceAttach::kCoordinate: f.coordinate = name(n, "coordinate"); break;
  }
  for (const ForceParameter& p : row.parameters) {
    const auto x = opt_number(n, p.name, p.required);
    if (!x) continue;
    *p.spec(f) = *x;
    if (p.range == ParameterRange::kNonNegative && *x < 0)
      error(n[p.name], p.name, "must not be negative, got " + format_number(*x));
    if (p.range == ParameterRange::kPositive && !(*x > 0))
      error(n[p.name], p.name, "must be positive, got " + format_number(*x));
  }
}

const std::map<std::string, Loader::ForceReader>& Loader::force_readers() {
  static const std::map<std::string, ForceReader> readers = {
      {"spring_damper", &Loader::spring_damper}, {"point_force", &Loader::point_force},
      {"torque", &Loader::torque}, {"joint_spring_damper", &Loader::joint_spring_damper},
      {"bushing", &Loader::bushing}, {"wheel_contact", &Loader::wheel_contact}, {"user", &Loader::user_force}};
  return readers;
}

namespace {
// Every field of some force type: the built-in ones in the order messages have always listed
// them, then those of types added to the table since.
const Fields& general_force_fields() {
  static const Fields general = [] {
    Fields g = {"name", "type", "body1", "point1", "body2", "point2", "body", "point",
                "stiffness", "damping", "free_length", "fx", "fy", "fz", "radius", "axis",
                "ground", "law", "parameters", "frame", "torque", "coordinate", "rest",
                "rest_deg", "rotational_stiffness", "rotational_damping", "wrap"};
    for (const ForceType* t : force_types())
      for (const std::string& field : t->fields)
        if (!contains(g, field)) g.push_back(field);
    return g;
  }();
  return general;
}
}  // namespace

void Loader::force(const YAML::Node& n, Model& m) {
  const Fields& general = general_force_fields();
  if (!check_keys(n, "force", general)) return;
  ForceSpec f;
  f.where = where(n);
  f.name = name(n);
  const std::string type = text(n, "type", "", true);
  const ForceKind kind = find_force_type(type);
  if (kind.id >= 0) {
    const ForceType& row = force_type(kind);
    applies(n, "a " + type + " force", general, row.fields);
    f.type = kind;
    const auto reader = force_readers().find(type);
    if (reader != force_readers().end()) (this->*(reader->second))(n, f);
    else table_force(n, row, f);
  } else if (!type.empty()) {
    error(n["type"], "type", "unknown force type " + quote(type) + " (" + force_type_names() + ")");
  }
  m.forces.push_back(f);
}

}  // namespace mbdae::scene_load
