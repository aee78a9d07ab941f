// YAML scene loader. Every problem is recorded with its file, line and field, and loading goes
// on so that all problems of a file are reported at once: first what can be seen field by field
// (unknown or missing fields, wrong types, numbers that are not finite or out of range), then
// the references between items and the joint tree (validate_scene, cases/scene/scene_validation.cpp).
#include "cases/scene/loader.h"

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
#include "cases/scene/field_ranges.h"
#include "cases/scene/analysis_types.h"
#include "cases/scene/scene.h"
#include "cases/scene/scene_overrides.h"
#include "cases/scene/scene_source.h"
#include "cases/scene/scene_validation.h"
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

using namespace scene_load;


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
    if (scene.redundant_constraints != "remove" && scene.redundant_constraints != "fail" &&
        scene.redundant_constraints != "remove_world")
      l.error(root["redundant_constraints"], "redundant_constraints",
              "expected remove, fail or remove_world, got '" + scene.redundant_constraints + "'");
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
