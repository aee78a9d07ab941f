// Semantic checks of a loaded scene, run by load_scene_text() before it returns: the model's
// rules (formulation/model_rules.h, the same build_system applies) and the scene's own (output
// columns and analysis steps). Every problem is reported, each with its file, line and field.
#pragma once

#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "cases/scene/scene.h"
#include "formulation/model_rules.h"  // did_you_mean

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


// Appends the problems of `scene` to `issues`. Items the loader could not read at all are
// absent from the scene; references to them are reported as unknown names.
void validate_scene(const Scene& scene, const FieldLines& lines, std::vector<SceneIssue>& issues);

}  // namespace mbdae
