// Parameter overrides on the parsed YAML trees (cases/scene/scene_overrides.h).
#include "cases/scene/scene_overrides.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <set>
#include <vector>

#include "cases/scene/parameter_units.h"
#include "cases/scene/scene.h"
#include "core/errors.h"
#include "formulation/force_types.h"

namespace mbdae {
namespace {

std::vector<std::string> split_path(const std::string& path) {
  std::vector<std::string> out(1);
  for (char c : path) {
    if (c == '.') out.emplace_back();
    else out.back() += c;
  }
  return out;
}

bool is_index(const std::string& s) {
  return !s.empty() && s.size() < 9 && std::all_of(s.begin(), s.end(), [](char c) { return std::isdigit(static_cast<unsigned char>(c)); });
}

int line_of(const YAML::Node& n) { return n.IsDefined() && n.Mark().line >= 0 ? n.Mark().line + 1 : 0; }

bool names(const YAML::Node& item, const char* key, const std::string& name) {
  return item.IsMap() && item[key] && item[key].IsScalar() && item[key].Scalar() == name;
}

// The index of the item `seg` of a list: by index, by its `name` (analysis steps: by `type`,
// the first of that type); -1 if none.
long item_index(const YAML::Node& list, const std::string& seg, bool steps) {
  if (is_index(seg)) {
    const long k = std::stol(seg);
    return k < static_cast<long>(list.size()) ? k : -1;
  }
  for (size_t k = 0; k < list.size(); ++k)
    if (names(list[k], steps ? "type" : "name", seg)) return static_cast<long>(k);
  return -1;
}

// The child `seg` of `n` (an undefined node if none). `steps`: n is the analysis section, which
// may also be a single step written as a mapping.
YAML::Node child(const YAML::Node& n, const std::string& seg, bool steps) {
  if (!n.IsDefined()) return YAML::Node(YAML::NodeType::Undefined);
  if (steps && n.IsMap()) return seg == "0" || names(n, "type", seg) ? n : YAML::Node(YAML::NodeType::Undefined);
  if (n.IsSequence()) {
    const long k = item_index(n, seg, steps);
    return k >= 0 ? YAML::Node(n[k]) : YAML::Node(YAML::NodeType::Undefined);
  }
  if (n.IsMap() && n[seg]) return n[seg];
  return YAML::Node(YAML::NodeType::Undefined);
}

// Walks `root` along segs[0, count); undefined if a segment is missing.
YAML::Node walk(YAML::Node root, const std::vector<std::string>& segs, size_t count) {
  YAML::Node n = root;
  // reset(), not operator=: assigning to a yaml-cpp handle writes into the node it refers to.
  for (size_t k = 0; k < count && n.IsDefined(); ++k) n.reset(child(n, segs[k], k == 1 && segs[0] == "analysis"));
  return n;
}

// YAML text parsed so that its nodes carry `line` (messages about it name that line).
YAML::Node parse_at(const std::string& text, int line, const std::string& file, const std::string& path) {
  try {
    return YAML::Load(std::string(std::max(0, line - 1), '\n') + text);
  } catch (const YAML::Exception& e) {
    throw SceneError({ModelError::format(file, line, path, "the value is not YAML: " + e.msg)});
  }
}

struct Resolved {
  bool in_scene = true;
  YAML::Node parent;
  bool last_is_step = false;
};

// Where a path goes: the node that holds (or receives) its last segment, in the scene or in the
// model tree. The scene's own item wins (it replaces the model's); coordinates and top-level keys
// are merged field by field, so a value given only in the model file is changed there. Throws
// SceneError naming the first segment found in neither file.
Resolved resolve_path(YAML::Node scene, const std::string& scene_file, YAML::Node* model,
                      const std::vector<std::string>& segs, const std::string& path) {
  const std::string& last = segs.back();
  const size_t n = segs.size() - 1;
  const bool last_is_step = n == 1 && segs[0] == "analysis";
  YAML::Node ps = walk(scene, segs, n), pm = model ? walk(*model, segs, n) : YAML::Node(YAML::NodeType::Undefined);
  auto has_last = [&](const YAML::Node& p) { return child(p, last, last_is_step).IsDefined(); };
  bool in_scene;
  if (has_last(ps)) in_scene = true;
  else if (has_last(pm) && (!ps.IsDefined() || n == 0 || segs[0] == "coordinates")) in_scene = false;
  else if (ps.IsMap() || ps.IsSequence()) in_scene = true;
  else if (pm.IsMap() || pm.IsSequence()) in_scene = false;
  else {
    size_t k = 0;
    while (k < n && (walk(scene, segs, k + 1).IsDefined() || (model && walk(*model, segs, k + 1).IsDefined()))) ++k;
    std::string where;
    for (size_t i = 0; i < k; ++i) where += (i ? "." : "") + segs[i];
    throw SceneError({ModelError::format(scene_file, 0, path,
                                         "unknown parameter: no item '" + segs[k] + "' in " +
                                             (where.empty() ? std::string("the scene") : "'" + where + "'") +
                                             (model ? " (scene or model file)" : ""))});
  }
  return {in_scene, in_scene ? ps : pm, last_is_step};
}

std::vector<std::string> checked_segments(const std::string& path, const std::string& scene_file) {
  const std::vector<std::string> segs = split_path(path);
  for (const auto& s : segs)
    if (s.empty()) throw SceneError({ModelError::format(scene_file, 0, path, "not a parameter path (names joined by '.')")});
  if (segs[0] == "model")
    throw SceneError({ModelError::format(scene_file, 0, path, "the model file cannot be overridden; load another scene")});
  return segs;
}

}  // namespace

OverrideTarget apply_override(YAML::Node scene, const std::string& scene_file, YAML::Node* model,
                              const std::string& model_file, const std::string& path, const std::string& value) {
  const std::vector<std::string> segs = checked_segments(path, scene_file);
  const std::string& last = segs.back();
  const size_t n = segs.size() - 1;
  const Resolved r = resolve_path(scene, scene_file, model, segs, path);
  const bool in_scene = r.in_scene, last_is_step = r.last_is_step;
  YAML::Node parent = r.parent;
  OverrideTarget t{in_scene ? scene_file : model_file, 0, path, value};
  if (parent.IsSequence() || (last_is_step && parent.IsMap())) {
    if (!parent.IsSequence()) {  // a single step written as a mapping: replace its content
      t.line = line_of(parent);
      const YAML::Node v = parse_at(value, t.line, t.file, path);
      if (in_scene) scene["analysis"] = v;
      return t;
    }
    const long k = item_index(parent, last, last_is_step);
    if (k < 0) throw SceneError({ModelError::format(t.file, line_of(parent), path, "no item '" + last + "' in the list")});
    t.line = line_of(parent[k]);
    parent[k] = parse_at(value, t.line, t.file, path);
  } else if (parent.IsMap()) {
    if (static_cast<const YAML::Node&>(parent)[last]) {  // const: a lookup must not add the key
      t.line = line_of(parent[last]);
      parent[last] = parse_at(value, t.line, t.file, path);
    } else {
      t.line = line_of(parent);
      parent.force_insert(parse_at(last, t.line, t.file, path), parse_at(value, t.line, t.file, path));
    }
  } else {
    throw SceneError({ModelError::format(t.file, line_of(parent), path, "'" + segs[n - 1] + "' has no fields to set")});
  }
  return t;
}

namespace {

// A value as the YAML text set_parameter takes (lists and maps in flow style).
std::string yaml_text(const YAML::Node& n) {
  if (n.IsScalar()) return n.Scalar();
  YAML::Emitter e;
  e.SetSeqFormat(YAML::Flow);
  e.SetMapFormat(YAML::Flow);
  e << n;
  return e.c_str();
}

// Every path under `n` (prefix: its own path): mapping keys, list items by name (analysis steps
// by type; by index where the name is missing or taken by an earlier item), list elements by
// index; a list without mappings is also listed whole.
void collect_paths(const YAML::Node& n, const std::string& prefix, bool steps, std::vector<std::string>& out) {
  const std::string dot = prefix.empty() ? "" : prefix + ".";
  if (n.IsScalar()) {
    out.push_back(prefix);
  } else if (n.IsMap() && steps && n["type"] && n["type"].IsScalar()) {  // a single analysis step
    collect_paths(n, dot + n["type"].Scalar(), false, out);
  } else if (n.IsMap()) {
    for (const auto& kv : n) {
      if (!kv.first.IsScalar() || (prefix.empty() && kv.first.Scalar() == "model")) continue;
      collect_paths(kv.second, dot + kv.first.Scalar(), prefix.empty() && kv.first.Scalar() == "analysis", out);
    }
  } else if (n.IsSequence()) {
    bool has_maps = false;
    for (size_t k = 0; k < n.size(); ++k) has_maps = has_maps || n[k].IsMap();
    if (!has_maps && !prefix.empty()) out.push_back(prefix);  // the whole list, then its elements
    for (size_t k = 0; k < n.size(); ++k) {
      std::string seg = std::to_string(k);
      const char* key = steps ? "type" : "name";
      if (n[k].IsMap() && n[k][key] && n[k][key].IsScalar() &&
          item_index(n, n[k][key].Scalar(), steps) == static_cast<long>(k))
        seg = n[k][key].Scalar();
      collect_paths(n[k], dot + seg, false, out);
    }
  }
}

// True for a number, or a list of numbers (lists of lists included): the values that have units.
bool numeric(const YAML::Node& n) {
  if (n.IsScalar()) {
    const std::string& s = n.Scalar();
    char* end = nullptr;
    std::strtod(s.c_str(), &end);
    return !s.empty() && end && *end == '\0';
  }
  if (!n.IsSequence() || n.size() == 0) return false;
  for (const auto& e : n)
    if (!numeric(e)) return false;
  return true;
}

// 'R' or 'T' for a coordinate named `name` (its joint's chain element), '?' if not found.
char coordinate_kind(const YAML::Node& root, const std::string& name) {
  const YAML::Node joints = root.IsMap() ? root["joints"] : YAML::Node();
  if (!joints || !joints.IsSequence()) return '?';
  for (const auto& j : joints) {
    if (!j.IsMap() || !j["chain"] || !j["coordinates"] || !j["chain"].IsSequence() || !j["coordinates"].IsSequence()) continue;
    const YAML::Node chain = j["chain"], coords = j["coordinates"];
    for (size_t k = 0; k < coords.size() && k < chain.size(); ++k)
      if (coords[k].IsScalar() && coords[k].Scalar() == name && chain[k].IsScalar() && !chain[k].Scalar().empty())
        return chain[k].Scalar()[0];
  }
  return '?';
}

}  // namespace

std::vector<ParameterEntry> list_parameters(YAML::Node scene, const std::string& scene_file, YAML::Node* model,
                                            const std::string& model_file) {
  std::vector<std::string> paths;
  if (model) collect_paths(*model, "", false, paths);
  collect_paths(scene, "", false, paths);
  std::vector<ParameterEntry> out;
  std::set<std::string> seen;
  for (const auto& path : paths) {
    if (path.empty() || !seen.insert(path).second) continue;
    const std::vector<std::string> segs = split_path(path);
    Resolved r;
    try {
      r = resolve_path(scene, scene_file, model, segs, path);
    } catch (const SceneError&) {
      continue;
    }
    const YAML::Node value = child(r.parent, segs.back(), r.last_is_step);
    if (!value.IsDefined() || value.IsMap() || value.IsNull()) continue;
    if (segs.size() == 3 && segs[2] == "name") continue;  // an item's name is its path segment
    // The item a field belongs to (forces.tyre for forces.tyre.stiffness) gives the type.
    const YAML::Node root = r.in_scene ? scene : *model;
    const YAML::Node item = segs.size() > 2 ? walk(root, segs, 2) : YAML::Node();
    const std::string type = item.IsDefined() && item.IsMap() && item["type"] && item["type"].IsScalar() ? item["type"].Scalar() : "";
    char kind = '?';
    if (segs[0] == "coordinates" && segs.size() > 1) kind = coordinate_kind(scene, segs[1]);
    if (kind == '?' && model && segs[0] == "coordinates" && segs.size() > 1) kind = coordinate_kind(*model, segs[1]);
    const ForceKind force_kind = find_force_type(type);  // a load on a coordinate: units by its kind
    if (segs[0] == "forces" && force_kind.id >= 0 && force_type(force_kind).attach == ForceAttach::kCoordinate &&
        item["coordinate"] && item["coordinate"].IsScalar()) {
      kind = coordinate_kind(scene, item["coordinate"].Scalar());
      if (kind == '?' && model) kind = coordinate_kind(*model, item["coordinate"].Scalar());
    }
    out.push_back({path, yaml_text(value), numeric(value) ? parameter_unit(segs, type, kind) : "",
                   r.in_scene ? scene_file : model_file, line_of(value)});
  }
  return out;
}

}  // namespace mbdae
