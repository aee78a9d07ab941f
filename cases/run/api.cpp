// The public API's scene functions (cases/mbdae.h); run() is in cases/run/run.cpp.
#include "cases/mbdae.h"

namespace mbdae {

void set_parameter(Scene& scene, const std::string& path, const std::string& yaml_value) {
  scene = reload_scene(scene, {{path, yaml_value}});
}

std::vector<ParameterEntry> parameters(const Scene& scene) { return scene_parameters(scene); }

Scene with_parameters(const Scene& scene, const std::vector<std::pair<std::string, std::string>>& overrides) {
  return reload_scene(scene, overrides);
}

}  // namespace mbdae
