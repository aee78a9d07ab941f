// YAML scene loader. Every problem is recorded with its file, line and field, and loading goes
// on so that all problems of a file are reported at once: first what can be seen field by field
// (unknown or missing fields, wrong types, numbers that are not finite or out of range), then
// the references between items and the joint tree (validate_scene, cases/scene_validation.cpp).
#include <yaml-cpp/yaml.h>

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

#include "cases/field_ranges.h"
#include "cases/analysis_types.h"
#include "cases/scene.h"
#include "cases/scene_overrides.h"
#include "cases/scene_source.h"
#include "cases/scene_validation.h"
#include "core/errors.h"
#include "core/expression.h"
#include "formulation/formulation_registry.h"

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
constexpr double kDefaultMaxFileMB = 16;  // scene and model files; MBDAE_MAX_SCENE_MB changes it

using Fields = std::vector<std::string>;

bool contains(const Fields& list, const std::string& s) { return std::find(list.begin(), list.end(), s) != list.end(); }
std::string join(const Fields& list) {
  std::string s;
  for (const auto& x : list) s += (s.empty() ? "" : ", ") + x;
  return s;
}
// A scalar as shown in a message: quoted, control characters escaped, long text shortened.
std::string quote(const std::string& s) {
  std::string out = "'";
  for (size_t k = 0; k < s.size(); ++k) {
    if (k == 60) {
      out += "...";
      break;
    }
    const unsigned char c = static_cast<unsigned char>(s[k]);
    if (c < 0x20 || c == 0x7f) {
      static const char* hex = "0123456789abcdef";
      out += "\\x";
      out += hex[c >> 4];
      out += hex[c & 15];
    } else {
      out += static_cast<char>(c);
    }
  }
  return out + "'";
}
std::string describe(const YAML::Node& n) {
  if (!n.IsDefined() || n.IsNull()) return "nothing";
  if (n.IsMap()) return "a mapping";
  if (n.IsSequence()) return "a list of " + std::to_string(n.size());
  return quote(n.Scalar());
}
struct Loader {
  std::string file;
  std::vector<SceneIssue>* issues;
  FieldLines* lines;

  static int line_of(const YAML::Node& n) {
    if (!n.IsDefined()) return 0;
    const int l = n.Mark().line;
    return l >= 0 ? l + 1 : 0;
  }
  SourceLocation where(const YAML::Node& n) const { return SourceLocation{file, line_of(n)}; }
  void error_at(int line, const std::string& field, const std::string& msg) {
    issues->push_back({file, line, field, msg});
  }
  void error(const YAML::Node& n, const std::string& field, const std::string& msg) {
    error_at(line_of(n), field, msg);
  }
  bool has(const YAML::Node& n, const char* key) const { return n.IsMap() && n[key]; }
  // The value of `key`, or `parent` itself if absent (to place a message).
  YAML::Node at(const YAML::Node& parent, const char* key) const {
    return has(parent, key) ? YAML::Node(parent[key]) : parent;
  }
  void record(const YAML::Node& item, const std::string& field, const YAML::Node& value) {
    lines->add(where(item), field, line_of(value));
  }

  std::optional<std::string> key_of(const YAML::Node& k, const std::string& what) {
    if (k.IsScalar()) return k.Scalar();
    error(k, what, "expected a name as key, got " + describe(k));
    return std::nullopt;
  }
  // Reports keys of a mapping that are not in `allowed`, or given twice.
  bool check_keys(const YAML::Node& n, const std::string& what, const Fields& allowed) {
    if (!n.IsMap()) {
      error(n, what, "expected a mapping, got " + describe(n));
      return false;
    }
    std::set<std::string> seen;
    for (const auto& kv : n) {
      const auto key = key_of(kv.first, what);
      if (!key) continue;
      if (!seen.insert(*key).second) error(kv.first, *key, "given twice in " + what);
      else if (!contains(allowed, *key))
        error(kv.first, *key, "unknown field in " + what + " (expected one of: " + join(allowed) + ")" +
                                  did_you_mean(*key, allowed));
    }
    return true;
  }
  // Reports known fields (in `general`) that have no effect for this type (not in `specific`).
  void applies(const YAML::Node& n, const std::string& what, const Fields& general, const Fields& specific) {
    if (!n.IsMap()) return;
    for (const auto& kv : n) {
      if (!kv.first.IsScalar()) continue;
      const std::string& key = kv.first.Scalar();
      if (contains(general, key) && !contains(specific, key))
        error(kv.first, key, "does not apply to " + what + " (its fields: " + join(specific) + ")");
    }
  }

  std::optional<double> to_number(const YAML::Node& v, const std::string& field) {
    if (!v.IsScalar()) {
      error(v, field, "expected a number, got " + describe(v));
      return std::nullopt;
    }
    const std::string& s = v.Scalar();
    std::string low;
    for (char c : s) low += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (low == ".nan" || low == ".inf" || low == "+.inf" || low == "-.inf") {
      error(v, field, quote(s) + " is not a finite number");
      return std::nullopt;
    }
    if (s.empty() || std::isspace(static_cast<unsigned char>(s[0]))) {
      error(v, field, "expected a number, got " + quote(s));
      return std::nullopt;
    }
    char* end = nullptr;
    const double x = std::strtod(s.c_str(), &end);
    if (end != s.c_str() + s.size()) {
      error(v, field, "expected a number, got " + quote(s));
      return std::nullopt;
    }
    if (!std::isfinite(x)) {
      error(v, field, quote(s) + " is not a finite number");
      return std::nullopt;
    }
    return x;
  }
  std::optional<double> opt_number(const YAML::Node& parent, const char* key, bool required = false) {
    if (!has(parent, key)) {
      if (required) error(parent, key, "missing");
      return std::nullopt;
    }
    const YAML::Node v = parent[key];
    record(parent, key, v);
    return to_number(v, key);
  }
  double number(const YAML::Node& parent, const char* key, double fallback, bool required = false) {
    return opt_number(parent, key, required).value_or(fallback);
  }
  std::string text(const YAML::Node& parent, const char* key, const std::string& fallback, bool required = false) {
    if (!has(parent, key)) {
      if (required) error(parent, key, "missing");
      return fallback;
    }
    const YAML::Node v = parent[key];
    record(parent, key, v);
    if (!v.IsScalar()) {
      error(v, key, "expected text, got " + describe(v));
      return fallback;
    }
    return v.Scalar();
  }
  // A required name (of the item, or of another item it refers to).
  std::string name(const YAML::Node& parent, const char* key = "name") {
    const std::string s = text(parent, key, "", true);
    if (has(parent, key) && parent[key].IsScalar()) {
      if (s.empty()) error(parent[key], key, "must not be empty");
      else if (std::any_of(s.begin(), s.end(), [](char c) { return static_cast<unsigned char>(c) < 0x20; }))
        error(parent[key], key, "must not contain control characters, got " + quote(s));
    }
    return s;
  }
  Vec3 vec3(const YAML::Node& parent, const char* key, const Vec3& fallback, bool required = false) {
    if (!has(parent, key)) {
      if (required) error(parent, key, "missing");
      return fallback;
    }
    const YAML::Node v = parent[key];
    record(parent, key, v);
    if (!v.IsSequence() || v.size() != 3) {
      error(v, key, "expected a list of 3 numbers, got " + describe(v));
      return fallback;
    }
    Vec3 out;
    for (int k = 0; k < 3; ++k) out[k] = to_number(v[k], key).value_or(fallback[k]);
    return out;
  }
  std::vector<std::string> names(const YAML::Node& parent, const char* key) {
    std::vector<std::string> out;
    if (!has(parent, key)) return out;
    const YAML::Node v = parent[key];
    record(parent, key, v);
    if (v.IsScalar()) return {v.Scalar()};
    if (!v.IsSequence()) {
      error(v, key, "expected a list of names, got " + describe(v));
      return out;
    }
    for (const auto& x : v) {
      if (!x.IsScalar()) {
        error(x, key, "expected a name, got " + describe(x));
        continue;
      }
      lines->add(where(parent), std::string(key) + "[" + std::to_string(out.size()) + "]", line_of(x));
      out.push_back(x.Scalar());
    }
    return out;
  }
  int axis_component(const YAML::Node& parent, const char* key) {
    const std::string c = text(parent, key, "x");
    if (c == "x") return 0;
    if (c == "y") return 1;
    if (c == "z") return 2;
    if (parent[key].IsScalar()) error(parent[key], key, "expected x, y or z, got " + quote(c));
    return 0;
  }

  TimeFunction function(const YAML::Node& n, const std::string& field) {
    TimeFunction f;
    if (n.IsScalar()) return TimeFunction::constant(to_number(n, field).value_or(0.0));
    static const Fields general = {"type", "value", "time", "before", "after", "points", "amplitude",
                                   "frequency", "phase", "offset", "f0", "f1", "t0", "t1", "coefficients"};
    if (!check_keys(n, field, general)) return f;
    const std::string type = text(n, "type", "", true);
    const std::string what = "a " + type + " function";
    if (type == "constant") {
      applies(n, what, general, {"type", "value"});
      f.a = number(n, "value", 0.0, true);
    } else if (type == "step") {
      applies(n, what, general, {"type", "time", "before", "after"});
      f.kind = TimeFunction::Kind::kStep;
      f.t0 = number(n, "time", 0.0, true);
      f.a = number(n, "before", 0.0, true);
      f.b = number(n, "after", 0.0, true);
    } else if (type == "piecewise_linear") {
      applies(n, what, general, {"type", "points"});
      f.kind = TimeFunction::Kind::kPiecewiseLinear;
      const YAML::Node pts = at(n, "points");
      if (!has(n, "points") || !pts.IsSequence() || pts.size() < 2) {
        error(pts, "points", "expected at least two [t, value] pairs");
        return TimeFunction{};
      }
      for (const auto& p : pts) {
        if (!p.IsSequence() || p.size() != 2) {
          error(p, "points", "expected a [t, value] pair, got " + describe(p));
          continue;
        }
        const auto t = to_number(p[0], "points"), y = to_number(p[1], "points");
        if (!t || !y) continue;
        if (!f.ts.empty() && !(*t > f.ts.back())) error(p, "points", "times must increase");
        f.ts.push_back(*t);
        f.ys.push_back(*y);
      }
      if (f.ts.size() < 2) return TimeFunction{};
    } else if (type == "sine") {
      applies(n, what, general, {"type", "amplitude", "frequency", "phase", "offset"});
      f.kind = TimeFunction::Kind::kSine;
      f.a = number(n, "amplitude", 0.0, true);
      f.b = number(n, "frequency", 0.0, true);
      f.c = number(n, "phase", 0.0);
      f.d = number(n, "offset", 0.0);
    } else if (type == "sweep") {
      applies(n, what, general, {"type", "amplitude", "f0", "f1", "t0", "t1"});
      f.kind = TimeFunction::Kind::kSweep;
      f.a = number(n, "amplitude", 0.0, true);
      f.b = number(n, "f0", 0.0, true);
      f.c = number(n, "f1", 0.0, true);
      const auto t0 = opt_number(n, "t0"), t1 = opt_number(n, "t1", true);
      f.t0 = t0.value_or(0.0);
      f.t1 = t1.value_or(1.0);
      if (t1 && !(f.t1 > f.t0)) error(n["t1"], "t1", "the sweep's time span is empty (t1 must exceed t0)");
    } else if (type == "polynomial") {
      applies(n, what, general, {"type", "coefficients"});
      f.kind = TimeFunction::Kind::kPolynomial;
      const YAML::Node c = at(n, "coefficients");
      if (!has(n, "coefficients") || !c.IsSequence() || c.size() == 0)
        error(c, "coefficients", "expected a list of numbers");
      else
        for (const auto& x : c) f.ys.push_back(to_number(x, "coefficients").value_or(0.0));
    } else if (!type.empty()) {
      error(n["type"], "type", "unknown function type " + quote(type) +
                                   " (constant, step, piecewise_linear, sine, sweep, polynomial)");
    }
    return f;
  }

  void inertia(const YAML::Node& in, BodySpec& b) {
    bool ok = true;
    if (in.IsMap()) {
      check_keys(in, "inertia", {"xx", "yy", "zz", "xy", "yz", "xz"});
      double v[6];
      const char* keys[6] = {"xx", "yy", "zz", "xy", "yz", "xz"};
      for (int k = 0; k < 6; ++k) {
        const auto x = opt_number(in, keys[k]);
        if (has(in, keys[k]) && !x) ok = false;
        v[k] = x.value_or(0.0);
      }
      b.inertia << v[0], v[3], v[5], v[3], v[1], v[4], v[5], v[4], v[2];
    } else if (in.IsSequence() && in.size() == 3) {
      for (int r = 0; r < 3; ++r) {
        if (!in[r].IsSequence() || in[r].size() != 3) {
          error(in[r], "inertia", "expected a row of 3 numbers, got " + describe(in[r]));
          ok = false;
          continue;
        }
        for (int c = 0; c < 3; ++c) {
          const auto x = to_number(in[r][c], "inertia");
          ok = ok && x.has_value();
          b.inertia(r, c) = x.value_or(0.0);
        }
      }
      if (ok && (b.inertia - b.inertia.transpose()).cwiseAbs().maxCoeff() >
                    1e-12 * (1 + b.inertia.cwiseAbs().maxCoeff())) {
        error(in, "inertia", "the inertia tensor is not symmetric");
        ok = false;
      }
    } else {
      error(in, "inertia", "expected {xx, yy, zz, xy, yz, xz} or a 3x3 matrix, got " + describe(in));
      ok = false;
    }
    if (!ok) return;
    Eigen::SelfAdjointEigenSolver<Mat3> es(b.inertia, Eigen::EigenvaluesOnly);
    const Vec3 ev = es.eigenvalues();
    const double tol = 1e-12 * std::max(1.0, ev.cwiseAbs().maxCoeff());
    if (!ev.allFinite())
      error(in, "inertia", "the inertia tensor is too large");
    else if (ev.minCoeff() < -tol)
      error(in, "inertia", "the inertia tensor is not positive semi-definite (smallest principal moment " +
                               format_number(ev.minCoeff()) + ")");
    else if (ev[0] + ev[1] < ev[2] - tol)
      error(in, "inertia", "the principal moments violate the triangle inequality (not a rigid body)");
  }

  // `points: {name: [x, y, z], ...}` of a body or of ground; "origin" and "com" are reserved.
  void named_points(const YAML::Node& n, std::map<std::string, Vec3>& points) {
    if (has(n, "points")) {
      const YAML::Node pts = n["points"];
      record(n, "points", pts);
      if (!pts.IsMap()) {
        error(pts, "points", "expected a mapping name: [x, y, z], got " + describe(pts));
      } else {
        for (const auto& kv : pts) {
          const auto pname = key_of(kv.first, "points");
          if (!pname) continue;
          const std::string field = "points." + *pname;
          if (*pname == "origin" || *pname == "com" || pname->empty()) {
            error(kv.first, field, pname->empty() ? "a point needs a name"
                                   : *pname == "com" ? "'com' is reserved (the centre of mass)"
                                                     : "'origin' is reserved (the origin of the body frame)");
            continue;
          }
          if (points.count(*pname)) {
            error(kv.first, field, "given twice");
            continue;
          }
          if (!kv.second.IsSequence() || kv.second.size() != 3) {
            error(kv.second, field, "expected a list of 3 numbers, got " + describe(kv.second));
            continue;
          }
          Vec3 p;
          for (int k = 0; k < 3; ++k) p[k] = to_number(kv.second[k], field).value_or(0.0);
          points[*pname] = p;
        }
      }
    }
  }

  void body(const YAML::Node& n, Model& m) {
    if (!check_keys(n, "body", {"name", "mass", "com", "inertia", "points"})) return;
    BodySpec b;
    b.where = where(n);
    b.name = name(n);
    if (const auto mass = opt_number(n, "mass", true)) {
      b.mass = *mass;
      if (!(b.mass > 0)) error(n["mass"], "mass", "must be positive, got " + format_number(b.mass));
    }
    b.com = vec3(n, "com", Vec3::Zero());
    if (has(n, "inertia")) {
      record(n, "inertia", n["inertia"]);
      inertia(n["inertia"], b);
    }
    named_points(n, b.points);
    m.bodies.push_back(b);
  }

  void joint(const YAML::Node& n, Model& m) {
    if (!check_keys(n, "joint", {"name", "parent", "child", "anchor", "chain", "coordinates"})) return;
    JointSpec j;
    j.where = where(n);
    j.name = name(n);
    j.parent = name(n, "parent");
    j.child = name(n, "child");
    if (has(n, "anchor")) {
      const YAML::Node a = n["anchor"];
      if (a.IsScalar()) {
        record(n, "anchor", a);
        j.anchor_point = a.Scalar();
        if (j.anchor_point.empty()) error(a, "anchor", "expected a point name or [x, y, z]");
      } else {
        j.anchor = vec3(n, "anchor", Vec3::Zero());
      }
    }
    const std::vector<std::string> chain = names(n, "chain");
    const std::vector<std::string> coords = names(n, "coordinates");
    if (coords.size() != chain.size())
      error(at(n, "coordinates"), "coordinates",
            "expected one coordinate name per elementary joint of the chain (" + std::to_string(chain.size()) +
                ", got " + std::to_string(coords.size()) + ")");
    bool chain_ok = true;
    for (size_t k = 0; k < chain.size(); ++k) {
      const std::string& e = chain[k];
      ElementaryJoint ej;
      if (e.size() != 2 || (e[0] != 'R' && e[0] != 'T') || e[1] < '1' || e[1] > '3') {
        error_at(lines->line(j.where, "chain[" + std::to_string(k) + "]"), "chain",
                 "unknown elementary joint " + quote(e) + " (R1 R2 R3 T1 T2 T3)");
        chain_ok = false;
      }
      ej.rotation = e[0] == 'R';
      ej.axis = e.size() == 2 ? e[1] - '1' : 0;
      ej.coordinate = k < coords.size() ? coords[k] : "";
      if (k < coords.size() && coords[k].empty())
        error_at(lines->line(j.where, "coordinates[" + std::to_string(k) + "]"), "coordinates",
                 "a coordinate name must not be empty");
      j.chain.push_back(ej);
    }
    // A chain with an unknown element (already reported) keeps its coordinates on a placeholder
    // chain R1 R2 R3 T1 T2 T3, so that they are not reported again as belonging to no joint.
    if (!chain_ok) {
      if (j.chain.size() > 6) j.chain.resize(6);
      for (size_t k = 0; k < j.chain.size(); ++k) {
        j.chain[k].rotation = k < 3;
        j.chain[k].axis = static_cast<int>(k % 3);
      }
    }
    m.joints.push_back(j);
  }

  void coordinate(const std::string& name, const YAML::Node& key, const YAML::Node& n, Model& m, bool patch) {
    const std::string field = "coordinates." + name;
    if (!check_keys(n, "coordinate " + quote(name), {"initial", "initial_deg", "mode", "drive"})) return;
    CoordinateSpec c;
    auto it = m.coordinates.find(name);
    const bool patching = patch && it != m.coordinates.end();
    if (patching) c = it->second;
    c.name = name;
    c.where = where(n);
    lines->add(c.where, "name", line_of(key));
    if (has(n, "initial") && has(n, "initial_deg")) error(n["initial_deg"], "initial_deg", "give initial or initial_deg, not both");
    if (has(n, "initial")) c.initial = number(n, "initial", c.initial);
    else if (has(n, "initial_deg")) c.initial = number(n, "initial_deg", c.initial / kDeg) * kDeg;
    if (has(n, "mode")) {
      const std::string mode = text(n, "mode", "free");
      if (mode == "free") c.mode = CoordinateSpec::Mode::kFree;
      else if (mode == "locked") c.mode = CoordinateSpec::Mode::kLocked;
      else if (mode == "driven") c.mode = CoordinateSpec::Mode::kDriven;
      else if (n["mode"].IsScalar()) error(n["mode"], "mode", "expected free, locked or driven, got " + quote(mode));
    }
    if (has(n, "drive")) c.drive = function(n["drive"], "drive");
    if (c.mode == CoordinateSpec::Mode::kDriven && !has(n, "drive") &&
        !(patching && it->second.mode == CoordinateSpec::Mode::kDriven))
      error(n, "drive", "a driven coordinate needs a drive function");
    m.coordinates[name] = c;
  }

  void cut(const YAML::Node& n, Model& m) {
    static const Fields general = {"name", "type", "body1", "point1", "body2", "point2", "axis1", "axis2", "ref1", "ref2",
                                   "distance"};
    if (!check_keys(n, "cut", general)) return;
    CutSpec c;
    c.where = where(n);
    c.name = name(n);
    const std::string type = text(n, "type", "", true);
    const Fields base = {"name", "type", "body1", "point1", "body2", "point2"};
    auto with = [&](Fields extra) {
      Fields f = base;
      f.insert(f.end(), extra.begin(), extra.end());
      return f;
    };
    if (type == "ball") c.type = CutSpec::Type::kBall;
    else if (type == "revolute") c.type = CutSpec::Type::kRevolute;
    else if (type == "universal") c.type = CutSpec::Type::kUniversal;
    else if (type == "prismatic") c.type = CutSpec::Type::kPrismatic;
    else if (type == "weld") c.type = CutSpec::Type::kWeld;
    else if (type == "distance") c.type = CutSpec::Type::kDistance;
    else if (!type.empty()) error(n["type"], "type", "unknown cut type " + quote(type) + " (ball, revolute, universal, prismatic, weld, distance)");
    if (type == "ball") applies(n, "a ball cut", general, base);
    if (type == "revolute" || type == "universal") applies(n, "a " + type + " cut", general, with({"axis1", "axis2"}));
    if (type == "weld" || type == "prismatic")
      applies(n, "a " + type + " cut", general, with({"axis1", "axis2", "ref1", "ref2"}));
    if (type == "distance") applies(n, "a distance cut", general, with({"distance"}));
    c.body1 = name(n, "body1");
    c.body2 = name(n, "body2");
    c.point1 = text(n, "point1", "");
    c.point2 = text(n, "point2", "");
    c.axis1 = vec3(n, "axis1", Vec3::UnitZ());
    c.axis2 = vec3(n, "axis2", c.axis1);
    if (c.axis1.norm() == 0) error(at(n, "axis1"), "axis1", "must not be zero");
    if (has(n, "axis2") && c.axis2.norm() == 0) error(at(n, "axis2"), "axis2", "must not be zero");
    c.ref1 = vec3(n, "ref1", Vec3::Zero());
    c.ref2 = vec3(n, "ref2", c.ref1);
    if (has(n, "ref1") && c.ref1.norm() == 0) error(at(n, "ref1"), "ref1", "must not be zero");
    if (has(n, "ref2") && c.ref2.norm() == 0) error(at(n, "ref2"), "ref2", "must not be zero");
    if (c.type == CutSpec::Type::kDistance) {
      const auto d = opt_number(n, "distance", true);
      c.distance = d.value_or(0.0);
      if (d && !(c.distance > 0)) error(n["distance"], "distance", "must be positive, got " + format_number(c.distance));
    }
    m.cuts.push_back(c);
  }

  // A point of a body: a name (of the body's points, "origin", "com") or [x, y, z] in its frame.
  void body_point(const YAML::Node& n, const char* key, std::string& point, Vec3& xyz, bool& at_xyz) {
    if (!has(n, key)) return;
    const YAML::Node v = n[key];
    record(n, key, v);
    if (v.IsScalar() && !v.Scalar().empty()) {
      point = v.Scalar();
    } else if (v.IsSequence() && v.size() == 3) {
      xyz = vec3(n, key, Vec3::Zero());
      at_xyz = true;
    } else {
      error(v, key, "expected a point name or [x, y, z], got " + describe(v));
    }
  }
  // A load component: a function of time (number or mapping) or an expression (other text).
  void load_component(const YAML::Node& n, const char* key, TimeFunction& f, std::string& expression) {
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
  void three(const YAML::Node& n, const char* key, Vec3& out, const char* unit) {
    if (!has(n, key)) return;
    out = vec3(n, key, Vec3::Zero());
    if (out.minCoeff() < 0) error(n[key], key, std::string("must not be negative (") + unit + ")");
  }
  void force_parameters(const YAML::Node& n, ForceSpec& f) {
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
  void frame(const YAML::Node& n, ForceSpec& f) {
    const std::string fr = text(n, "frame", "world");
    if (fr == "body") f.body_frame = true;
    else if (fr != "world" && n["frame"].IsScalar()) error(n["frame"], "frame", "expected world or body, got " + quote(fr));
  }

  // Number fields of a force, checked as they are read.
  void non_negative(const YAML::Node& n, const char* key, double& out, bool required) {
    const auto x = opt_number(n, key, required);
    if (x) out = *x;
    if (x && *x < 0) error(n[key], key, "must not be negative, got " + format_number(*x));
  }
  void positive(const YAML::Node& n, const char* key, double& out) {
    const auto x = opt_number(n, key, true);
    if (x) out = *x;
    if (x && !(*x > 0)) error(n[key], key, "must be positive, got " + format_number(*x));
  }
  void two_points(const YAML::Node& n, ForceSpec& f) {
    f.body1 = name(n, "body1");
    body_point(n, "point1", f.point1, f.xyz1, f.at_xyz1);
    f.body2 = name(n, "body2");
    body_point(n, "point2", f.point2, f.xyz2, f.at_xyz2);
  }

  // The fields of each force type (the table force_types() below lists the types).
  void spring_damper(const YAML::Node& n, ForceSpec& f) {
    two_points(n, f);
    non_negative(n, "stiffness", f.stiffness, true);
    non_negative(n, "damping", f.damping, false);
    non_negative(n, "free_length", f.free_length, false);
  }
  void point_force(const YAML::Node& n, ForceSpec& f) {
    f.body1 = name(n, "body");
    body_point(n, "point", f.point1, f.xyz1, f.at_xyz1);
    frame(n, f);
    load_component(n, "fx", f.fx, f.expression[0]);
    load_component(n, "fy", f.fy, f.expression[1]);
    load_component(n, "fz", f.fz, f.expression[2]);
    force_parameters(n, f);
  }
  void torque(const YAML::Node& n, ForceSpec& f) {
    f.body1 = name(n, "body");
    frame(n, f);
    f.axis = vec3(n, "axis", Vec3::UnitZ(), true);
    if (has(n, "axis") && f.axis.norm() == 0) error(n["axis"], "axis", "must not be zero");
    if (!has(n, "torque")) error(n, "torque", "missing (a number, a function of time or an expression)");
    load_component(n, "torque", f.fx, f.expression[0]);
    force_parameters(n, f);
  }
  void joint_spring_damper(const YAML::Node& n, ForceSpec& f) {
    f.coordinate = name(n, "coordinate");
    non_negative(n, "stiffness", f.stiffness, true);
    non_negative(n, "damping", f.damping, false);
    if (has(n, "rest") && has(n, "rest_deg")) error(n["rest_deg"], "rest_deg", "give rest or rest_deg, not both");
    if (has(n, "rest")) f.free_length = number(n, "rest", 0.0);
    else if (has(n, "rest_deg")) f.free_length = number(n, "rest_deg", 0.0) * kDeg;
  }
  void bushing(const YAML::Node& n, ForceSpec& f) {
    two_points(n, f);
    if (!has(n, "stiffness") && !has(n, "rotational_stiffness"))
      error(n, "stiffness", "missing (a bushing needs stiffness and/or rotational_stiffness, [x, y, z] each)");
    three(n, "stiffness", f.translational_stiffness, "N/m per frame-1 axis");
    three(n, "damping", f.translational_damping, "N s/m per frame-1 axis");
    three(n, "rotational_stiffness", f.rotational_stiffness, "N m/rad per frame-1 axis");
    three(n, "rotational_damping", f.rotational_damping, "N m s/rad per frame-1 axis");
  }
  void wheel_contact(const YAML::Node& n, ForceSpec& f) {
    f.body1 = name(n, "body");
    body_point(n, "point", f.point1, f.xyz1, f.at_xyz1);
    positive(n, "stiffness", f.stiffness);
    positive(n, "radius", f.radius);
    f.axis = vec3(n, "axis", Vec3::UnitY());
    if (f.axis.norm() == 0) error(n["axis"], "axis", "must not be zero");
    if (has(n, "ground")) f.ground = function(n["ground"], "ground");
  }
  void user_force(const YAML::Node& n, ForceSpec& f) {
    two_points(n, f);
    f.law = name(n, "law");
    force_parameters(n, f);
  }

  struct ForceType {
    const char* name;
    ForceSpec::Type type;
    Fields fields;  // the fields that apply to it
    void (Loader::*read)(const YAML::Node&, ForceSpec&);
  };
  static const std::vector<ForceType>& force_types() {
    using T = ForceSpec::Type;
    static const std::vector<ForceType> table = {
        {"spring_damper", T::kSpringDamper,
         {"name", "type", "body1", "point1", "body2", "point2", "stiffness", "damping", "free_length"},
         &Loader::spring_damper},
        {"point_force", T::kPointForce, {"name", "type", "body", "point", "fx", "fy", "fz", "frame", "parameters"},
         &Loader::point_force},
        {"torque", T::kTorque, {"name", "type", "body", "axis", "frame", "torque", "parameters"}, &Loader::torque},
        {"joint_spring_damper", T::kJointSpringDamper,
         {"name", "type", "coordinate", "stiffness", "damping", "rest", "rest_deg"}, &Loader::joint_spring_damper},
        {"bushing", T::kBushing,
         {"name", "type", "body1", "point1", "body2", "point2", "stiffness", "damping", "rotational_stiffness",
          "rotational_damping"},
         &Loader::bushing},
        {"wheel_contact", T::kWheelContact, {"name", "type", "body", "point", "stiffness", "radius", "axis", "ground"},
         &Loader::wheel_contact},
        {"user", T::kUser, {"name", "type", "body1", "point1", "body2", "point2", "law", "parameters"},
         &Loader::user_force},
    };
    return table;
  }

  void force(const YAML::Node& n, Model& m) {
    static const Fields general = {"name", "type", "body1", "point1", "body2", "point2", "body", "point",
                                   "stiffness", "damping", "free_length", "fx", "fy", "fz", "radius", "axis",
                                   "ground", "law", "parameters", "frame", "torque", "coordinate", "rest",
                                   "rest_deg", "rotational_stiffness", "rotational_damping"};
    if (!check_keys(n, "force", general)) return;
    ForceSpec f;
    f.where = where(n);
    f.name = name(n);
    const std::string type = text(n, "type", "", true);
    const auto& types = force_types();
    const auto it = std::find_if(types.begin(), types.end(), [&](const ForceType& t) { return type == t.name; });
    if (it != types.end()) {
      applies(n, "a " + type + " force", general, it->fields);
      f.type = it->type;
      (this->*(it->read))(n, f);
    } else if (!type.empty()) {
      std::string names;
      for (const ForceType& t : types) names += (names.empty() ? "" : ", ") + std::string(t.name);
      error(n["type"], "type", "unknown force type " + quote(type) + " (" + names + ")");
    }
    m.forces.push_back(f);
  }

  void sensor(const YAML::Node& n, Model& m) {
    static const Fields general = {"name", "type", "body", "point", "component", "axis", "coordinate", "force", "expression", "wrap"};
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
        {"kinetic_energy", T::kKineticEnergy}, {"potential_energy", T::kPotentialEnergy}};
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
      default:  // whole-system sensors
        applies(n, what, general, {"name", "type"});
        break;
    }
    m.sensors.push_back(s);
  }

  // `initial_velocities` of a dynamics step: coordinate names to rates.
  void initial_velocities(const YAML::Node& n, const std::string& type, AnalysisStep& s) {
    if (!has(n, "initial_velocities")) return;
    const YAML::Node iv = n["initial_velocities"];
    if (type == "kinematics")
      error(iv, "initial_velocities", "does not apply to a kinematics step (its velocities follow from the drives)");
    record(n, "initial_velocities", iv);
    if (!iv.IsMap()) {
      error(iv, "initial_velocities", "expected a mapping of coordinate names to rates, got " + describe(iv));
      return;
    }
    for (const auto& kv : iv) {
      const auto cname = key_of(kv.first, "initial_velocities");
      if (!cname) continue;
      if (const auto x = to_number(kv.second, "initial_velocities." + *cname)) s.initial_velocities.emplace_back(*cname, *x);
    }
  }

  // A true/false field (absent: `out` unchanged).
  void flag(const YAML::Node& n, const char* key, bool& out) {
    if (!has(n, key)) return;
    const std::string v = text(n, key, "false");
    if (v == "true" || v == "false") out = v == "true";
    else if (n[key].IsScalar()) error(n[key], key, "expected true or false, got " + quote(v));
  }

  // The time span, tolerances and model scales of a step, each checked against its range.
  void step_span_and_tolerances(const YAML::Node& n, bool integrates, AnalysisStep& s) {
    const auto t0 = opt_number(n, "t0"), t_end = opt_number(n, "t_end"), output_step = opt_number(n, "output_step");
    const auto rtol = opt_number(n, "rtol"), atol = opt_number(n, "atol"), max_step = opt_number(n, "max_step");
    s.t0 = t0.value_or(s.t0);
    s.t_end = t_end.value_or(s.t_end);
    s.output_step = output_step.value_or(s.output_step);
    s.rtol = rtol.value_or(s.rtol);
    s.atol = atol.value_or(s.atol);
    s.max_step = max_step.value_or(s.max_step);
    // Tolerances in model units (formulation/tolerance_scales.h): absent means derived.
    for (auto [key, field] : {std::pair<const char*, double*>{"length_scale", &s.length_scale}, {"time_scale", &s.time_scale},
                              {"atol_rotation", &s.atol_rotation}, {"atol_velocity", &s.atol_velocity}}) {
      const auto x = opt_number(n, key);
      if (x && !(*x > 0)) error(n[key], key, "must be positive, got " + format_number(*x));
      else if (x) *field = *x;
    }
    const bool times_ok = (t0 || !has(n, "t0")) && (t_end || !has(n, "t_end"));
    if (integrates && times_ok && !(s.t_end > s.t0))
      error(at(n, "t_end"), "t_end", "the time span is empty (t_end " + format_number(s.t_end) +
                                         " must exceed t0 " + format_number(s.t0) + ")");
    if (integrates && (output_step || !has(n, "output_step"))) {
      const std::string why = output_step_range_error(s.output_step, times_ok ? s.t0 : 0, times_ok ? s.t_end : 0);
      if (!why.empty()) error(at(n, "output_step"), "output_step", why);
    }
    if (rtol && !rtol_range_error(s.rtol).empty()) error(n["rtol"], "rtol", rtol_range_error(s.rtol));
    if (atol && !atol_range_error(s.atol).empty()) error(n["atol"], "atol", atol_range_error(s.atol));
    if (max_step && s.max_step < 0) error(n["max_step"], "max_step", "must not be negative (0: no limit), got " + format_number(s.max_step));
  }

  // The formulation and its parameters (constraint scale, Baumgarte rates, penalty, Newton).
  void step_formulation(const YAML::Node& n, AnalysisStep& s) {
    s.formulation = text(n, "formulation", "index3");
    if (has(n, "formulation") && n["formulation"].IsScalar() && !find_formulation(s.formulation))
      error(n["formulation"], "formulation", "unknown formulation " + quote(s.formulation) + " (" + formulation_names() + ")");
    const auto scale = opt_number(n, "constraint_scale");
    s.constraint_scale = scale.value_or(s.constraint_scale);
    if (scale && s.constraint_scale < 0)
      error(n["constraint_scale"], "constraint_scale", "must not be negative (0: automatic), got " + format_number(s.constraint_scale));
    s.newton_convergence = opt_number(n, "newton_convergence").value_or(s.newton_convergence);
    if (!(s.newton_convergence > 0 && s.newton_convergence <= 1))
      error(at(n, "newton_convergence"), "newton_convergence", "out of range (0, 1], got " + format_number(s.newton_convergence));
    s.newton_solve = text(n, "newton_solve", s.newton_solve);
    if (has(n, "newton_solve") && n["newton_solve"].IsScalar() && s.newton_solve != "full" && s.newton_solve != "reduced")
      error(n["newton_solve"], "newton_solve", "expected full or reduced, got " + quote(s.newton_solve));
    s.baumgarte_alpha = opt_number(n, "baumgarte_alpha").value_or(s.baumgarte_alpha);
    s.baumgarte_beta = opt_number(n, "baumgarte_beta").value_or(s.baumgarte_beta);
    if (has(n, "baumgarte_alpha") && !(s.baumgarte_alpha >= 0)) error(at(n, "baumgarte_alpha"), "baumgarte_alpha", "must not be negative, got " + format_number(s.baumgarte_alpha));
    if (has(n, "baumgarte_beta") && !(s.baumgarte_beta >= 0)) error(at(n, "baumgarte_beta"), "baumgarte_beta", "must not be negative, got " + format_number(s.baumgarte_beta));
    s.penalty = opt_number(n, "penalty").value_or(s.penalty);
    if (!(s.penalty > 0)) error(at(n, "penalty"), "penalty", "must be positive, got " + format_number(s.penalty));
  }

  // The checks a step reports on: the assembly mode check and the quiet sensors.
  void step_checks(const YAML::Node& n, bool integrates, AnalysisStep& s) {
    s.mode_check = text(n, "mode_check", s.mode_check);
    if (has(n, "mode_check") && n["mode_check"].IsScalar() && s.mode_check != "warn" && s.mode_check != "fail" &&
        s.mode_check != "off")
      error(n["mode_check"], "mode_check", "expected warn, fail or off, got " + quote(s.mode_check));
    const auto mode_deg = opt_number(n, "mode_check_deg");
    s.mode_check_deg = mode_deg.value_or(s.mode_check_deg);
    if (mode_deg && !(s.mode_check_deg > 0 && s.mode_check_deg <= 180))
      error(n["mode_check_deg"], "mode_check_deg", "out of range (0, 180], got " + format_number(s.mode_check_deg));
    s.quiet_until = opt_number(n, "quiet_until").value_or(s.quiet_until);
    s.quiet_sensors = names(n, "quiet_sensors");
    if (integrates && !s.quiet_sensors.empty() && !has(n, "quiet_until"))
      error(n["quiet_sensors"], "quiet_until", "missing (quiet_sensors are watched until quiet_until)");
  }

  AnalysisStep step(const YAML::Node& n) {
    AnalysisStep s;
    s.where = where(n);
    const Fields& general = analysis_fields();
    if (!check_keys(n, "analysis step", general)) return s;
    const std::string type = text(n, "type", "", true);
    const AnalysisType* kind = find_analysis_type(type);
    if (kind) s.type = kind->type;
    else if (!type.empty()) error(n["type"], "type", "unknown analysis " + quote(type) + " (" + analysis_type_names() + ")");
    const bool integrates = kind && kind->integrates;
    if (kind) applies(n, (std::string("aeiou").find(type[0]) == std::string::npos ? "a " : "an ") + type + " step", general,
                      kind->fields);
    initial_velocities(n, type, s);
    s.hold = names(n, "hold");
    s.release = names(n, "release");
    s.unknowns = names(n, "unknowns");
    step_span_and_tolerances(n, integrates, s);
    flag(n, "output_projection", s.output_projection);
    flag(n, "error_estimate", s.error_estimate);
    step_formulation(n, s);
    step_checks(n, integrates, s);
    return s;
  }

  // The `animation` section (cases/animation_spec.h), from the model file or the scene.
  void animation(const YAML::Node& n, AnimationSpec& a) {
    if (!check_keys(n, "animation", {"write", "frame_rate", "max_frames", "start", "end", "axis_length", "shapes"}))
      return;
    flag(n, "write", a.write);
    auto positive = [&](const char* key, double& x, bool zero_ok) {
      const auto v = opt_number(n, key);
      if (v && (zero_ok ? *v >= 0 : *v > 0)) x = *v;
      else if (v) error(n[key], key, std::string("must be ") + (zero_ok ? "zero or positive" : "positive") + ", got " + format_number(*v));
    };
    positive("frame_rate", a.frame_rate, false);
    positive("axis_length", a.axis_length, true);
    if (const auto m = opt_number(n, "max_frames")) {
      if (*m >= 2 && *m <= 1e7 && std::floor(*m) == *m) a.max_frames = static_cast<int>(*m);
      else error(n["max_frames"], "max_frames", "expected a whole number from 2 to 1e7, got " + format_number(*m));
    }
    a.start = opt_number(n, "start").value_or(a.start);
    a.end = opt_number(n, "end").value_or(a.end);
    if (!(a.end > a.start)) error(at(n, "end"), "end", "must exceed start");
    if (!has(n, "shapes")) return;
    if (!n["shapes"].IsSequence()) return error(n["shapes"], "shapes", "expected a list, got " + describe(n["shapes"]));
    a.shapes.clear();
    for (const auto& sn : n["shapes"]) {
      if (!check_keys(sn, "shape", {"body", "type", "center", "axis", "size", "radius", "length"})) continue;
      AnimationShape s;
      s.where = where(sn);
      s.body = name(sn, "body");
      const std::string type = text(sn, "type", "", true);
      s.center = vec3(sn, "center", s.center);
      s.axis = vec3(sn, "axis", s.axis);
      s.size = vec3(sn, "size", s.size, type == "box");
      s.radius = number(sn, "radius", 0, type == "cylinder" || type == "sphere");
      s.length = number(sn, "length", 0, type == "cylinder");
      if (type == "box") s.type = AnimationShape::Type::kBox;
      else if (type == "cylinder") s.type = AnimationShape::Type::kCylinder;
      else if (type == "sphere") s.type = AnimationShape::Type::kSphere;
      else if (has(sn, "type")) error(sn["type"], "type", "unknown shape " + quote(type) + " (box, cylinder, sphere)");
      if (type == "box" && !(s.size.minCoeff() > 0)) error(at(sn, "size"), "size", "edge lengths must be positive");
      if ((type == "cylinder" || type == "sphere") && !(s.radius > 0)) error(at(sn, "radius"), "radius", "must be positive");
      if (type == "cylinder" && !(s.length > 0)) error(at(sn, "length"), "length", "must be positive");
      if (!(s.axis.norm() > 0)) error(at(sn, "axis"), "axis", "must not be zero");
      a.shapes.push_back(s);
    }
  }

  // Model sections: a model file, or the scene itself (`patch`: entries named like one of the
  // model replace it).
  void sections(const YAML::Node& root, Model& m, bool patch) {
    if (has(root, "name")) m.name = text(root, "name", m.name);
    if (has(root, "gravity")) m.gravity = vec3(root, "gravity", m.gravity);
    if (has(root, "ground") && check_keys(root["ground"], "ground", {"points"})) {
      record(root, "ground", root["ground"]);
      std::map<std::string, Vec3> points;
      named_points(root["ground"], points);
      for (const auto& [pname, xyz] : points) m.ground_points[pname] = xyz;  // the scene's replace the model's
    }
    auto each = [&](const char* key, auto&& fn) {
      if (!has(root, key)) return;
      const YAML::Node list = root[key];
      if (!list.IsSequence()) {
        error(list, key, "expected a list, got " + describe(list));
        return;
      }
      for (const auto& item : list) fn(item);
    };
    // A scene item replaces the model's item of its name (found through a name -> index map, so
    // that loading stays linear in the number of items); two of one name in this file are an error.
    struct Names {
      std::set<std::string> added_here;
      std::unordered_map<std::string, size_t> index;  // first item of each name
      bool built = false;
    };
    auto replace = [&](auto& vec, size_t before, Names& names, const char* what) {
      if (!patch || vec.size() == before) return;
      if (!names.built) {
        for (size_t k = 0; k < before; ++k) names.index.emplace(vec[k].name, k);
        names.built = true;
      }
      auto added = std::move(vec.back());
      vec.pop_back();
      if (!added.name.empty() && !names.added_here.insert(added.name).second) {  // keep the first
        error_at(lines->line(added.where, "name"), "name", std::string(what) + " " + quote(added.name) + " is defined twice in this file");
        return;
      }
      const auto it = names.index.find(added.name);
      if (it != names.index.end()) {
        vec[it->second] = std::move(added);
        return;
      }
      names.index.emplace(added.name, vec.size());
      vec.push_back(std::move(added));
    };
    Names b_names, j_names, c_names, f_names, s_names;
    each("bodies", [&](const YAML::Node& n) { size_t b = m.bodies.size(); body(n, m); replace(m.bodies, b, b_names, "body"); });
    each("joints", [&](const YAML::Node& n) { size_t b = m.joints.size(); joint(n, m); replace(m.joints, b, j_names, "joint"); });
    each("cuts", [&](const YAML::Node& n) { size_t b = m.cuts.size(); cut(n, m); replace(m.cuts, b, c_names, "cut"); });
    each("forces", [&](const YAML::Node& n) { size_t b = m.forces.size(); force(n, m); replace(m.forces, b, f_names, "force"); });
    each("sensors", [&](const YAML::Node& n) { size_t b = m.sensors.size(); sensor(n, m); replace(m.sensors, b, s_names, "sensor"); });
    if (has(root, "coordinates")) {
      const YAML::Node c = root["coordinates"];
      if (!c.IsMap()) {
        error(c, "coordinates", "expected a mapping name: {initial, mode, drive}, got " + describe(c));
      } else {
        std::set<std::string> seen;
        for (const auto& kv : c) {
          const auto cname = key_of(kv.first, "coordinates");
          if (!cname) continue;
          if (cname->empty()) error(kv.first, "coordinates", "a coordinate needs a name");
          else if (!seen.insert(*cname).second) error(kv.first, "coordinates." + *cname, "given twice");
          else coordinate(*cname, kv.first, kv.second, m, patch);
        }
      }
    }
  }
};

// The size limit of scene and model files in MB: MBDAE_MAX_SCENE_MB if set (a positive number),
// else kDefaultMaxFileMB. Returns 0 (and says why) for a value that is not a positive number.
double max_file_mb(std::string& why) {
  const char* s = std::getenv("MBDAE_MAX_SCENE_MB");
  if (!s) return kDefaultMaxFileMB;
  char* end = nullptr;
  const double mb = std::strtod(s, &end);
  if (*s && end && *end == '\0' && mb > 0 && std::isfinite(mb)) return mb;
  why = "MBDAE_MAX_SCENE_MB must be a positive number of megabytes, got " + quote(s);
  return 0;
}

// Reads a file within the size limit (max_file_mb); on failure returns nullopt and says why.
std::optional<std::string> read_text_file(const std::string& path, std::string& why) {
  const double limit_mb = max_file_mb(why);
  if (limit_mb <= 0) return std::nullopt;
  const double limit_bytes = limit_mb * 1048576.0;
  std::error_code ec;
  const auto st = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(st)) {
    why = "no such file";
    return std::nullopt;
  }
  if (!std::filesystem::is_regular_file(st)) {
    why = "not a regular file";
    return std::nullopt;
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    why = "cannot open it";
    return std::nullopt;
  }
  std::string text;
  char buf[65536];
  while (in.read(buf, sizeof buf) || in.gcount() > 0) {
    text.append(buf, static_cast<size_t>(in.gcount()));
    if (static_cast<double>(text.size()) > limit_bytes) {
      why = "larger than " + format_number(limit_mb) + " MB; set MBDAE_MAX_SCENE_MB to read larger files";
      return std::nullopt;
    }
  }
  return text;
}

// The line (1-based) of the '---' that starts the document whose content begins at 0-based line
// `content` (the last '---' line up to it; the first '---' after line 1 if the document is empty).
// True if `line` is the document marker `marker` ("---" or "...") at column 0.
bool document_marker(const std::string& line, const char* marker) {
  return line.compare(0, 3, marker) == 0 && (line.size() == 3 || line[3] == ' ' || line[3] == '\t' || line[3] == '\r');
}

// The YAML content of one line, trimmed: the line after a start marker ("---"), empty for a blank
// line, a comment, a directive ("%") or an end marker ("...").
std::string line_content(const std::string& line) {
  if (document_marker(line, "...") || line.compare(0, 1, "%") == 0) return "";
  const std::string rest = document_marker(line, "---") ? line.substr(3) : line;
  const size_t a = rest.find_first_not_of(" \t\r");
  if (a == std::string::npos || rest[a] == '#') return "";
  return rest.substr(a, rest.find_last_not_of(" \t\r") - a + 1);
}

// The first line (1-based) with YAML content and that content cut at 40 characters; 0 if none.
int first_content_line(const std::string& text, std::string& content) {
  std::istringstream in(text);
  std::string line;
  for (int k = 0; std::getline(in, line); ++k) {
    const std::string c = line_content(line);
    if (c.empty()) continue;
    content = c.substr(0, 40);
    return k + 1;
  }
  return 0;
}

// The line (1-based) where a second YAML document starts in `text`, 0 if none: a start marker
// ("---") after content, or content after an end marker ("..."). A scan of the text instead of
// counting yaml-cpp's documents: YAML::LoadAll (yaml-cpp 0.7) never returns on some invalid
// inputs (a file holding a lone ',' hung `mbdae check`; found by the fuzz target).
int second_document_line(const std::string& text) {
  std::istringstream in(text);
  std::string line;
  bool content = false, ended = false;
  for (int k = 0; std::getline(in, line); ++k) {
    const bool start = document_marker(line, "---");
    if (start && (content || ended)) return k + 1;
    if (document_marker(line, "...")) {
      ended = ended || content;
      continue;
    }
    if (line_content(line).empty()) continue;
    if (ended) return k + 1;
    content = true;
  }
  return 0;
}

std::optional<YAML::Node> parse(const std::string& text, const std::string& path, std::vector<SceneIssue>& issues) {
  try {
    // One document per file: a second one (after '---') would be silently ignored by YAML::Load.
    if (const int second = second_document_line(text)) {
      issues.push_back({path, second, "",
                        "a second YAML document ('---') is not read; a scene or model file holds one document"});
      return std::nullopt;
    }
    const YAML::Node root = YAML::Load(text);
    // yaml-cpp returns an empty document for some invalid text (a lone ','): say so instead of
    // "the scene is empty".
    std::string first;
    const int line = first_content_line(text, first);
    if (root.IsNull() && line > 0 && first != "~" && first != "null" && first != "Null" && first != "NULL") {
      issues.push_back({path, line, "", "YAML syntax error: no YAML value could be read from '" + first + "'"});
      return std::nullopt;
    }
    return root;
  } catch (const YAML::Exception& e) {
    issues.push_back({path, e.mark.line >= 0 ? e.mark.line + 1 : 0, "", "YAML syntax error: " + e.msg});
    return std::nullopt;
  }
}

// The model file the scene's `model` field names, parsed into `mroot` (read once: kept in
// src.models). False when the field is empty or the file cannot be read or parsed.
bool read_model_tree(SceneSource& src, Loader& l, const YAML::Node& root, std::vector<SceneIssue>& issues,
                     std::optional<YAML::Node>& mroot, std::string& model_path) {
  const std::string model = l.name(root, "model");
  if (model.empty()) return false;
  model_path = (std::filesystem::path(src.path).parent_path() / model).string();
  std::string why;
  auto known = src.models.find(model_path);
  const auto model_text =
      known != src.models.end() ? std::optional<std::string>(known->second) : read_text_file(model_path, why);
  if (!model_text) l.error(root["model"], "model", "cannot read model file '" + model_path + "' (" + why + ")");
  else mroot = parse(src.models[model_path] = *model_text, model_path, issues);
  return mroot.has_value();
}

// The model file's sections (the scene's own are read after them and add to or patch them).
bool load_model_sections(const YAML::Node& mroot, const std::string& model_path, Scene& scene,
                         std::vector<SceneIssue>& issues, FieldLines& lines) {
  Loader l{model_path, &issues, &lines};
  if (!l.check_keys(mroot, "model", {"name", "gravity", "ground", "bodies", "joints", "coordinates", "cuts", "forces",
                                     "sensors", "animation"}))
    return false;
  l.sections(mroot, scene.model, false);
  if (l.has(mroot, "animation")) l.animation(mroot["animation"], scene.animation);
  return true;
}

// `remove`: forces, sensors and cuts of the model dropped by name.
void remove_items(Loader& l, const YAML::Node& root, Model& m) {
  for (const std::string& name : l.names(root, "remove")) {
    bool found = false;
    auto drop = [&](auto& vec) {
      for (auto it = vec.begin(); it != vec.end(); ++it)
        if (it->name == name) {
          vec.erase(it);
          found = true;
          return;
        }
    };
    drop(m.forces);
    drop(m.sensors);
    drop(m.cuts);
    if (!found) l.error(root["remove"], "remove", "nothing named " + quote(name) + " to remove (forces, sensors, cuts)");
  }
}

// `analysis`: one step or a list of them, at most one of which integrates in time.
void analysis_steps(Loader& l, const YAML::Node& root, Scene& scene) {
  if (l.has(root, "analysis")) {
    const YAML::Node a = root["analysis"];
    if (a.IsSequence()) {
      if (a.size() == 0) l.error(a, "analysis", "no analysis steps (assembly, equilibrium, kinematics or dynamics)");
      for (const auto& s : a) scene.steps.push_back(l.step(s));
    } else {
      scene.steps.push_back(l.step(a));
    }
  } else {
    l.error(root, "analysis", "missing (assembly, equilibrium, kinematics or dynamics steps)");
  }
  int integrations = 0;
  for (const auto& s : scene.steps)
    if (integrates(s)) ++integrations;
  if (integrations > 1) l.error(root["analysis"], "analysis", "at most one kinematics or dynamics step per scene");
}

// Animation shapes, output columns, the redundancy policy.
void scene_options(Loader& l, const YAML::Node& root, Scene& scene, std::vector<SceneIssue>& issues) {
  if (l.has(root, "animation")) l.animation(root["animation"], scene.animation);
  for (const auto& shape : scene.animation.shapes)
    if (std::none_of(scene.model.bodies.begin(), scene.model.bodies.end(),
                     [&](const BodySpec& b) { return b.name == shape.body; }))
      issues.push_back({shape.where.file, shape.where.line, "body",
                        "animation shape on " + quote(shape.body) + ", which is not a body"});
  scene.columns = l.names(root, "output");
  if (root["redundant_constraints"]) {
    scene.redundant_constraints = l.text(root, "redundant_constraints", "remove");
    if (scene.redundant_constraints != "remove" && scene.redundant_constraints != "fail")
      l.error(root["redundant_constraints"], "redundant_constraints",
              "expected remove or fail, got '" + scene.redundant_constraints + "'");
  }
}

// Loads into `scene` from `src` (the model file is read once and kept in src.models), with
// src.overrides applied to the parsed trees first (their places in `targets`); returns false if
// the scene could not be read far enough to be validated.
bool load(SceneSource& src, Scene& scene, std::vector<SceneIssue>& issues, FieldLines& lines,
          std::vector<OverrideTarget>& targets) {
  const std::string& path = src.path;
  const auto parsed = parse(src.text, path, issues);
  if (!parsed) return false;
  const YAML::Node root = *parsed;
  Loader l{path, &issues, &lines};
  if (!root.IsMap()) {
    issues.push_back({path, Loader::line_of(root), "",
                      root.IsNull() ? "the scene is empty" : "the scene must be a YAML mapping (field: value lines)"});
    return false;
  }
  lines.scene_root = l.where(root);
  std::optional<YAML::Node> mroot;
  std::string model_path;
  bool complete = !l.has(root, "model") || read_model_tree(src, l, root, issues, mroot, model_path);
  if (!complete && !src.overrides.empty()) return false;
  for (const auto& [p, v] : src.overrides)
    targets.push_back(apply_override(root, path, mroot ? &*mroot : nullptr, model_path, p, v));
  l.check_keys(root, "scene", {"model", "name", "gravity", "ground", "bodies", "joints", "coordinates", "cuts", "forces",
                               "sensors", "remove", "analysis", "output", "redundant_constraints", "animation"});
  if (mroot && !load_model_sections(*mroot, model_path, scene, issues, lines)) complete = false;
  l.sections(root, scene.model, true);
  scene_options(l, root, scene, issues);
  remove_items(l, root, scene.model);
  analysis_steps(l, root, scene);
  return complete;
}

// Messages sorted by file (in order of first appearance) and line, without repeats.
std::vector<std::string> messages(const std::vector<SceneIssue>& issues) {
  std::vector<std::string> files;
  for (const auto& i : issues)
    if (std::find(files.begin(), files.end(), i.file) == files.end()) files.push_back(i.file);
  std::vector<const SceneIssue*> order;
  for (const auto& i : issues) order.push_back(&i);
  auto rank = [&](const SceneIssue* i) {
    const long f = std::find(files.begin(), files.end(), i->file) - files.begin();
    return std::make_pair(f, i->line > 0 ? i->line : 1 << 30);
  };
  std::stable_sort(order.begin(), order.end(), [&](const SceneIssue* a, const SceneIssue* b) { return rank(a) < rank(b); });
  std::vector<std::string> out;
  std::set<std::string> seen;
  for (const SceneIssue* i : order) {
    std::string t = i->text();
    if (seen.insert(t).second) out.push_back(std::move(t));
  }
  return out;
}

}  // namespace

// Loads a scene from its source; issues at an override's place say which parameter set it.
Scene load_source(SceneSource src) {
  Scene scene;
  scene.file = src.path;
  std::vector<SceneIssue> issues;
  std::vector<OverrideTarget> targets;
  FieldLines lines;
  bool complete = false;
  try {
    complete = load(src, scene, issues, lines, targets);
  } catch (const YAML::Exception& e) {  // a node shape the loader did not expect
    issues.push_back({src.path, e.mark.line >= 0 ? e.mark.line + 1 : 0, "", "cannot read the scene: " + e.msg});
  }
  if (complete) validate_scene(scene, lines, issues);
  for (auto& i : issues)
    for (const auto& t : targets)
      if (i.file == t.file && i.line == t.line) i.message += " (set by parameter " + t.path + " = " + quote(t.value) + ")";
  if (!issues.empty()) throw SceneError(messages(issues));
  scene.source = std::make_shared<const SceneSource>(std::move(src));
  return scene;
}

Scene load_scene_text(const std::string& text, const std::string& path) {
  SceneSource src;
  src.path = path;
  src.text = text;
  return load_source(std::move(src));
}

Scene reload_scene(const Scene& scene, const std::vector<std::pair<std::string, std::string>>& overrides) {
  if (!scene.source)
    throw SceneError({ModelError::format(scene.file, 0, "", "this scene was not loaded from YAML; it has no parameters to set")});
  SceneSource src = *scene.source;
  src.overrides.insert(src.overrides.end(), overrides.begin(), overrides.end());
  return load_source(std::move(src));
}

std::vector<ParameterEntry> scene_parameters(const Scene& scene) {
  if (!scene.source)
    throw SceneError({ModelError::format(scene.file, 0, "", "this scene was not loaded from YAML; it has no parameters")});
  SceneSource src = *scene.source;
  std::vector<SceneIssue> issues;
  FieldLines lines;
  const auto parsed = parse(src.text, src.path, issues);
  if (!parsed || !parsed->IsMap()) throw SceneError(messages(issues));
  YAML::Node root = *parsed;
  Loader l{src.path, &issues, &lines};
  std::optional<YAML::Node> mroot;
  std::string model_path;
  if (l.has(root, "model")) read_model_tree(src, l, root, issues, mroot, model_path);
  for (const auto& [p, v] : src.overrides) apply_override(root, src.path, mroot ? &*mroot : nullptr, model_path, p, v);
  return list_parameters(root, src.path, mroot ? &*mroot : nullptr, model_path);
}

Scene load_scene(const std::string& path) {
  std::string why;
  const auto text = read_text_file(path, why);
  if (!text) throw SceneError({path + ": cannot read the file (" + why + ")"});
  return load_scene_text(*text, path);
}

}  // namespace mbdae
