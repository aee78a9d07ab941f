// Reading sensors.
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


void Loader::sensor(const YAML::Node& n, Model& m) {
  static const Fields general = {"name", "type", "body", "point", "component", "axis", "coordinate", "force",
                                 "expression", "wrap", "frame", "about"};
  if (!check_keys(n, "sensor", general)) return;
  SensorSpec s;
  s.where = where(n);
  s.name = name(n);
  if (Expression::is_reserved(s.name))
    error(n["name"], "name", quote(s.name) + " is reserved in expressions (reserved: " + Expression::reserved_list() +
                                 "); choose another sensor name");
  const std::string type = text(n, "type", "", true);
  using T = SensorSpec::Type;
  static const std::map<std::string, T> types = {
      {"position", T::kPosition}, {"velocity", T::kVelocity}, {"acceleration", T::kAcceleration},
      {"axis", T::kAxis}, {"coordinate", T::kCoordinate}, {"coordinate_rate", T::kCoordinateRate},
      {"force_length", T::kForceLength}, {"force_value", T::kForceValue}, {"expression", T::kExpression},
      {"kinetic_energy", T::kKineticEnergy}, {"potential_energy", T::kPotentialEnergy},
      {"angular_velocity", T::kAngularVelocity}, {"angular_momentum", T::kAngularMomentum}};
  auto it = types.find(type);
  if (it == types.end()) {
    if (!type.empty()) {
      Fields known;
      for (const auto& kv : types) known.push_back(kv.first);
      error(n["type"], "type", "unknown sensor type " + quote(type) + " (" + join(known) + ")" + did_you_mean(type, known));
    }
    // Keep the name (as an empty expression, which nothing checks) so that output columns and
    // expressions naming this sensor are not reported as well; the scene is rejected anyway.
    s.type = T::kExpression;
    if (!s.name.empty()) m.sensors.push_back(s);
    return;
  }
  s.type = it->second;
  sensor_fields(n, type, general, s);
  m.sensors.push_back(s);
}

// The fields of sensor `s` of the given (known) type.
void Loader::sensor_fields(const YAML::Node& n, const std::string& type, const Fields& general, SensorSpec& s) {
  using T = SensorSpec::Type;
  const std::string what = "a " + type + " sensor";
  switch (s.type) {
    case T::kPosition: case T::kVelocity: case T::kAcceleration:
      applies(n, what, general, {"name", "type", "body", "point", "component"});
      s.body = name(n, "body");
      body_point(n, "point", s.point, s.xyz, s.at_xyz);
      s.component = axis_component(n, "component");
      break;
    case T::kAxis:
      applies(n, what, general, {"name", "type", "body", "axis", "component"});
      s.body = name(n, "body");
      s.axis = vec3(n, "axis", Vec3::UnitX(), true);
      if (has(n, "axis") && s.axis.norm() == 0) error(n["axis"], "axis", "must not be zero");
      s.component = axis_component(n, "component");
      break;
    case T::kCoordinate: case T::kCoordinateRate:
      applies(n, what, general, {"name", "type", "coordinate", "wrap"});
      s.target = name(n, "coordinate");
      flag(n, "wrap", s.wrap);
      if (has(n, "wrap") && s.type == T::kCoordinateRate)
        error(n["wrap"], "wrap", "does not apply to a coordinate_rate sensor (rates are not wrapped)");
      break;
    case T::kForceLength: case T::kForceValue:
      applies(n, what, general, {"name", "type", "force"});
      s.target = name(n, "force");
      break;
    case T::kExpression:
      applies(n, what, general, {"name", "type", "expression"});
      s.expression = name(n, "expression");
      break;
    case T::kAngularVelocity: {
      applies(n, what, general, {"name", "type", "body", "component", "frame"});
      s.body = name(n, "body");
      s.component = axis_component(n, "component");
      const std::string fr = text(n, "frame", "world");
      s.body_frame = fr == "body";
      if (fr != "world" && fr != "body" && n["frame"].IsScalar())
        error(n["frame"], "frame", "expected world or body, got " + quote(fr));
      break;
    }
    case T::kAngularMomentum:
      applies(n, what, general, {"name", "type", "body", "component", "about"});
      if (has(n, "body")) s.body = name(n, "body");  // absent: the whole system
      s.about = vec3(n, "about", Vec3::Zero());
      s.component = axis_component(n, "component");
      break;
    default:  // whole-system sensors
      applies(n, what, general, {"name", "type"});
      break;
  }
}

}  // namespace mbdae::scene_load
