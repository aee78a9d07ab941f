// YAML scene loader. Every problem is recorded with its file, line and field, and loading goes
// on so that all problems of a file are reported at once.
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "cases/scene.h"
#include "core/errors.h"

namespace mbdae {

SceneError::SceneError(std::vector<std::string> m)
    : std::runtime_error([&] {
        std::string s;
        for (const auto& x : m) s += (s.empty() ? "" : "\n") + x;
        return s;
      }()),
      messages(std::move(m)) {}

namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

struct Loader {
  std::string file;
  std::vector<std::string>* errors;

  SourceLocation where(const YAML::Node& n) const {
    return SourceLocation{file, n.Mark().line >= 0 ? n.Mark().line + 1 : 0};
  }
  void error(const YAML::Node& n, const std::string& field, const std::string& msg) {
    const SourceLocation w = where(n);
    errors->push_back(ModelError::format(w.file, w.line, field, msg));
  }
  // Reports keys of a mapping that are not in `allowed`.
  bool check_keys(const YAML::Node& n, const std::string& what, std::initializer_list<const char*> allowed) {
    if (!n.IsMap()) {
      error(n, what, "expected a mapping");
      return false;
    }
    for (const auto& kv : n) {
      const std::string key = kv.first.as<std::string>();
      bool ok = false;
      for (const char* a : allowed) ok = ok || key == a;
      if (!ok) {
        std::string list;
        for (const char* a : allowed) list += std::string(list.empty() ? "" : ", ") + a;
        error(kv.first, key, "unknown field in " + what + " (expected one of: " + list + ")");
      }
    }
    return true;
  }
  bool has(const YAML::Node& n, const char* key) const { return n.IsMap() && n[key]; }

  double number(const YAML::Node& parent, const char* key, double fallback, bool required = false) {
    if (!has(parent, key)) {
      if (required) error(parent, key, "missing");
      return fallback;
    }
    const YAML::Node v = parent[key];
    return as_number(v, key, fallback);
  }
  double as_number(const YAML::Node& v, const std::string& field, double fallback) {
    if (!v.IsScalar()) {
      error(v, field, "expected a number");
      return fallback;
    }
    const std::string s = v.Scalar();
    try {
      size_t used = 0;
      const double x = std::stod(s, &used);
      if (used != s.size()) throw std::invalid_argument(s);
      if (!std::isfinite(x)) {
        error(v, field, "'" + s + "' is not a finite number");
        return fallback;
      }
      return x;
    } catch (const std::exception&) {
      error(v, field, "expected a number, got '" + s + "'");
      return fallback;
    }
  }
  std::string text(const YAML::Node& parent, const char* key, const std::string& fallback, bool required = false) {
    if (!has(parent, key)) {
      if (required) error(parent, key, "missing");
      return fallback;
    }
    const YAML::Node v = parent[key];
    if (!v.IsScalar()) {
      error(v, key, "expected text");
      return fallback;
    }
    return v.Scalar();
  }
  Vec3 vec3(const YAML::Node& parent, const char* key, const Vec3& fallback, bool required = false) {
    if (!has(parent, key)) {
      if (required) error(parent, key, "missing");
      return fallback;
    }
    const YAML::Node v = parent[key];
    if (!v.IsSequence() || v.size() != 3) {
      error(v, key, "expected a list of 3 numbers");
      return fallback;
    }
    Vec3 out;
    for (int k = 0; k < 3; ++k) out[k] = as_number(v[k], key, fallback[k]);
    return out;
  }
  std::vector<std::string> names(const YAML::Node& parent, const char* key) {
    std::vector<std::string> out;
    if (!has(parent, key)) return out;
    const YAML::Node v = parent[key];
    if (v.IsScalar()) return {v.Scalar()};
    if (!v.IsSequence()) {
      error(v, key, "expected a list of names");
      return out;
    }
    for (const auto& x : v) {
      if (!x.IsScalar()) error(x, key, "expected a name");
      else out.push_back(x.Scalar());
    }
    return out;
  }
  int axis_component(const YAML::Node& parent, const char* key) {
    const std::string c = text(parent, key, "x");
    if (c == "x") return 0;
    if (c == "y") return 1;
    if (c == "z") return 2;
    error(parent[key], key, "expected x, y or z");
    return 0;
  }

  TimeFunction function(const YAML::Node& n, const std::string& field) {
    TimeFunction f;
    if (n.IsScalar()) return TimeFunction::constant(as_number(n, field, 0.0));
    if (!check_keys(n, field, {"type", "value", "time", "before", "after", "points", "amplitude",
                               "frequency", "phase", "offset", "f0", "f1", "t0", "t1", "coefficients"}))
      return f;
    const std::string type = text(n, "type", "", true);
    if (type == "constant") {
      f.a = number(n, "value", 0.0, true);
    } else if (type == "step") {
      f.kind = TimeFunction::Kind::kStep;
      f.t0 = number(n, "time", 0.0, true);
      f.a = number(n, "before", 0.0, true);
      f.b = number(n, "after", 0.0, true);
    } else if (type == "piecewise_linear") {
      f.kind = TimeFunction::Kind::kPiecewiseLinear;
      const YAML::Node pts = n["points"];
      if (!pts || !pts.IsSequence() || pts.size() < 2) {
        error(n, "points", "expected at least two [t, value] pairs");
        return TimeFunction{};
      }
      for (const auto& p : pts) {
        if (!p.IsSequence() || p.size() != 2) {
          error(p, "points", "expected a [t, value] pair");
          continue;
        }
        f.ts.push_back(as_number(p[0], "points", 0.0));
        f.ys.push_back(as_number(p[1], "points", 0.0));
        if (f.ts.size() > 1 && !(f.ts.back() > f.ts[f.ts.size() - 2]))
          error(p, "points", "times must increase");
      }
    } else if (type == "sine") {
      f.kind = TimeFunction::Kind::kSine;
      f.a = number(n, "amplitude", 0.0, true);
      f.b = number(n, "frequency", 0.0, true);
      f.c = number(n, "phase", 0.0);
      f.d = number(n, "offset", 0.0);
    } else if (type == "sweep") {
      f.kind = TimeFunction::Kind::kSweep;
      f.a = number(n, "amplitude", 0.0, true);
      f.b = number(n, "f0", 0.0, true);
      f.c = number(n, "f1", 0.0, true);
      f.t0 = number(n, "t0", 0.0);
      f.t1 = number(n, "t1", 1.0, true);
      if (!(f.t1 > f.t0)) error(n, "t1", "must be after t0");
    } else if (type == "polynomial") {
      f.kind = TimeFunction::Kind::kPolynomial;
      const YAML::Node c = n["coefficients"];
      if (!c || !c.IsSequence() || c.size() == 0) error(n, "coefficients", "expected a list of numbers");
      else for (const auto& x : c) f.ys.push_back(as_number(x, "coefficients", 0.0));
    } else if (!type.empty()) {
      error(n["type"], "type", "unknown function type '" + type +
                                   "' (constant, step, piecewise_linear, sine, sweep, polynomial)");
    }
    return f;
  }

  void body(const YAML::Node& n, Model& m) {
    if (!check_keys(n, "body", {"name", "mass", "com", "inertia", "points"})) return;
    BodySpec b;
    b.where = where(n);
    b.name = text(n, "name", "", true);
    b.mass = number(n, "mass", 0.0, true);
    if (has(n, "mass") && !(b.mass > 0)) error(n["mass"], "mass", "must be positive");
    b.com = vec3(n, "com", Vec3::Zero());
    if (has(n, "inertia")) {
      const YAML::Node in = n["inertia"];
      if (in.IsMap()) {
        check_keys(in, "inertia", {"xx", "yy", "zz", "xy", "yz", "xz"});
        const double xx = number(in, "xx", 0), yy = number(in, "yy", 0), zz = number(in, "zz", 0);
        const double xy = number(in, "xy", 0), yz = number(in, "yz", 0), xz = number(in, "xz", 0);
        b.inertia << xx, xy, xz, xy, yy, yz, xz, yz, zz;
      } else if (in.IsSequence() && in.size() == 3 && in[0].IsSequence()) {
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c) b.inertia(r, c) = in[r].size() == 3 ? as_number(in[r][c], "inertia", 0) : 0;
        if ((b.inertia - b.inertia.transpose()).cwiseAbs().maxCoeff() > 1e-12 * (1 + b.inertia.cwiseAbs().maxCoeff()))
          error(in, "inertia", "the inertia tensor is not symmetric");
      } else {
        error(in, "inertia", "expected {xx, yy, zz, xy, yz, xz} or a 3x3 matrix");
      }
      Eigen::SelfAdjointEigenSolver<Mat3> es(b.inertia);
      const Vec3 ev = es.eigenvalues();
      const double tol = 1e-12 * std::max(1.0, ev.cwiseAbs().maxCoeff());
      if (ev.minCoeff() < -tol) error(in, "inertia", "the inertia tensor is not positive semi-definite");
      else if (ev[0] + ev[1] < ev[2] - tol)
        error(in, "inertia", "the principal moments violate the triangle inequality (not a rigid body)");
    }
    if (has(n, "points")) {
      const YAML::Node pts = n["points"];
      if (!pts.IsMap()) error(pts, "points", "expected a mapping name: [x, y, z]");
      else
        for (const auto& kv : pts) {
          const std::string pname = kv.first.as<std::string>();
          YAML::Node holder;
          holder[pname] = kv.second;
          if (!kv.second.IsSequence() || kv.second.size() != 3) {
            error(kv.second, "points." + pname, "expected a list of 3 numbers");
            continue;
          }
          Vec3 p;
          for (int k = 0; k < 3; ++k) p[k] = as_number(kv.second[k], "points." + pname, 0.0);
          b.points[pname] = p;
        }
    }
    m.bodies.push_back(b);
  }

  void joint(const YAML::Node& n, Model& m) {
    if (!check_keys(n, "joint", {"name", "parent", "child", "anchor", "chain", "coordinates"})) return;
    JointSpec j;
    j.where = where(n);
    j.name = text(n, "name", "", true);
    j.parent = text(n, "parent", "", true);
    j.child = text(n, "child", "", true);
    if (has(n, "anchor")) {
      if (n["anchor"].IsScalar()) j.anchor_point = n["anchor"].Scalar();
      else j.anchor = vec3(n, "anchor", Vec3::Zero());
    }
    const std::vector<std::string> chain = names(n, "chain");
    const std::vector<std::string> coords = names(n, "coordinates");
    if (coords.size() != chain.size())
      error(n, "coordinates", "expected one coordinate name per elementary joint of the chain (" +
                                  std::to_string(chain.size()) + ")");
    for (size_t k = 0; k < chain.size(); ++k) {
      const std::string& e = chain[k];
      ElementaryJoint ej;
      if (e.size() != 2 || (e[0] != 'R' && e[0] != 'T') || e[1] < '1' || e[1] > '3') {
        error(n["chain"], "chain", "unknown elementary joint '" + e + "' (R1 R2 R3 T1 T2 T3)");
        continue;
      }
      ej.rotation = e[0] == 'R';
      ej.axis = e[1] - '1';
      ej.coordinate = k < coords.size() ? coords[k] : "";
      j.chain.push_back(ej);
    }
    m.joints.push_back(j);
  }

  void coordinate(const std::string& name, const YAML::Node& n, Model& m, bool patch) {
    if (!check_keys(n, "coordinate " + name, {"initial", "initial_deg", "mode", "drive"})) return;
    CoordinateSpec c;
    auto it = m.coordinates.find(name);
    if (patch && it != m.coordinates.end()) c = it->second;
    c.name = name;
    c.where = where(n);
    if (has(n, "initial")) c.initial = number(n, "initial", 0.0);
    if (has(n, "initial_deg")) c.initial = number(n, "initial_deg", 0.0) * kDeg;
    if (has(n, "mode")) {
      const std::string mode = text(n, "mode", "free");
      if (mode == "free") c.mode = CoordinateSpec::Mode::kFree;
      else if (mode == "locked") c.mode = CoordinateSpec::Mode::kLocked;
      else if (mode == "driven") c.mode = CoordinateSpec::Mode::kDriven;
      else error(n["mode"], "mode", "expected free, locked or driven");
    }
    if (has(n, "drive")) c.drive = function(n["drive"], "drive");
    if (c.mode == CoordinateSpec::Mode::kDriven && !has(n, "drive") && !(patch && it != m.coordinates.end() && it->second.mode == CoordinateSpec::Mode::kDriven))
      error(n, "drive", "a driven coordinate needs a drive function");
    m.coordinates[name] = c;
  }

  void cut(const YAML::Node& n, Model& m) {
    if (!check_keys(n, "cut", {"name", "type", "body1", "point1", "body2", "point2", "axis1", "axis2", "distance"})) return;
    CutSpec c;
    c.where = where(n);
    c.name = text(n, "name", "", true);
    const std::string type = text(n, "type", "", true);
    if (type == "ball") c.type = CutSpec::Type::kBall;
    else if (type == "revolute") c.type = CutSpec::Type::kRevolute;
    else if (type == "universal") c.type = CutSpec::Type::kUniversal;
    else if (type == "prismatic") c.type = CutSpec::Type::kPrismatic;
    else if (type == "weld") c.type = CutSpec::Type::kWeld;
    else if (type == "distance") c.type = CutSpec::Type::kDistance;
    else if (!type.empty()) error(n["type"], "type", "unknown cut type '" + type + "' (ball, revolute, universal, prismatic, weld, distance)");
    c.body1 = text(n, "body1", "", true);
    c.body2 = text(n, "body2", "", true);
    c.point1 = text(n, "point1", "");
    c.point2 = text(n, "point2", "");
    c.axis1 = vec3(n, "axis1", Vec3::UnitZ());
    c.axis2 = vec3(n, "axis2", c.axis1);
    if (c.axis1.norm() == 0) error(n, "axis1", "must not be zero");
    if (c.axis2.norm() == 0) error(n, "axis2", "must not be zero");
    c.distance = number(n, "distance", 0.0, c.type == CutSpec::Type::kDistance);
    if (c.type == CutSpec::Type::kDistance && !(c.distance > 0)) error(n, "distance", "must be positive");
    m.cuts.push_back(c);
  }

  void force(const YAML::Node& n, Model& m) {
    if (!check_keys(n, "force", {"name", "type", "body1", "point1", "body2", "point2", "body", "point",
                                 "stiffness", "damping", "free_length", "fx", "fy", "fz", "radius", "axis",
                                 "ground", "law", "parameters"}))
      return;
    ForceSpec f;
    f.where = where(n);
    f.name = text(n, "name", "", true);
    const std::string type = text(n, "type", "", true);
    if (type == "spring_damper") {
      f.type = ForceSpec::Type::kSpringDamper;
      f.body1 = text(n, "body1", "", true);
      f.point1 = text(n, "point1", "");
      f.body2 = text(n, "body2", "", true);
      f.point2 = text(n, "point2", "");
      f.stiffness = number(n, "stiffness", 0.0, true);
      f.damping = number(n, "damping", 0.0);
      f.free_length = number(n, "free_length", 0.0);
      if (f.stiffness < 0) error(n["stiffness"], "stiffness", "must not be negative");
      if (f.damping < 0) error(n["damping"], "damping", "must not be negative");
    } else if (type == "point_force") {
      f.type = ForceSpec::Type::kPointForce;
      f.body1 = text(n, "body", "", true);
      f.point1 = text(n, "point", "");
      if (has(n, "fx")) f.fx = function(n["fx"], "fx");
      if (has(n, "fy")) f.fy = function(n["fy"], "fy");
      if (has(n, "fz")) f.fz = function(n["fz"], "fz");
    } else if (type == "wheel_contact") {
      f.type = ForceSpec::Type::kWheelContact;
      f.body1 = text(n, "body", "", true);
      f.point1 = text(n, "point", "");
      f.stiffness = number(n, "stiffness", 0.0, true);
      f.radius = number(n, "radius", 0.0, true);
      f.axis = vec3(n, "axis", Vec3::UnitY());
      if (f.axis.norm() == 0) error(n["axis"], "axis", "must not be zero");
      if (!(f.stiffness > 0)) error(n, "stiffness", "must be positive");
      if (!(f.radius > 0)) error(n, "radius", "must be positive");
      if (has(n, "ground")) f.ground = function(n["ground"], "ground");
    } else if (type == "user") {
      f.type = ForceSpec::Type::kUser;
      f.body1 = text(n, "body1", "", true);
      f.point1 = text(n, "point1", "");
      f.body2 = text(n, "body2", "", true);
      f.point2 = text(n, "point2", "");
      f.law = text(n, "law", "", true);
      if (has(n, "parameters")) {
        const YAML::Node p = n["parameters"];
        if (!p.IsMap()) error(p, "parameters", "expected a mapping name: number");
        else for (const auto& kv : p) f.parameters[kv.first.as<std::string>()] = as_number(kv.second, "parameters", 0.0);
      }
    } else if (!type.empty()) {
      error(n["type"], "type", "unknown force type '" + type + "' (spring_damper, point_force, wheel_contact, user)");
    }
    m.forces.push_back(f);
  }

  void sensor(const YAML::Node& n, Model& m) {
    if (!check_keys(n, "sensor", {"name", "type", "body", "point", "component", "axis", "coordinate", "force", "expression"})) return;
    SensorSpec s;
    s.where = where(n);
    s.name = text(n, "name", "", true);
    const std::string type = text(n, "type", "", true);
    using T = SensorSpec::Type;
    static const std::map<std::string, T> types = {
        {"position", T::kPosition}, {"velocity", T::kVelocity}, {"acceleration", T::kAcceleration},
        {"axis", T::kAxis}, {"coordinate", T::kCoordinate}, {"coordinate_rate", T::kCoordinateRate},
        {"force_length", T::kForceLength}, {"force_value", T::kForceValue}, {"expression", T::kExpression},
        {"kinetic_energy", T::kKineticEnergy}, {"potential_energy", T::kPotentialEnergy}};
    auto it = types.find(type);
    if (it == types.end()) {
      if (!type.empty()) error(n["type"], "type", "unknown sensor type '" + type + "'");
      return;
    }
    s.type = it->second;
    switch (s.type) {
      case T::kPosition: case T::kVelocity: case T::kAcceleration:
        s.body = text(n, "body", "", true);
        s.point = text(n, "point", "");
        s.component = axis_component(n, "component");
        break;
      case T::kAxis:
        s.body = text(n, "body", "", true);
        s.axis = vec3(n, "axis", Vec3::UnitX(), true);
        s.component = axis_component(n, "component");
        break;
      case T::kCoordinate: case T::kCoordinateRate: s.target = text(n, "coordinate", "", true); break;
      case T::kForceLength: case T::kForceValue: s.target = text(n, "force", "", true); break;
      case T::kExpression: s.expression = text(n, "expression", "", true); break;
    }
    m.sensors.push_back(s);
  }

  AnalysisStep step(const YAML::Node& n) {
    AnalysisStep s;
    s.where = where(n);
    if (!check_keys(n, "analysis step", {"type", "hold", "release", "unknowns", "t0", "t_end", "output_step",
                                         "rtol", "atol", "max_step", "constraint_scale", "formulation",
                                         "quiet_until", "quiet_sensors"}))
      return s;
    const std::string type = text(n, "type", "", true);
    if (type == "assembly") s.type = AnalysisStep::Type::kAssembly;
    else if (type == "equilibrium") s.type = AnalysisStep::Type::kEquilibrium;
    else if (type == "kinematics") s.type = AnalysisStep::Type::kKinematics;
    else if (type == "dynamics") s.type = AnalysisStep::Type::kDynamics;
    else if (!type.empty()) error(n["type"], "type", "unknown analysis '" + type + "' (assembly, equilibrium, kinematics, dynamics)");
    s.hold = names(n, "hold");
    s.release = names(n, "release");
    s.unknowns = names(n, "unknowns");
    s.t0 = number(n, "t0", 0.0);
    s.t_end = number(n, "t_end", 1.0);
    s.output_step = number(n, "output_step", 0.01);
    s.rtol = number(n, "rtol", 1e-6);
    s.atol = number(n, "atol", 1e-8);
    s.max_step = number(n, "max_step", 0.0);
    s.constraint_scale = number(n, "constraint_scale", 0.0);
    s.formulation = text(n, "formulation", "index3");
    s.quiet_until = number(n, "quiet_until", -1.0);
    s.quiet_sensors = names(n, "quiet_sensors");
    const bool integrates = s.type == AnalysisStep::Type::kKinematics || s.type == AnalysisStep::Type::kDynamics;
    if (integrates && !(s.t_end > s.t0)) error(n, "t_end", "the time span is empty (t_end must exceed t0)");
    if (integrates && !(s.output_step > 0)) error(n, "output_step", "must be positive");
    if (!(s.rtol >= 1e-14 && s.rtol <= 0.5)) error(has(n, "rtol") ? n["rtol"] : n, "rtol", "out of range [1e-14, 0.5]");
    if (!(s.atol > 0 && s.atol <= 1.0)) error(has(n, "atol") ? n["atol"] : n, "atol", "out of range (0, 1]");
    if (s.max_step < 0) error(n["max_step"], "max_step", "must not be negative");
    if (s.formulation != "index3")
      error(n["formulation"], "formulation", "unknown formulation '" + s.formulation + "' (index3)");
    return s;
  }

  // Model sections: a model file, or the scene itself.
  void sections(const YAML::Node& root, Model& m, bool patch) {
    if (has(root, "name")) m.name = text(root, "name", m.name);
    if (has(root, "gravity")) m.gravity = vec3(root, "gravity", m.gravity);
    auto each = [&](const char* key, auto&& fn) {
      if (!has(root, key)) return;
      const YAML::Node list = root[key];
      if (!list.IsSequence()) {
        error(list, key, "expected a list");
        return;
      }
      for (const auto& item : list) fn(item);
    };
    // In a scene, an entry named like one of the model replaces it.
    auto replace = [&](auto& vec, size_t before) {
      if (!patch || vec.size() == before) return;
      auto added = vec.back();
      vec.pop_back();
      for (auto& e : vec)
        if (e.name == added.name) {
          e = added;
          return;
        }
      vec.push_back(added);
    };
    each("bodies", [&](const YAML::Node& n) { size_t b = m.bodies.size(); body(n, m); replace(m.bodies, b); });
    each("joints", [&](const YAML::Node& n) { size_t b = m.joints.size(); joint(n, m); replace(m.joints, b); });
    each("cuts", [&](const YAML::Node& n) { size_t b = m.cuts.size(); cut(n, m); replace(m.cuts, b); });
    each("forces", [&](const YAML::Node& n) { size_t b = m.forces.size(); force(n, m); replace(m.forces, b); });
    each("sensors", [&](const YAML::Node& n) { size_t b = m.sensors.size(); sensor(n, m); replace(m.sensors, b); });
    if (has(root, "coordinates")) {
      const YAML::Node c = root["coordinates"];
      if (!c.IsMap()) error(c, "coordinates", "expected a mapping name: {initial, mode, drive}");
      else for (const auto& kv : c) coordinate(kv.first.as<std::string>(), kv.second, m, patch);
    }
  }
};

YAML::Node parse(const std::string& text, const std::string& path) {
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw SceneError({ModelError::format(path, e.mark.line + 1, "", "YAML syntax error: " + e.msg)});
  }
}

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw SceneError({path + ": cannot read the file"});
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace

Scene load_scene_text(const std::string& text, const std::string& path) {
  Scene scene;
  scene.file = path;
  std::vector<std::string> errors;
  const YAML::Node root = parse(text, path);
  Loader scene_loader{path, &errors};
  if (!root.IsMap()) throw SceneError({path + ": the scene must be a YAML mapping"});
  scene_loader.check_keys(root, "scene", {"model", "name", "gravity", "bodies", "joints", "coordinates", "cuts",
                                          "forces", "sensors", "remove", "analysis", "output"});
  if (root["model"]) {
    const std::string model_path =
        (std::filesystem::path(path).parent_path() / scene_loader.text(root, "model", "")).string();
    std::string model_text;
    try {
      model_text = read_file(model_path);
    } catch (const SceneError&) {
      scene_loader.error(root["model"], "model", "cannot read model file '" + model_path + "'");
    }
    if (!model_text.empty()) {
      const YAML::Node mroot = parse(model_text, model_path);
      Loader model_loader{model_path, &errors};
      model_loader.check_keys(mroot, "model", {"name", "gravity", "bodies", "joints", "coordinates", "cuts",
                                               "forces", "sensors"});
      model_loader.sections(mroot, scene.model, false);
    }
  }
  scene_loader.sections(root, scene.model, true);
  for (const std::string& name : scene_loader.names(root, "remove")) {
    bool found = false;
    auto drop = [&](auto& vec) {
      for (auto it = vec.begin(); it != vec.end(); ++it)
        if (it->name == name) {
          vec.erase(it);
          found = true;
          return;
        }
    };
    drop(scene.model.forces);
    drop(scene.model.sensors);
    drop(scene.model.cuts);
    if (!found) scene_loader.error(root["remove"], "remove", "nothing named '" + name + "' to remove (forces, sensors, cuts)");
  }
  if (root["analysis"]) {
    const YAML::Node a = root["analysis"];
    if (a.IsSequence()) for (const auto& s : a) scene.steps.push_back(scene_loader.step(s));
    else scene.steps.push_back(scene_loader.step(a));
  } else {
    scene_loader.error(root, "analysis", "missing (assembly, equilibrium, kinematics or dynamics steps)");
  }
  int integrations = 0;
  for (const auto& s : scene.steps)
    if (s.type == AnalysisStep::Type::kKinematics || s.type == AnalysisStep::Type::kDynamics) ++integrations;
  if (integrations > 1) scene_loader.error(root["analysis"], "analysis", "at most one kinematics or dynamics step per scene");
  scene.columns = scene_loader.names(root, "output");
  if (!errors.empty()) throw SceneError(errors);
  return scene;
}

Scene load_scene(const std::string& path) { return load_scene_text(read_file(path), path); }

}  // namespace mbdae
