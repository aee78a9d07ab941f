// mbdae command-line front end:
//   mbdae run SCENE.yaml --out DIR [--rtol R] [--atol A] [--output-step DT]
//                         [--formulation index3|index2-ggl|index1|penalty]
// Exit codes: 0 success, 1 usage, 2 invalid scene, 3 solve failure.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>

#include "cases/animation_sink.h"
#include "cases/run_scene.h"
#include "cases/scene.h"
#include "core/errors.h"
#include "formulation/system.h"

namespace {
void usage() {
  std::fprintf(stderr,
               "usage: mbdae run SCENE.yaml --out DIR [--rtol R] [--atol A] [--quiet]\n"
               "                  [--output-step DT] [--animation] [--animation-rate HZ]\n"
               "                  [--formulation index3|index2-ggl|index1|penalty]\n"
               "       mbdae check SCENE.yaml\n");
}
bool parse_number(const char* s, double& v) {
  char* end = nullptr;
  v = std::strtod(s, &end);
  return end && *end == '\0' && end != s;
}
}  // namespace

int main(int argc, char** argv) {
  if (argc < 3 || (std::strcmp(argv[1], "run") != 0 && std::strcmp(argv[1], "check") != 0)) {
    usage();
    return 1;
  }
  const bool check_only = std::strcmp(argv[1], "check") == 0;
  const std::string scene_path = argv[2];
  mbdae::RunOptions opt;
  opt.verbose = true;
  opt.progress = true;
  opt.keep_rows = false;
  bool animation = false;  // DIR/animation.pvd (cases/animation_sink.h)
  double animation_rate = 0;
  for (int i = 3; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--out" && i + 1 < argc) {
      opt.out_dir = argv[++i];
    } else if ((a == "--rtol" || a == "--atol") && i + 1 < argc) {
      double v;
      if (!parse_number(argv[++i], v) || !(v > 0) || v > 1) {
        std::fprintf(stderr, "mbdae: %s expects a number in (0, 1], got '%s'\n", a.c_str(), argv[i]);
        return 1;
      }
      (a == "--rtol" ? opt.rtol : opt.atol) = v;
    } else if (a == "--output-step" && i + 1 < argc) {
      double v;
      if (!parse_number(argv[++i], v) || !(v > 0)) {
        std::fprintf(stderr, "mbdae: --output-step expects a positive number of seconds, got '%s'\n", argv[i]);
        return 1;
      }
      opt.output_step = v;
    } else if (a == "--formulation" && i + 1 < argc) {
      opt.formulation = argv[++i];
      if (opt.formulation != "index3" && opt.formulation != "index2-ggl" && opt.formulation != "index1" &&
          opt.formulation != "penalty") {
        std::fprintf(stderr, "mbdae: --formulation expects index3, index2-ggl, index1 or penalty, got '%s'\n",
                     opt.formulation.c_str());
        return 1;
      }
    } else if (a == "--animation") {
      animation = true;
    } else if (a == "--animation-rate" && i + 1 < argc) {
      if (!parse_number(argv[++i], animation_rate) || !(animation_rate > 0)) {
        std::fprintf(stderr, "mbdae: --animation-rate expects a positive number of frames per second, got '%s'\n", argv[i]);
        return 1;
      }
      animation = true;
    } else if (a == "--quiet") {
      opt.verbose = false;
      opt.progress = false;
    } else {
      std::fprintf(stderr, "mbdae: unknown argument '%s'\n", a.c_str());
      usage();
      return 1;
    }
  }
  if (!check_only && opt.out_dir.empty()) {
    std::fprintf(stderr, "mbdae: --out DIR is required\n");
    return 1;
  }
  try {
    const mbdae::Scene scene = mbdae::load_scene(scene_path);
    if (check_only) {
      const mbdae::System sys = mbdae::build_system(scene.model);
      std::printf("%s: ok (%d bodies, %d coordinates, %d constraint equations)\n", scene_path.c_str(),
                  sys.num_bodies(), sys.nq(), sys.num_constraint_rows());
      return 0;
    }
    std::unique_ptr<mbdae::AnimationSink> anim;
    if (animation || scene.animation.write) anim = std::make_unique<mbdae::AnimationSink>(scene, opt.out_dir, animation_rate);
    std::vector<mbdae::Sink*> sinks;
    if (anim) sinks.push_back(anim.get());
    return mbdae::run(scene, opt, sinks).exit_code;
  } catch (const mbdae::SceneError& e) {
    for (const auto& m : e.messages) std::fprintf(stderr, "%s\n", m.c_str());
    return 2;
  } catch (const mbdae::ModelError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  } catch (const mbdae::SolveError& e) {
    std::fprintf(stderr, "mbdae: %s\n", e.what());
    return 3;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mbdae: %s\n", e.what());
    return 3;
  }
}
