// The scene loader's reading state, internal to cases/scene/: where problems go (file, line,
// field) and the field readers that the section readers (load_*.cpp) share. One Loader per
// file read; its methods record every problem and go on, so a file reports all of them at once.
#pragma once

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "cases/scene/field_ranges.h"
#include "cases/scene/scene.h"
#include "cases/scene/scene_overrides.h"
#include "cases/scene/scene_validation.h"
#include "formulation/force_types.h"

namespace mbdae::scene_load {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

using Fields = std::vector<std::string>;

inline bool contains(const Fields& list, const std::string& s) { return std::find(list.begin(), list.end(), s) != list.end(); }
std::string join(const Fields& list);
// A scalar as shown in a message: quoted, control characters escaped, long text shortened.
std::string quote(const std::string& s);
std::string describe(const YAML::Node& n);

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

  std::optional<double> to_number(const YAML::Node& v, const std::string& field);
  std::optional<double> opt_number(const YAML::Node& parent, const char* key, bool required = false);
  double number(const YAML::Node& parent, const char* key, double fallback, bool required = false);
  std::string text(const YAML::Node& parent, const char* key, const std::string& fallback, bool required = false);
  // A required name (of the item, or of another item it refers to).
  std::string name(const YAML::Node& parent, const char* key = "name");
  Vec3 vec3(const YAML::Node& parent, const char* key, const Vec3& fallback, bool required = false);
  std::vector<std::string> names(const YAML::Node& parent, const char* key);
  int axis_component(const YAML::Node& parent, const char* key);

  TimeFunction function(const YAML::Node& n, const std::string& field);

  void inertia(const YAML::Node& in, BodySpec& b);

  // `points: {name: [x, y, z], ...}` of a body or of ground; "origin" and "com" are reserved.
  void named_points(const YAML::Node& n, std::map<std::string, Vec3>& points);

  void body(const YAML::Node& n, Model& m);

  void joint(const YAML::Node& n, Model& m);

  void coordinate(const std::string& name, const YAML::Node& key, const YAML::Node& n, Model& m, bool patch);

  void cut(const YAML::Node& n, Model& m);

  // A point of a body: a name (of the body's points, "origin", "com") or [x, y, z] in its frame.
  void body_point(const YAML::Node& n, const char* key, std::string& point, Vec3& xyz, bool& at_xyz);
  // A load component: a function of time (number or mapping) or an expression (other text).
  void load_component(const YAML::Node& n, const char* key, TimeFunction& f, std::string& expression);
  void three(const YAML::Node& n, const char* key, Vec3& out, const char* unit);
  void force_parameters(const YAML::Node& n, ForceSpec& f);
  void frame(const YAML::Node& n, ForceSpec& f);

  // Number fields of a force, checked as they are read.
  void non_negative(const YAML::Node& n, const char* key, double& out, bool required);
  void positive(const YAML::Node& n, const char* key, double& out);
  void two_points(const YAML::Node& n, ForceSpec& f);

  // The readers of the built-in force types (force_readers() below).
  void spring_damper(const YAML::Node& n, ForceSpec& f);
  void point_force(const YAML::Node& n, ForceSpec& f);
  void torque(const YAML::Node& n, ForceSpec& f);
  void joint_spring_damper(const YAML::Node& n, ForceSpec& f);
  void bushing(const YAML::Node& n, ForceSpec& f);
  void wheel_contact(const YAML::Node& n, ForceSpec& f);
  void user_force(const YAML::Node& n, ForceSpec& f);

  // A type of the force-type table (formulation/force_types.h) without a reader here: its
  // attachment (bodies and points, or a coordinate) and its parameters, checked by their ranges.
  void table_force(const YAML::Node& n, const ForceType& row, ForceSpec& f);
  // The readers of the built-in types whose fields need more than their row (expression
  // components, rest_deg, 3-vectors, ...), by type name; the row lists the fields of every type.
  using ForceReader = void (Loader::*)(const YAML::Node&, ForceSpec&);
  static const std::map<std::string, ForceReader>& force_readers();

  void force(const YAML::Node& n, Model& m);

  void sensor(const YAML::Node& n, Model& m);

  void sensor_fields(const YAML::Node& n, const std::string& type, const Fields& general, SensorSpec& s);

  // `initial_velocities` of a dynamics step: coordinate names to rates.
  void initial_velocities(const YAML::Node& n, const std::string& type, AnalysisStep& s);

  // A true/false field (absent: `out` unchanged).
  void flag(const YAML::Node& n, const char* key, bool& out);

  // The time span, tolerances and model scales of a step, each checked against its range.
  void step_span_and_tolerances(const YAML::Node& n, bool integrates, AnalysisStep& s);

  // The formulation and its parameters (constraint scale, Baumgarte rates, penalty, Newton).
  void step_formulation(const YAML::Node& n, AnalysisStep& s);

  // The checks a step reports on: the assembly mode check and the quiet sensors.
  void step_checks(const YAML::Node& n, bool integrates, AnalysisStep& s);

  AnalysisStep step(const YAML::Node& n);

  // The `animation` section (cases/output/animation_spec.h), from the model file or the scene.
  void animation(const YAML::Node& n, AnimationSpec& a);

  // Model sections: a model file, or the scene itself (`patch`: entries named like one of the
  // model replace it).
  void sections(const YAML::Node& root, Model& m, bool patch);
};

// Files and YAML documents (scene_files.cpp).
double max_file_mb(std::string& why);
std::optional<std::string> read_text_file(const std::string& path, std::string& why);
std::optional<YAML::Node> parse(const std::string& text, const std::string& path, std::vector<SceneIssue>& issues);

}  // namespace mbdae::scene_load
