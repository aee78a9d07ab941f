// libFuzzer target for the scene loader: arbitrary text through load_scene_text (YAML parsing,
// field checks, validate_scene) and, for a scene that loads, build_system and the evaluation
// of its expression sensors. Rejections are the expected SceneError and ModelError; anything
// else (another exception, a crash, a sanitizer report, a hang) is a finding.
//
// With MBDAE_FUZZ_STRICT=1 in the environment, a scene that passes validation but that
// build_system rejects also counts as a finding: validate_scene should have reported it.
//
// Built and run by cases/fuzz/run_fuzz.sh. The scene's path is cases/fuzz/scene.yaml, so that
// `model: models/pendulum_model.yaml` names the model file next to this source.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "cases/scene.h"
#include "core/errors.h"
#include "formulation/system.h"

#ifndef MBDAE_FUZZ_SCENE_PATH
#define MBDAE_FUZZ_SCENE_PATH "scene.yaml"
#endif

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const bool strict = [] {
    const char* s = std::getenv("MBDAE_FUZZ_STRICT");
    return s && *s && *s != '0';
  }();
  const std::string text(reinterpret_cast<const char*>(data), size);
  mbdae::Scene scene;
  try {
    scene = mbdae::load_scene_text(text, MBDAE_FUZZ_SCENE_PATH);
  } catch (const mbdae::SceneError& e) {
    if (e.messages.empty()) std::abort();  // a rejection must say why
    return 0;
  }
  try {
    const mbdae::System sys = mbdae::build_system(scene.model);
    std::vector<double> values(sys.sensors.size() + 1, 0.5);
    for (const auto& s : sys.sensors)
      if (!s.expression.empty()) (void)s.expression.evaluate(values.data());
  } catch (const mbdae::ModelError& e) {
    if (strict) {
      std::fprintf(stderr, "validation gap: the scene passed validation, build_system says:\n%s\n", e.what());
      std::abort();
    }
  }
  return 0;
}
