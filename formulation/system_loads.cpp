// Stage 5 of build_system(): force elements and sensors, their bodies, points and targets
// resolved; then the expression components of loads, compiled against the sensors.
#include <algorithm>
#include <string>
#include <unordered_map>

#include "core/expression.h"
#include "formulation/force_types.h"
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

// Fields of the loads of issue 13: torque axis, bushing stiffness and damping, the coordinate of
// a load on a joint coordinate, named parameters of expression loads; the numbers of its row.
void add_load_fields(const ForceSpec& fs, const System& sys, const NameIndex& coordinate_of, Force& f) {
  const ForceType& row = force_type(fs.type);
  for (const ForceParameter& p : row.parameters)  // the accessor only takes the address
    *p.value(f) = *p.spec(const_cast<ForceSpec&>(fs));
  if (fs.type == ForceSpec::Type::kTorque && !fs.body_frame) f.axis = fs.axis.normalized();
  f.kt = fs.translational_stiffness;
  f.ct = fs.translational_damping;
  f.kr = fs.rotational_stiffness;
  f.cr = fs.rotational_damping;
  if (row.attach == ForceAttach::kCoordinate) {
    const int k = find_name(coordinate_of, fs.coordinate);
    if (k < 0) fail(fs.where, "coordinate", "no joint coordinate named '" + fs.coordinate + "'");
    f.coordinate = sys.coordinates[k].function;
    f.coordinate_index = k;
    f.wrap = fs.wrap;
    f.bi = f.coordinate.body_parent;
    f.bj = f.coordinate.body_child;
  }
  if (fs.type == ForceSpec::Type::kUser) return;
  for (const auto& [pname, value] : fs.parameters) {
    f.parameter_names.push_back(pname);
    f.parameters.push_back(value);
  }
}

// Bodies whose state sensor `s` reads (ground and merged coordinates read none).
void sensor_bodies(const System& sys, const Sensor& s, std::vector<int>& out) {
  switch (s.type) {
    case SensorSpec::Type::kCoordinate:
    case SensorSpec::Type::kCoordinateRate: {
      const JointCoordinate& jc = sys.coordinates[s.target];
      if (jc.merged) return;
      out.push_back(jc.function.body_parent);
      out.push_back(jc.function.body_child);
      return;
    }
    case SensorSpec::Type::kForceLength:
    case SensorSpec::Type::kForceValue:
      out.push_back(sys.forces[s.target].bi);
      out.push_back(sys.forces[s.target].bj);
      return;
    default: out.push_back(s.body); return;
  }
}

// The index of sensor `n` as a load input (variables: t, the parameters, then the inputs), with
// the sensor kinds whose gradient is known (sensors.cpp, sensor_gradient).
int load_variable(const System& sys, const NameIndex& sensor_of, const std::vector<char>& is_expression_load,
                  const std::string& n, Force& f) {
  const int np = static_cast<int>(f.parameter_names.size());
  if (n == "t") return 0;
  for (int k = 0; k < np; ++k)
    if (f.parameter_names[k] == n) return 1 + k;
  const int s = find_name(sensor_of, n);
  if (s < 0) return -1;
  using T = SensorSpec::Type;
  const Sensor& sensor = sys.sensors[s];
  if (sensor.type == T::kAcceleration || sensor.type == T::kExpression || sensor.type == T::kKineticEnergy ||
      sensor.type == T::kPotentialEnergy || (sensor.type == T::kAngularMomentum && sensor.whole_system))
    throw ExpressionError("sensor '" + n + "' cannot drive a load (loads read position, velocity, axis, "
                          "coordinate, coordinate_rate, force_length, force_value, angular_velocity and a "
                          "body's angular_momentum sensors)", 0);
  if ((sensor.type == T::kForceLength || sensor.type == T::kForceValue) && is_expression_load[sensor.target])
    throw ExpressionError("sensor '" + n + "' measures a load given by an expression (loads may not depend on each other)", 0);
  auto it = std::find(f.inputs.begin(), f.inputs.end(), s);
  if (it == f.inputs.end()) it = f.inputs.insert(f.inputs.end(), s);
  return 1 + np + static_cast<int>(it - f.inputs.begin());
}

// Compiles a load's expression components and lists the bodies they read.
void resolve_load_expressions(const ForceSpec& fs, const System& sys, const NameIndex& sensor_of,
                              const std::vector<char>& is_expression_load, Force& f) {
  if (fs.expression[0].empty() && fs.expression[1].empty() && fs.expression[2].empty()) return;
  for (const auto& pname : f.parameter_names)
    if (Expression::is_reserved(pname))
      fail(fs.where, "parameters." + pname, "'" + pname + "' is reserved in expressions (" + Expression::reserved_list() + ")");
  for (int c = 0; c < 3; ++c) {
    if (fs.expression[c].empty()) continue;
    const char* field = force_type(fs.type).components[c];
    if (!field) field = c == 0 ? "fx" : c == 1 ? "fy" : "fz";
    try {
      f.expression[c] = Expression::compile(fs.expression[c], [&](const std::string& n) {
        return load_variable(sys, sensor_of, is_expression_load, n, f);
      });
    } catch (const ExpressionError& e) {
      const std::string m = e.what();
      fail(fs.where, field, m.find("unknown name") == 0 ? m + " (names are t, the force's parameters and sensors)" : m);
    }
  }
  for (int s : f.inputs) sensor_bodies(sys, sys.sensors[s], f.reads);
  f.reads.erase(std::remove(f.reads.begin(), f.reads.end(), -1), f.reads.end());
  std::sort(f.reads.begin(), f.reads.end());
  f.reads.erase(std::unique(f.reads.begin(), f.reads.end()), f.reads.end());
  if (static_cast<int>(f.reads.size()) > kMaxLoadReads)
    fail(fs.where, "type", "the load's expressions read " + std::to_string(f.reads.size()) + " bodies (at most " +
                               std::to_string(kMaxLoadReads) + ")");
  if (1 + static_cast<int>(f.parameters.size() + f.inputs.size()) > kMaxLoadVariables)
    fail(fs.where, "parameters", "the load's expressions use more than " + std::to_string(kMaxLoadVariables) +
                                     " parameters and sensors");
}

void add_forces(const ModelIndex& index, System& sys, const NameIndex& coordinate_of, NameIndex& force_of) {
  const Model& model = index.model;
  for (const auto& fs : model.forces) {
    Force f;
    f.type = fs.type;
    f.name = fs.name;
    // A point given as [x, y, z] in the body frame, or by name.
    auto located = [&](const std::string& body, const std::string& name, bool at_xyz, const Vec3& xyz,
                       const std::string& field) {
      auto p = point_of(index, sys, body, at_xyz ? "" : name, fs.where, field);
      if (at_xyz) p.second = p.first->local_point(xyz);
      return p;
    };
    const ForceAttach attach = force_type(fs.type).attach;
    const bool on_coordinate = attach == ForceAttach::kCoordinate;  // no body point
    auto [b1, p1] = located(on_coordinate ? kGround : fs.body1, fs.point1, fs.at_xyz1, fs.xyz1, "body1");
    f.bi = b1->body;
    f.si = p1;
    if (attach == ForceAttach::kTwoPoints) {
      auto [b2, p2] = located(fs.body2, fs.point2, fs.at_xyz2, fs.xyz2, "body2");
      f.bj = b2->body;
      f.sj = p2;
      f.frame_j = b2->rotation;
    }
    f.frame_i = b1->rotation;
    f.body_frame = fs.body_frame;
    f.stiffness = fs.stiffness;
    f.damping = fs.damping;
    f.free_length = fs.free_length;
    f.fx = fs.fx;
    f.fy = fs.fy;
    f.fz = fs.fz;
    f.ground = fs.ground;
    f.radius = fs.radius;
    f.axis = b1->local_vector(fs.axis.normalized());
    add_load_fields(fs, sys, coordinate_of, f);
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
    force_of.emplace(f.name, static_cast<int>(sys.forces.size()));
    sys.forces.push_back(f);
  }
}

void add_sensors(const ModelIndex& index, System& sys, const NameIndex& coordinate_of, const NameIndex& force_of,
                 NameIndex& sensor_of) {
  const Model& model = index.model;
  for (const auto& ss : model.sensors) {
    Sensor s;
    s.type = ss.type;
    s.name = ss.name;
    s.component = ss.component;
    if (Expression::is_reserved(s.name))
      fail(ss.where, "name", "'" + s.name + "' is reserved in expressions (" + Expression::reserved_list() + ")");
    switch (ss.type) {
      case SensorSpec::Type::kPosition:
      case SensorSpec::Type::kVelocity:
      case SensorSpec::Type::kAcceleration: {
        auto [b, p] = point_of(index, sys, ss.body, ss.at_xyz ? "" : ss.point, ss.where, "body");
        s.body = b->body;
        s.point = ss.at_xyz ? b->local_point(ss.xyz) : p;
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
        s.unwrap = ss.type == SensorSpec::Type::kCoordinate && !ss.wrap && sys.coordinates[s.target].function.rotation;
        s.reference = sys.coordinates[s.target].spec.initial;
        break;
      case SensorSpec::Type::kForceLength:
      case SensorSpec::Type::kForceValue:
        s.target = find_name(force_of, ss.target);
        if (s.target < 0) fail(ss.where, "force", "no force named '" + ss.target + "'");
        break;
      case SensorSpec::Type::kKineticEnergy:
      case SensorSpec::Type::kPotentialEnergy:
        break;  // whole-system quantities: nothing to resolve
      case SensorSpec::Type::kAngularVelocity:
      case SensorSpec::Type::kAngularMomentum: {
        s.whole_system = ss.type == SensorSpec::Type::kAngularMomentum && ss.body.empty();
        if (s.whole_system) {
          s.point = ss.about;
          break;
        }
        auto it = sys.frames.find(ss.body);
        if (it == sys.frames.end()) fail(ss.where, "body", "no body named '" + ss.body + "'");
        s.body = it->second.body;
        s.point = ss.about;
        // Body-axes components of the named body: its axis `component` in its host's local axes.
        s.body_frame = ss.type == SensorSpec::Type::kAngularVelocity && ss.body_frame;
        s.axis = s.body_frame ? it->second.local_vector(Vec3::Unit(ss.component)) : Vec3(Vec3::Unit(ss.component));
        break;
      }
      case SensorSpec::Type::kExpression: {
        try {  // sensor_of holds the sensors listed before this one
          s.expression = Expression::compile(ss.expression, [&](const std::string& n) { return find_name(sensor_of, n); });
        } catch (const ExpressionError& e) {
          fail(ss.where, "expression", std::string(e.what()) + " (names must be sensors listed before)");
        }
        break;
      }
    }
    sensor_of.emplace(s.name, static_cast<int>(sys.sensors.size()));
    sys.sensors.push_back(s);
  }
}

}  // namespace

void add_forces_and_sensors(const ModelIndex& index, System& sys) {
  NameIndex coordinate_of, force_of, sensor_of;
  for (size_t k = 0; k < sys.coordinates.size(); ++k) coordinate_of.emplace(sys.coordinates[k].name, static_cast<int>(k));
  add_forces(index, sys, coordinate_of, force_of);
  add_sensors(index, sys, coordinate_of, force_of, sensor_of);
  // Load expressions last: they read sensors, and sensors may measure forces.
  std::vector<char> is_expression_load;
  for (const auto& fs : index.model.forces)
    is_expression_load.push_back(!fs.expression[0].empty() || !fs.expression[1].empty() || !fs.expression[2].empty());
  for (size_t k = 0; k < index.model.forces.size(); ++k)
    resolve_load_expressions(index.model.forces[k], sys, sensor_of, is_expression_load, sys.forces[k]);
}

}  // namespace mbdae
