// What a Scene keeps to be read again with parameter overrides (cases/mbdae.h set_parameter):
// the texts of its scene and model files as first read, and the overrides applied so far.
// Immutable once built and shared between copies of a Scene (safe to read from any thread).
#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

namespace mbdae {

struct SceneSource {
  std::string path, text;                      // the scene file
  std::map<std::string, std::string> models;   // model file path -> text, as read at first load
  std::vector<std::pair<std::string, std::string>> overrides;  // (parameter path, YAML value)
};

}  // namespace mbdae
