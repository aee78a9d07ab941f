#include "formulation/model_rules.h"

#include <algorithm>
#include <set>

#include "core/errors.h"
#include "core/expression.h"
#include "formulation/cut_types.h"
#include "formulation/force_types.h"
#include "formulation/forces.h"

namespace mbdae {

std::string ModelIssue::shown_field() const {
  std::string f = shown.empty() ? field : shown;
  const size_t bracket = f.find('[');
  if (bracket != std::string::npos) f.erase(bracket);
  return f;
}

namespace {

// The evaluation stack of Expression::evaluate (core/expression.cpp) holds 64 values.
constexpr int kExpressionStack = 64;

size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diag = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

// "; did you mean 'x'?" for the closest candidate within a small edit distance.
template <class Names>
std::string suggestion(const std::string& name, const Names& candidates) {
  if (name.size() > 64) return "";
  std::string best;
  size_t best_d = std::max<size_t>(1, std::min<size_t>(2, name.size() / 3));
  for (const auto& c : candidates) {
    if (c.size() > 64) continue;
    const size_t d = edit_distance(name, c);
    if (d <= best_d && (best.empty() || d < best_d)) {
      best = c;
      best_d = d;
    }
  }
  return best.empty() ? "" : "; did you mean '" + best + "'?";
}

}  // namespace

std::string did_you_mean(const std::string& name, const std::vector<std::string>& candidates) {
  return suggestion(name, candidates);
}

namespace {

std::string indexed(const std::string& field, size_t k) { return field + "[" + std::to_string(k) + "]"; }

struct ModelRules : ModelNames {
  const Model& m;
  std::vector<ModelIssue>& issues;

  ModelRules(const Model& model, std::vector<ModelIssue>& out) : m(model), issues(out) {}


  // `field` locates the line (it may carry an index); the message shows it without the index,
  // or `shown` if given.
  void report(const SourceLocation& item, const std::string& field, const std::string& message,
              const std::string& shown = "") {
    issues.push_back({item, field, message, shown});
  }
  std::string at(const SourceLocation& first, const SourceLocation& here) const {
    if (first.file == here.file) return "line " + std::to_string(first.line);
    return first.file + ":" + std::to_string(first.line);
  }
  bool known_body(const std::string& b) const { return b == kGround || bodies.count(b); }
  // Records a named item in `names`; a second item of that name is reported where it stands.
  template <class Spec>
  void register_name(std::map<std::string, const Spec*>& names, const Spec& item, const char* kind) {
    if (item.name.empty()) return;
    auto [it, fresh] = names.emplace(item.name, &item);
    if (!fresh)
      report(item.where, "name", std::string(kind) + " '" + item.name + "' is defined twice (first at " +
                                     at(it->second->where, item.where) + ")");
  }
  std::vector<std::string> body_names() const {
    std::vector<std::string> v = {kGround};
    for (const auto& [n, b] : bodies) v.push_back(n);
    return v;
  }
  template <class Map>
  static std::vector<std::string> keys(const Map& map) {
    std::vector<std::string> v;
    for (const auto& kv : map) v.push_back(kv.first);
    return v;
  }
  std::string no_body(const std::string& name) const {
    return "no body named '" + name + "'" + suggestion(name, body_names());
  }

  std::string ground_points_text() const {
    std::string list = "origin";
    for (const auto& kv : m.ground_points) list += ", " + kv.first;
    return "its points: " + list + "; name more under ground: {points: ...}";
  }

  // A body and one of its points: "" or "origin" (the body frame's origin), "com", or a named
  // point. Ground has only its origin.
  void check_point(const SourceLocation& w, const std::string& who, const std::string& body_field,
                   const std::string& body, const std::string& point_field, const std::string& point) {
    if (body.empty()) return;  // reported as missing by the loader
    if (!known_body(body)) {
      report(w, body_field, who + no_body(body));
      return;
    }
    if (point.empty() || point == "origin") return;
    if (body == kGround) {
      if (!m.ground_points.count(point))
        report(w, point_field, who + "ground has no point '" + point + "' (" + ground_points_text() +
                                   "); expected a point name or [x, y, z]" + suggestion(point, keys(m.ground_points)));
      return;
    }
    if (point == "com") return;
    const BodySpec& b = *bodies.at(body);
    if (b.points.count(point)) return;
    std::vector<std::string> names = {"origin", "com"};
    for (const auto& kv : b.points) names.push_back(kv.first);
    std::string list;
    for (size_t k = 0; k < names.size() && k < 12; ++k) list += (k ? ", " : "") + names[k];
    if (names.size() > 12) list += ", ...";
    report(w, point_field, who + "body '" + body + "' has no point '" + point + "' (its points: " + list +
                               "); expected a point name or [x, y, z]" + suggestion(point, names));
  }

  void check_bodies() {
    for (const auto& b : m.bodies) {
      if (b.name.empty()) continue;
      if (b.name == kGround) {
        report(b.where, "name", "'ground' is reserved for the fixed frame; name the body differently");
        continue;
      }
      register_name(bodies, b, "body");
    }
  }

  void check_chain(const JointSpec& j, const std::string& who) {
    for (const auto& problem : chain_problems(j.chain)) report(j.where, "chain", who + problem);
  }

  void check_joints() {
    std::map<std::string, const JointSpec*> names;
    for (const auto& j : m.joints) {
      const std::string who = "joint '" + j.name + "': ";
      register_name(names, j, "joint");
      if (!j.parent.empty() && !known_body(j.parent)) report(j.where, "parent", who + no_body(j.parent));
      if (!j.child.empty()) {
        if (j.child == kGround) {
          report(j.where, "child", who + "ground cannot be the child of a joint (it is the fixed frame)");
        } else if (!bodies.count(j.child)) {
          report(j.where, "child", who + no_body(j.child));
        } else {
          // A joint from a body to itself is kept in the tree as a loop of one body.
          if (j.child == j.parent) report(j.where, "parent", who + "joins body '" + j.child + "' to itself");
          auto [it, fresh] = joint_of_child.emplace(j.child, &j);
          if (!fresh)
            report(j.where, "child", who + "body '" + j.child + "' is already the child of joint '" +
                                         it->second->name + "' (at " + at(it->second->where, j.where) +
                                         "); a body has one tree joint, make the other a cut");
        }
      }
      check_chain(j, who);
      for (size_t k = 0; k < j.chain.size(); ++k) {
        const std::string& c = j.chain[k].coordinate;
        if (c.empty()) continue;  // the loader reported the count mismatch
        const std::string field = indexed("coordinates", k);
        if (!m.coordinates.count(c))
          report(j.where, field, who + "coordinate '" + c + "' has no entry under 'coordinates' (give at least its initial value)" +
                                     suggestion(c, keys(m.coordinates)));
        auto [it, fresh] = joint_of_coordinate.emplace(c, &j);
        if (!fresh)
          report(j.where, field, who + "coordinate '" + c + "' is " +
                                     (it->second == &j ? "used twice in this joint"
                                                       : "already used by joint '" + it->second->name + "' (at " +
                                                             at(it->second->where, j.where) + ")"));
      }
      if (!j.anchor_point.empty() && !j.parent.empty()) {
        if (j.parent == kGround) {
          if (!m.ground_points.count(j.anchor_point))
            report(j.where, "anchor", who + "ground has no point '" + j.anchor_point + "' (" + ground_points_text() +
                                          "); expected a point name or [x, y, z]" +
                                          suggestion(j.anchor_point, keys(m.ground_points)));
        } else if (bodies.count(j.parent) && j.parent != j.child) {
          const BodySpec& p = *bodies.at(j.parent);
          if (!p.points.count(j.anchor_point)) {
            std::string list;
            for (const auto& kv : p.points) list += (list.empty() ? "" : ", ") + kv.first;
            report(j.where, "anchor", who + "body '" + j.parent + "' has no point '" + j.anchor_point + "'" +
                                          (list.empty() ? " (it has no named points)" : " (its points: " + list + ")") +
                                          suggestion(j.anchor_point, keys(p.points)));
          }
        }
      }
    }
    for (const auto& [name, c] : m.coordinates)
      if (!joint_of_coordinate.count(name))
        report(c.where, "name", "coordinate '" + name + "' belongs to no joint" +
                                    suggestion(name, keys(joint_of_coordinate)),
               "coordinates." + name);
  }

  // Orders the tree from ground outwards, reports loops and bodies without a path to ground,
  // and finds which bodies are merged together by locked or welded joints.
  void check_tree() {
    // A joint whose child is missing or unknown probably was the tree joint of a body reported
    // below as having none: report that body only if no such joint exists.
    bool broken_child = false;
    for (const auto& j : m.joints) broken_child = broken_child || !bodies.count(j.child);
    tree = resolve_joint_tree(m.joints, joint_of_child, m.coordinates);
    // Each body without a path to ground is cut off by a root cause: an ancestor without a
    // joint, a loop, or a joint to an unknown parent (reported already).
    struct Cause {
      std::vector<std::string> loop;  // empty: `root` has no joint
      std::string root;
      std::vector<std::string> cut_off;
    };
    std::map<std::string, Cause> causes;
    std::vector<std::string> cause_order;
    for (const auto& b : m.bodies) {
      if (tree.placed.count(b.name) || !bodies.count(b.name) || bodies.at(b.name) != &b) continue;
      std::vector<std::string> path;
      std::string cur = b.name, key;
      Cause cause;
      for (;;) {
        auto seen = std::find(path.begin(), path.end(), cur);
        if (seen != path.end()) {  // a loop: the path from `cur` on
          cause.loop.assign(seen, path.end());
          key = "loop:" + *std::min_element(cause.loop.begin(), cause.loop.end());
          break;
        }
        path.push_back(cur);
        auto it = joint_of_child.find(cur);
        if (it == joint_of_child.end()) {
          cause.root = cur;
          key = "root:" + cur;
          break;
        }
        const std::string& parent = it->second->parent;
        if (parent.empty() || !known_body(parent) || tree.placed.count(parent)) break;  // reported elsewhere
        cur = parent;
      }
      if (key.empty()) continue;
      auto [it, fresh] = causes.emplace(key, cause);
      if (fresh) cause_order.push_back(key);
      const bool in_cause = it->second.root == b.name ||
                            std::find(it->second.loop.begin(), it->second.loop.end(), b.name) != it->second.loop.end();
      if (!in_cause) it->second.cut_off.push_back(b.name);
    }
    for (const auto& key : cause_order) {
      const Cause& c = causes.at(key);
      std::string also;
      for (const auto& n : c.cut_off) also += (also.empty() ? "" : ", ") + ("'" + n + "'");
      if (!also.empty()) also = "; bodies hanging from " + std::string(c.loop.empty() ? "it" : "them") + " have none either: " + also;
      if (c.loop.empty()) {
        if (broken_child) continue;
        report(bodies.at(c.root)->where, "name",
               "body '" + c.root + "' has no joint to a parent (no path to ground)" + also);
        continue;
      }
      if (c.loop.size() == 1) continue;  // a joint from a body to itself, reported already
      // Report at the loop's joint that comes first in the file.
      const JointSpec* first = nullptr;
      std::string path, joints;
      for (const auto& n : c.loop) {
        const JointSpec* j = joint_of_child.at(n);
        if (!first || j < first) first = j;
        path += "'" + n + "' -> ";
        joints += (joints.empty() ? "'" : ", '") + j->name + "'";
      }
      path += "'" + c.loop.front() + "'";
      report(first->where, "parent",
             "the joint tree has a loop: " + path + " (child -> parent), so these bodies have no path to ground" +
                 also + "; make one of the joints " + joints + " a cut");
    }
  }

  bool same_rigid_body(const std::string& a, const std::string& b) const {
    auto ha = tree.host.find(a), hb = tree.host.find(b);
    return ha != tree.host.end() && hb != tree.host.end() && ha->second == hb->second;
  }

  // A weld or prismatic cut's frame: x along ref without its component along the axis (a zero
  // ref takes the body axis most perpendicular to it: formulation/system_cuts.cpp).
  void cut_reference_across_axis(const CutSpec& c, const std::string& who, const Vec3& axis, const Vec3& ref,
                                 const char* axis_field, const char* ref_field) {
    if (ref.isZero() || !(axis.norm() > 0)) return;
    const Vec3 z = axis.normalized();
    if ((ref - ref.dot(z) * z).norm() < 1e-6 * ref.norm())
      report(c.where, ref_field, who + ref_field + " is parallel to " + axis_field +
                                     "; give a reference direction across the axis");
  }

  void check_cuts() {
    std::map<std::string, const CutSpec*> names;
    for (const auto& c : m.cuts) {
      const std::string who = "cut '" + c.name + "': ";
      register_name(names, c, "cut");
      check_point(c.where, who, "body1", c.body1, "point1", c.point1);
      check_point(c.where, who, "body2", c.body2, "point2", c.point2);
      if (cut_type(c.type).frames) {
        cut_reference_across_axis(c, who, c.axis1, c.ref1, "axis1", "ref1");
        cut_reference_across_axis(c, who, c.axis2, c.ref2, "axis2", "ref2");
      }
      if (c.body1.empty() || c.body2.empty()) continue;
      if (c.body1 == c.body2)
        report(c.where, "body2", who + "joins body '" + c.body1 + "' to itself");
      else if (same_rigid_body(c.body1, c.body2))
        report(c.where, "body2", who + "joins two parts of the same rigid body ('" + c.body1 + "' and '" + c.body2 +
                                       "' are welded or locked together)");
    }
  }

  void check_forces() {
    for (const auto& f : m.forces) {
      const std::string who = "force '" + f.name + "': ";
      register_name(forces, f, "force");
      switch (force_type(f.type).attach) {  // the references of its row's attachment
        case ForceAttach::kTwoPoints:
          check_point(f.where, who, "body1", f.body1, "point1", f.point1);
          check_point(f.where, who, "body2", f.body2, "point2", f.point2);
          if (f.type == ForceSpec::Type::kBushing && !f.body1.empty() && !f.body2.empty() && known_body(f.body1) &&
              known_body(f.body2) && same_rigid_body(f.body1, f.body2))
            report(f.where, "body2", who + "a bushing between two parts of the same rigid body");
          break;
        case ForceAttach::kBodyPoint:
        case ForceAttach::kBody:
          check_point(f.where, who, "body", f.body1, "point", f.point1);
          if ((f.type == ForceSpec::Type::kPointForce || f.type == ForceSpec::Type::kTorque) && !f.body1.empty() &&
              known_body(f.body1) && same_rigid_body(f.body1, kGround)) {
            const std::string what = f.type == ForceSpec::Type::kTorque ? "a torque" : "a point force";
            report(f.where, "body", who + (f.body1 == kGround ? what + " on ground does nothing (ground does not move); apply it to a moving body"
                                                              : what + " on '" + f.body1 + "', which is fixed to ground (its joints to ground are locked or welds), does nothing"));
          }
          break;
        case ForceAttach::kCoordinate:
          if (!f.coordinate.empty() && !joint_of_coordinate.count(f.coordinate))
            report(f.where, "coordinate", who + "no joint coordinate named '" + f.coordinate + "'" +
                                              suggestion(f.coordinate, keys(joint_of_coordinate)));
          else if (tree.merged_coordinates.count(f.coordinate))
            report(f.where, "coordinate", who + "coordinate '" + f.coordinate + "' belongs to a locked joint (merged)");
          break;
      }
      if (f.type == ForceSpec::Type::kWheelContact && !f.body1.empty() && known_body(f.body1) &&
          same_rigid_body(f.body1, kGround))
        report(f.where, "body", who + (f.body1 == kGround ? std::string("a wheel contact needs a moving body, not ground")
                                                          : "wheel contact on '" + f.body1 +
                                                                "', which is fixed to ground (its joints to ground are locked or welds)"));
      if (f.type == ForceSpec::Type::kUser && !f.law.empty()) {
        const UserForceLaw* law = find_force_law(f.law);
        if (!law) {
          report(f.where, "law", who + "no force law named '" + f.law + "' is registered");
          continue;
        }
        std::string list;
        for (const auto& p : law->parameter_names) list += (list.empty() ? "" : ", ") + p;
        for (const auto& p : law->parameter_names)
          if (!f.parameters.count(p)) report(f.where, "parameters", who + "force law '" + f.law + "' needs parameter '" + p + "'");
        for (const auto& [p, v] : f.parameters)
          if (std::find(law->parameter_names.begin(), law->parameter_names.end(), p) == law->parameter_names.end())
            report(f.where, "parameters." + p, who + "force law '" + f.law + "' has no parameter '" + p + "' (" +
                                                   (list.empty() ? "it has none" : "its parameters: " + list) + ")" +
                                                   suggestion(p, law->parameter_names));
      }
    }
  }

  void check_sensors() {
    for (size_t k = 0; k < m.sensors.size(); ++k) {
      const SensorSpec& s = m.sensors[k];
      if (s.name.empty()) continue;
      auto [it, fresh] = sensor_index.emplace(s.name, k);
      if (!fresh)
        report(s.where, "name", "sensor '" + s.name + "' is defined twice (first at " +
                                    at(m.sensors[it->second].where, s.where) + ")");
    }
    std::map<std::string, int> before;  // sensors listed before the current one
    for (size_t k = 0; k < m.sensors.size(); ++k) {
      const SensorSpec& s = m.sensors[k];
      const std::string who = "sensor '" + s.name + "': ";
      using T = SensorSpec::Type;
      switch (s.type) {
        case T::kPosition:
        case T::kVelocity:
        case T::kAcceleration:
          check_point(s.where, who, "body", s.body, "point", s.point);
          break;
        case T::kAxis:
        case T::kAngularVelocity:
        case T::kAngularMomentum:
          if (!s.body.empty() && !known_body(s.body)) report(s.where, "body", who + no_body(s.body));
          break;
        case T::kCoordinate:
        case T::kCoordinateRate:
          if (!s.target.empty() && !joint_of_coordinate.count(s.target))
            report(s.where, "coordinate", who + "no joint coordinate named '" + s.target + "'" +
                                              suggestion(s.target, keys(joint_of_coordinate)));
          break;
        case T::kForceLength:
        case T::kForceValue:
          if (!s.target.empty() && !forces.count(s.target))
            report(s.where, "force", who + "no force named '" + s.target + "'" + suggestion(s.target, keys(forces)));
          break;
        case T::kExpression:
          check_expression(s, who, before);
          break;
        default:
          break;
      }
      before.emplace(s.name, static_cast<int>(k));
    }
  }

  // The expression components of point forces and torques, before anything is solved or written:
  // names (t, the force's parameters, sensors that a load may read), parameters that would hide a
  // sensor of the same name, and the nesting depth.
  void check_load_expressions() {
    std::set<std::string> expression_loads;
    for (const auto& f : m.forces)
      if (!f.expression[0].empty() || !f.expression[1].empty() || !f.expression[2].empty()) expression_loads.insert(f.name);
    for (const auto& f : m.forces) {
      if (!expression_loads.count(f.name)) continue;
      const std::string who = "force '" + f.name + "': ";
      for (const auto& [p, value] : f.parameters)
        if (sensor_index.count(p))
          report(f.where, "parameters." + p, who + "parameter '" + p + "' has the name of a sensor (in the expressions "
                                                   "it would hide the sensor); rename one of them");
      for (int c = 0; c < 3; ++c) {
        if (f.expression[c].empty()) continue;
        const char* component = force_type(f.type).components[c];
        const std::string field = component ? component : c == 0 ? "fx" : c == 1 ? "fy" : "fz";
        check_load_expression(f, who, field, f.expression[c], expression_loads);
      }
    }
  }

  void check_load_expression(const ForceSpec& f, const std::string& who, const std::string& field,
                             const std::string& text, const std::set<std::string>& expression_loads) {
    std::vector<std::string> problems;
    auto note = [&](const std::string& m) {
      if (std::find(problems.begin(), problems.end(), m) == problems.end()) problems.push_back(m);
    };
    try {
      const Expression e = Expression::compile(text, [&](const std::string& n) {
        if (n == "t" || f.parameters.count(n)) return 0;
        const auto it = sensor_index.find(n);
        if (it == sensor_index.end()) {
          note("unknown name '" + n + "' (names are t, the force's parameters and sensors)" +
               suggestion(n, keys(sensor_index)));
          return 0;
        }
        const SensorSpec& s = m.sensors[it->second];
        using T = SensorSpec::Type;
        if (s.type == T::kAcceleration || s.type == T::kExpression || s.type == T::kKineticEnergy ||
            s.type == T::kPotentialEnergy || (s.type == T::kAngularMomentum && s.body.empty()))
          note("sensor '" + n + "' cannot drive a load (loads read position, velocity, axis, coordinate, "
               "coordinate_rate, force_length, force_value, angular_velocity and a body's angular_momentum sensors)");
        else if ((s.type == T::kForceLength || s.type == T::kForceValue) && expression_loads.count(s.target))
          note("sensor '" + n + "' measures a load given by an expression (loads may not depend on each other)");
        return 0;
      });
      if (stack_depth(e) > kExpressionStack)
        note("the expression is nested too deeply (it needs " + std::to_string(stack_depth(e)) +
             " evaluation stack entries, at most " + std::to_string(kExpressionStack) + ")");
    } catch (const ExpressionError& e) {
      note(e.what());
    }
    for (const auto& p : problems) report(f.where, field, who + p);
  }

  // Evaluation stack entries the compiled code needs.
  static int stack_depth(const Expression& e) {
    int depth = 0, deepest = 0;
    for (const auto& in : e.code) {
      switch (in.op) {
        case Expression::Op::kConst:
        case Expression::Op::kVar: ++depth; break;
        case Expression::Op::kNeg:
        case Expression::Op::kCall1: break;
        default: --depth; break;
      }
      deepest = std::max(deepest, depth);
    }
    return deepest;
  }

  void check_expression(const SensorSpec& s, const std::string& who, const std::map<std::string, int>& before) {
    if (s.expression.empty()) return;
    std::vector<std::string> unknown;
    try {
      const Expression e = Expression::compile(s.expression, [&](const std::string& n) {
        auto it = before.find(n);
        if (it != before.end()) return it->second;
        if (std::find(unknown.begin(), unknown.end(), n) == unknown.end()) unknown.push_back(n);
        return 0;  // carry on to find every unknown name
      });
      const int deepest = stack_depth(e);
      if (deepest > kExpressionStack)
        report(s.where, "expression", who + "the expression is nested too deeply (it needs " + std::to_string(deepest) +
                                          " evaluation stack entries, at most " + std::to_string(kExpressionStack) + ")");
    } catch (const ExpressionError& e) {
      report(s.where, "expression", who + e.what());
    }
    for (const auto& n : unknown) {
      auto later = sensor_index.find(n);
      if (n == s.name)
        report(s.where, "expression", who + "the expression uses its own sensor '" + n + "'");
      else if (later != sensor_index.end())
        report(s.where, "expression", who + "sensor '" + n + "' is listed after this one (an expression may use only sensors listed before it)");
      else
        report(s.where, "expression", who + "unknown name '" + n + "' (names are sensors listed before this one, and pi)" +
                                          suggestion(n, keys(before)));
    }
  }

};

}  // namespace

std::vector<ModelIssue> check_model(const Model& m, ModelNames* names) {
  std::vector<ModelIssue> issues;
  ModelRules r(m, issues);
  r.check_bodies();
  r.check_joints();
  r.check_tree();
  r.check_cuts();
  r.check_forces();
  r.check_sensors();
  r.check_load_expressions();
  if (names) *names = static_cast<ModelNames&&>(r);
  return issues;
}

}  // namespace mbdae
