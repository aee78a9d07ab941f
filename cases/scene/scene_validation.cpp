#include "cases/scene/scene_validation.h"

#include <algorithm>
#include <set>

#include "cases/scene/analysis_types.h"
#include "cases/scene/field_ranges.h"  // format_number
#include "core/errors.h"
#include "formulation/force_types.h"
#include "formulation/model_rules.h"

namespace mbdae {

std::string SceneIssue::text() const { return ModelError::format(file, line, field, message); }

void FieldLines::add(const SourceLocation& item, const std::string& field, int line) {
  if (line <= 0) return;
  const auto key = std::make_tuple(item.file, item.line, field);
  auto it = lines_.find(key);
  if (it == lines_.end()) lines_.emplace(key, line);
  else if (it->second != line) it->second = 0;  // two items start on one line: ambiguous
}

int FieldLines::line(const SourceLocation& item, const std::string& field) const {
  auto it = lines_.find(std::make_tuple(item.file, item.line, field));
  if (it != lines_.end() && it->second > 0) return it->second;
  const size_t bracket = field.find('[');
  if (bracket != std::string::npos) {
    it = lines_.find(std::make_tuple(item.file, item.line, field.substr(0, bracket)));
    if (it != lines_.end() && it->second > 0) return it->second;
  }
  return item.line;
}

namespace {

std::string indexed(const std::string& field, size_t k) { return field + "[" + std::to_string(k) + "]"; }

// A problem at the line of its field (FieldLines), the field shown without its index.
SceneIssue scene_issue(const ModelIssue& i, const FieldLines& lines) {
  return {i.item.file, lines.line(i.item, i.field), i.shown_field(), i.message};
}

template <class Map>
std::vector<std::string> keys(const Map& map) {
  std::vector<std::string> v;
  for (const auto& kv : map) v.push_back(kv.first);
  return v;
}

// The rules of the scene around its model (formulation/model_rules.h): output columns and
// analysis steps, against the names the model defines.
struct SceneRules : ModelNames {
  const Scene& scene;
  const Model& m;
  const FieldLines& lines;
  std::vector<SceneIssue>& issues;

  SceneRules(const Scene& s, ModelNames names, const FieldLines& l, std::vector<SceneIssue>& out)
      : ModelNames(std::move(names)), scene(s), m(s.model), lines(l), issues(out) {}

  void report(const SourceLocation& item, const std::string& field, const std::string& message) {
    issues.push_back(scene_issue({item, field, message, ""}, lines));
  }
  static std::string suggestion(const std::string& name, const std::vector<std::string>& candidates) {
    return did_you_mean(name, candidates);
  }

  void check_output() {
    std::set<std::string> seen;
    for (size_t k = 0; k < scene.columns.size(); ++k) {
      const std::string& c = scene.columns[k];
      if (!sensor_index.count(c))
        report(lines.scene_root, indexed("output", k), "no sensor named '" + c + "'" + suggestion(c, keys(sensor_index)));
      else if (!seen.insert(c).second)
        report(lines.scene_root, indexed("output", k), "sensor '" + c + "' is listed twice");
    }
  }

  void check_coordinate_list(const AnalysisStep& s, const std::string& field, const std::vector<std::string>& names) {
    std::set<std::string> seen;
    for (size_t k = 0; k < names.size(); ++k) {
      const std::string& n = names[k];
      const std::string f = indexed(field, k);
      if (!joint_of_coordinate.count(n))
        report(s.where, f, "no joint coordinate named '" + n + "'" + suggestion(n, keys(joint_of_coordinate)));
      else if (tree.merged_coordinates.count(n))
        report(s.where, f, "coordinate '" + n + "' is locked (its joint is merged); it cannot be held or solved for");
      if (!seen.insert(n).second) report(s.where, f, "coordinate '" + n + "' is listed twice");
    }
  }

  // A driven coordinate whose value jumps (a step drive) inside a dynamics step: no motion
  // follows a jump of a position, and the restart would move the free coordinates by a
  // projection (a pendulum on a cart jumped 5 degrees). A ramp (piecewise_linear) is motion.
  void check_position_jumps(const AnalysisStep& s) {
    for (const auto& [name, c] : scene.model.coordinates) {
      const TimeFunction& d = c.drive;
      if (c.mode != CoordinateSpec::Mode::kDriven || d.kind != TimeFunction::Kind::kStep || d.a == d.b) continue;
      if (d.t0 > s.t0 && d.t0 < s.t_end)
        report(c.where, "drive",
               "coordinate '" + name + "' is driven by a step (from " + format_number(d.a) + " to " + format_number(d.b) +
                   " at t = " + format_number(d.t0) + ") inside a dynamics step (t = " + format_number(s.t0) + " to " +
                   format_number(s.t_end) + "): no motion follows a jump of a position; drive it by a ramp "
                   "(piecewise_linear)");
    }
  }

  void check_steps() {
    for (const auto& s : scene.steps) {
      using A = AnalysisStep::Type;
      if (s.type == A::kAssembly || s.type == A::kEquilibrium) check_coordinate_list(s, "hold", s.hold);
      if (s.type == A::kEquilibrium) {
        check_coordinate_list(s, "release", s.release);
        for (size_t k = 0; k < s.release.size(); ++k)
          if (std::find(s.hold.begin(), s.hold.end(), s.release[k]) == s.hold.end())
            report(s.where, indexed("release", k), "coordinate '" + s.release[k] +
                                                       "' is released but not held (release names held coordinates whose reaction must vanish)");
        std::set<std::string> seen;
        for (size_t k = 0; k < s.unknowns.size(); ++k) {
          const std::string& u = s.unknowns[k];
          const std::string f = indexed("unknowns", k);
          if (!seen.insert(u).second) report(s.where, f, "'" + u + "' is listed twice");
          const size_t dot = u.rfind('.');
          if (dot == std::string::npos) {
            report(s.where, f, "expected force.parameter (e.g. spring.free_length), got '" + u + "'");
            continue;
          }
          const std::string fname = u.substr(0, dot), p = u.substr(dot + 1);
          auto it = forces.find(fname);
          if (it == forces.end()) {
            report(s.where, f, "no force named '" + fname + "'" + suggestion(fname, keys(forces)));
            continue;
          }
          std::vector<std::string> params;  // its row's solvable parameters
          for (const ForceParameter& fp : force_type(it->second->type).parameters)
            if (fp.solvable) params.push_back(fp.name);
          if (std::find(params.begin(), params.end(), p) == params.end()) {
            std::string list;
            for (const auto& x : params) list += (list.empty() ? "" : ", ") + x;
            report(s.where, f, "'" + p + "' is not a parameter of force '" + fname + "' (" +
                                   (list.empty() ? "it has none that can be solved for" : "parameters: " + list) + ")" +
                                   suggestion(p, params));
          }
        }
        if (s.release.size() != s.unknowns.size())
          report(s.where, s.release.empty() ? "unknowns" : "release",
                 "one released coordinate is needed per unknown parameter (" + std::to_string(s.release.size()) +
                     " released, " + std::to_string(s.unknowns.size()) + " unknown)");
      }
      {
        std::set<std::string> seen;
        for (const auto& [n, rate] : s.initial_velocities) {
          const std::string f = "initial_velocities";
          if (!joint_of_coordinate.count(n)) {
            report(s.where, f, "no joint coordinate named '" + n + "'" + suggestion(n, keys(joint_of_coordinate)));
            continue;
          }
          const auto it = m.coordinates.find(n);
          const auto mode = it == m.coordinates.end() ? CoordinateSpec::Mode::kFree : it->second.mode;
          if (mode == CoordinateSpec::Mode::kLocked || tree.merged_coordinates.count(n))
            report(s.where, f, "coordinate '" + n + "' is locked: its rate is 0, not a free initial velocity");
          else if (mode == CoordinateSpec::Mode::kDriven)
            report(s.where, f, "coordinate '" + n + "' is driven: its rate at t0 is its drive's");
          if (!seen.insert(n).second) report(s.where, f, "coordinate '" + n + "' is listed twice");
        }
      }
      if (s.type == A::kDynamics) check_position_jumps(s);
      if (integrates(s))
        for (size_t k = 0; k < s.quiet_sensors.size(); ++k)
          if (!sensor_index.count(s.quiet_sensors[k]))
            report(s.where, indexed("quiet_sensors", k), "no sensor named '" + s.quiet_sensors[k] + "'" +
                                                             suggestion(s.quiet_sensors[k], keys(sensor_index)));
      if (integrates(s)) {
        for (size_t k = 0; k < s.error_sensors.size(); ++k) {
          if (!sensor_index.count(s.error_sensors[k]))
            report(s.where, indexed("error_sensors", k), "no sensor named '" + s.error_sensors[k] + "'" +
                                                             suggestion(s.error_sensors[k], keys(sensor_index)));
          else if (!scene.columns.empty() &&
                   std::find(scene.columns.begin(), scene.columns.end(), s.error_sensors[k]) == scene.columns.end())
            report(s.where, indexed("error_sensors", k), "sensor '" + s.error_sensors[k] + "' is not in the scene's output list");
        }
      }
    }
  }
};

}  // namespace

void validate_scene(const Scene& scene, const FieldLines& lines, std::vector<SceneIssue>& issues) {
  ModelNames names;
  for (const ModelIssue& i : check_model(scene.model, &names))
    issues.push_back(scene_issue(i, lines));
  SceneRules rules(scene, std::move(names), lines, issues);
  rules.check_output();
  rules.check_steps();
}

}  // namespace mbdae
