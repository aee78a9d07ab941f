// Semantic checks of a loaded scene, run by load_scene_text() before it returns: references
// between bodies, points, joints, coordinates, cuts, forces, sensors, expressions, output
// columns and analysis steps, and the joint tree (loops, bodies without a path to ground,
// bodies welded together by a cut). Every problem is reported, each with its file, line and
// field; build_system() repeats the essential checks as a second line of defence but stops at
// the first. The chain and tree rules (which chains are refused, the tree order, which joints
// merge bodies) are build_system's own, from formulation/joint_tree.h.
#pragma once

#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "cases/scene/scene.h"

namespace mbdae {

// One problem found in a scene or model file.
struct SceneIssue {
  std::string file;
  int line = 0;       // 1-based; 0 if unknown
  std::string field;  // as written in the file, e.g. "parent", "points.bp1", "hold"
  std::string message;
  std::string text() const;  // "file:line: field 'x': message"
};

// Lines of the fields of each item, recorded by the loader so that a problem found later is
// reported at the line of the field rather than of the item. An item is identified by its
// SourceLocation (the line where its mapping starts); list elements are "field[k]".
class FieldLines {
 public:
  SourceLocation scene_root;  // the scene's top-level mapping (fields "output", "remove")

  void add(const SourceLocation& item, const std::string& field, int line);
  // Line of `field` of `item`, else of `field` without an index, else the item's own line.
  int line(const SourceLocation& item, const std::string& field) const;

 private:
  std::map<std::tuple<std::string, int, std::string>, int> lines_;
};

// "; did you mean 'x'?" if one of `candidates` is within a small edit distance of `name`.
std::string did_you_mean(const std::string& name, const std::vector<std::string>& candidates);

// Appends the problems of `scene` to `issues`. Items the loader could not read at all are
// absent from the scene; references to them are reported as unknown names.
void validate_scene(const Scene& scene, const FieldLines& lines, std::vector<SceneIssue>& issues);

}  // namespace mbdae
