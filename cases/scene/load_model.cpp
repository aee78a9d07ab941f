// Reading the model sections (sections(): bodies, joints, cuts, forces, sensors in order) and bodies (inertia, named points), joints and their coordinates, cuts.
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
#include "formulation/cut_types.h"
#include "formulation/formulation_registry.h"

namespace mbdae::scene_load {


void Loader::inertia(const YAML::Node& in, BodySpec& b) {
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
void Loader::named_points(const YAML::Node& n, std::map<std::string, Vec3>& points) {
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


void Loader::body(const YAML::Node& n, Model& m) {
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


void Loader::joint(const YAML::Node& n, Model& m) {
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


void Loader::coordinate(const std::string& name, const YAML::Node& key, const YAML::Node& n, Model& m, bool patch) {
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


void Loader::cut(const YAML::Node& n, Model& m) {
  static const Fields general = {"name", "type", "body1", "point1", "body2", "point2", "axis1", "axis2", "ref1", "ref2",
                                 "distance"};
  if (!check_keys(n, "cut", general)) return;
  CutSpec c;
  c.where = where(n);
  c.name = name(n);
  const std::string type = text(n, "type", "", true);
  // The cut-type table (formulation/cut_types.h): the type and the fields that apply to it.
  const CutType* row = find_cut_type(type);
  if (row) {
    c.type = row->type;
    Fields fields = {"name", "type", "body1", "point1", "body2", "point2"};
    fields.insert(fields.end(), row->fields.begin(), row->fields.end());
    applies(n, "a " + type + " cut", general, fields);
  } else if (!type.empty()) {
    error(n["type"], "type", "unknown cut type " + quote(type) + " (" + cut_type_names() + ")");
  }
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
void Loader::body_point(const YAML::Node& n, const char* key, std::string& point, Vec3& xyz, bool& at_xyz) {
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


// Model sections: a model file, or the scene itself (`patch`: entries named like one of the
// model replace it).
void Loader::sections(const YAML::Node& root, Model& m, bool patch) {
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

}  // namespace mbdae::scene_load
