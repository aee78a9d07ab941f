// libFuzzer target for the scene loader: arbitrary text through load_scene_text (YAML parsing,
// field checks, validate_scene) and, for a scene that loads, build_system and the evaluation
// of its expression sensors. Rejections are the expected SceneError and ModelError; anything
// else (another exception, a crash, a sanitizer report, a hang) is a finding.
//
// With MBDAE_FUZZ_STRICT=1 in the environment, a scene that passes validation but that
// build_system rejects also counts as a finding: validate_scene should have reported it.
//
// An input whose first line is `#!mbdae ARGS` (a YAML comment, so the scene still reads) also
// runs the command-line parser (cases/cli/cli_options.h) on `run scene.yaml ARGS` (split at spaces)
// and checks the overrides against the scene: a refusal must say why, nothing may crash.
//
// Built and run by cases/fuzz/run_fuzz.sh. The scene's path is cases/fuzz/scene.yaml, so that
// `model: models/pendulum_model.yaml` names the model file next to this source.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "cases/scene/analysis_types.h"
#include "cases/cli/cli_options.h"
#include "cases/scene/scene.h"
#include "core/errors.h"
#include "formulation/system.h"

#ifndef MBDAE_FUZZ_SCENE_PATH
#define MBDAE_FUZZ_SCENE_PATH "scene.yaml"
#endif

namespace {

// The arguments of an input starting with "#!mbdae " (after `run scene.yaml`); false if none.
bool command_line_of(const std::string& text, std::vector<std::string>& args) {
  const std::string tag = "#!mbdae ";
  if (text.compare(0, tag.size(), tag) != 0) return false;
  const std::string line = text.substr(tag.size(), text.find('\n') == std::string::npos ? std::string::npos
                                                                                        : text.find('\n') - tag.size());
  args = {"run", "scene.yaml"};
  for (size_t k = 0; k < line.size();) {
    const size_t e = std::min(line.find(' ', k), line.size());
    if (e > k) args.push_back(line.substr(k, e - k));
    k = e + 1;
  }
  return true;
}

// A command line that parses holds only values the scene fields would accept, and overrides that
// pass check_overrides ask for at most 1e8 rows per integration step.
void check_command_line(const std::vector<std::string>& args, const mbdae::Scene* scene) {
  mbdae::CommandLine cl;
  if (!mbdae::parse_command_line(args, cl).empty()) return;  // refused, with a message
  const mbdae::RunOptions& o = cl.options;
  if (o.rtol != 0 && !(o.rtol >= 1e-14 && o.rtol <= 0.5)) std::abort();
  if (o.atol != 0 && !(o.atol > 0 && o.atol <= 1)) std::abort();
  if (o.output_step != 0 && !(o.output_step > 0)) std::abort();
  if (!cl.check_only && cl.out_dir.empty()) std::abort();  // run needs --out
  if (!scene || !mbdae::check_overrides(*scene, o).empty() || !(o.output_step > 0)) return;
  for (const auto& s : scene->steps)
    if (mbdae::integrates(s) &&
        s.t_end > s.t0 && (s.t_end - s.t0) / o.output_step > 1e8)
      std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const bool strict = [] {
    const char* s = std::getenv("MBDAE_FUZZ_STRICT");
    return s && *s && *s != '0';
  }();
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> args;
  const bool with_command_line = command_line_of(text, args);
  mbdae::Scene scene;
  try {
    scene = mbdae::load_scene_text(text, MBDAE_FUZZ_SCENE_PATH);
  } catch (const mbdae::SceneError& e) {
    if (e.messages.empty()) std::abort();  // a rejection must say why
    if (with_command_line) check_command_line(args, nullptr);
    return 0;
  }
  if (with_command_line) check_command_line(args, &scene);
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
