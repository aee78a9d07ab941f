// Stage 5 of build_system(): force elements and sensors, their bodies, points and targets
// resolved.
#include <string>
#include <unordered_map>

#include "core/expression.h"
#include "formulation/forces.h"
#include "formulation/system_build.h"

namespace mbdae {

namespace {

// Names are looked up through hash maps, so that building stays linear in the number of names.
using NameIndex = std::unordered_map<std::string, int>;

int find_name(const NameIndex& names, const std::string& n) {
  const auto it = names.find(n);
  return it == names.end() ? -1 : it->second;
}

void add_forces(const ModelIndex& index, System& sys, NameIndex& force_of) {
  const Model& model = index.model;
  for (const auto& fs : model.forces) {
    Force f;
    f.type = fs.type;
    f.name = fs.name;
    auto [b1, p1] = point_of(index, sys, fs.body1, fs.point1, fs.where, "body1");
    f.bi = b1->body;
    f.si = p1;
    if (fs.type == ForceSpec::Type::kSpringDamper || fs.type == ForceSpec::Type::kUser) {
      auto [b2, p2] = point_of(index, sys, fs.body2, fs.point2, fs.where, "body2");
      f.bj = b2->body;
      f.sj = p2;
    }
    f.stiffness = fs.stiffness;
    f.damping = fs.damping;
    f.free_length = fs.free_length;
    f.fx = fs.fx;
    f.fy = fs.fy;
    f.fz = fs.fz;
    f.ground = fs.ground;
    f.radius = fs.radius;
    f.axis = b1->local_vector(fs.axis.normalized());
    if (fs.type == ForceSpec::Type::kWheelContact && f.bi < 0)
      fail(fs.where, "body1", "wheel contact on a body merged into ground");
    if (fs.type == ForceSpec::Type::kUser) {
      f.law = find_force_law(fs.law);
      if (!f.law) fail(fs.where, "law", "no force law named '" + fs.law + "' is registered");
      for (const auto& pname : f.law->parameter_names) {
        auto it = fs.parameters.find(pname);
        if (it == fs.parameters.end())
          fail(fs.where, "parameters", "force law '" + fs.law + "' needs parameter '" + pname + "'");
        f.parameters.push_back(it->second);
      }
    }
    if (!force_of.emplace(f.name, static_cast<int>(sys.forces.size())).second)
      fail(fs.where, "name", "force '" + f.name + "' is defined twice");
    sys.forces.push_back(f);
  }
}

void add_sensors(const ModelIndex& index, System& sys, const NameIndex& force_of) {
  const Model& model = index.model;
  NameIndex coordinate_of, sensor_of;
  for (size_t k = 0; k < sys.coordinates.size(); ++k) coordinate_of.emplace(sys.coordinates[k].name, static_cast<int>(k));
  for (const auto& ss : model.sensors) {
    Sensor s;
    s.type = ss.type;
    s.name = ss.name;
    s.component = ss.component;
    switch (ss.type) {
      case SensorSpec::Type::kPosition:
      case SensorSpec::Type::kVelocity:
      case SensorSpec::Type::kAcceleration: {
        auto [b, p] = point_of(index, sys, ss.body, ss.point, ss.where, "body");
        s.body = b->body;
        s.point = p;
        break;
      }
      case SensorSpec::Type::kAxis: {
        auto it = sys.frames.find(ss.body);
        if (it == sys.frames.end()) fail(ss.where, "body", "no body named '" + ss.body + "'");
        s.body = it->second.body;
        s.axis = it->second.local_vector(ss.axis);
        break;
      }
      case SensorSpec::Type::kCoordinate:
      case SensorSpec::Type::kCoordinateRate:
        s.target = find_name(coordinate_of, ss.target);
        if (s.target < 0) fail(ss.where, "coordinate", "no coordinate named '" + ss.target + "'");
        break;
      case SensorSpec::Type::kForceLength:
      case SensorSpec::Type::kForceValue:
        s.target = find_name(force_of, ss.target);
        if (s.target < 0) fail(ss.where, "force", "no force named '" + ss.target + "'");
        break;
      case SensorSpec::Type::kKineticEnergy:
      case SensorSpec::Type::kPotentialEnergy:
        break;  // whole-system quantities: nothing to resolve
      case SensorSpec::Type::kExpression: {
        try {  // sensor_of holds the sensors listed before this one
          s.expression = Expression::compile(ss.expression, [&](const std::string& n) { return find_name(sensor_of, n); });
        } catch (const ExpressionError& e) {
          fail(ss.where, "expression", std::string(e.what()) + " (names must be sensors listed before)");
        }
        break;
      }
    }
    if (!sensor_of.emplace(s.name, static_cast<int>(sys.sensors.size())).second)
      fail(ss.where, "name", "sensor '" + s.name + "' is defined twice");
    sys.sensors.push_back(s);
  }
}

}  // namespace

void add_forces_and_sensors(const ModelIndex& index, System& sys) {
  NameIndex force_of;
  add_forces(index, sys, force_of);
  add_sensors(index, sys, force_of);
}

}  // namespace mbdae
