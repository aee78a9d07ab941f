// Parameter overrides applied to the parsed YAML trees of a scene and its model file, before
// the loader reads them (so a bad value gets the loader's own message). A path names list items
// by their name (analysis steps by their type) or index, mapping entries by key and elements of
// a list of values by index:
//   forces.tyre.stiffness, coordinates.q4.initial, gravity, analysis.dynamics.rtol, analysis.2.t_end,
//   bodies.chassis.points.bp1.2 (z of point bp1), gravity.2
#pragma once

#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

#include "cases/scene/scene.h"  // ParameterEntry

namespace mbdae {

// Where an override was put: the file and the line of the value it replaced (or of the item
// that received a new key), to place messages about it.
struct OverrideTarget {
  std::string file;
  int line = 0;
  std::string path, value;
};

// Sets `path` to the YAML text `value` in the scene tree, or in the model tree where the scene
// does not name the item (an entry of the scene's own item, or a new top-level key, goes to the
// scene). `model` may be null (no model file). Throws SceneError for an unknown path or a value
// that is not YAML.
OverrideTarget apply_override(YAML::Node scene, const std::string& scene_file, YAML::Node* model,
                              const std::string& model_file, const std::string& path, const std::string& value);

// Every parameter path of the scene and model trees that the resolver of apply_override finds a
// value at (mapping fields, list items by name, list elements by index; a list of numbers also
// whole), in model then scene order.
std::vector<ParameterEntry> list_parameters(YAML::Node scene, const std::string& scene_file, YAML::Node* model,
                                            const std::string& model_file);

}  // namespace mbdae
