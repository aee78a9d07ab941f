// mbdae command-line front end:
//   mbdae run SCENE.yaml --out DIR [--rtol R] [--atol A] [--output-step DT]
//                         [--formulation index3|index2-ggl|index1|penalty]
// Exit codes: 0 success, 1 usage, 2 invalid scene, 3 solve failure.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "cases/mbdae.h"
#include "cases/sinks.h"
#include "core/errors.h"
#include "core/output.h"
#include "formulation/formulation_registry.h"
#include "formulation/system.h"

namespace {
void usage() {
  std::string names;  // the registered formulations, index3|index2-ggl|...
  for (const std::string& f : mbdae::formulations()) names += (names.empty() ? "" : "|") + f;
  std::fprintf(stderr,
               "usage: mbdae run SCENE.yaml --out DIR [--rtol R] [--atol A] [--quiet]\n"
               "                  [--output-step DT]\n"
               "                  [--formulation %s]\n"
               "       mbdae check SCENE.yaml\n", names.c_str());
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
  std::string out_dir;
  for (int i = 3; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--out" && i + 1 < argc) {
      out_dir = argv[++i];
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
      if (!mbdae::find_formulation(opt.formulation)) {
        std::fprintf(stderr, "mbdae: --formulation expects %s, got '%s'\n", mbdae::formulation_names(true).c_str(),
                     opt.formulation.c_str());
        return 1;
      }
    } else if (a == "--quiet") {
      opt.verbose = false;
      opt.progress = false;
    } else {
      std::fprintf(stderr, "mbdae: unknown argument '%s'\n", a.c_str());
      usage();
      return 1;
    }
  }
  if (!check_only && out_dir.empty()) {
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
    mbdae::prepare_output_folder(out_dir);
    mbdae::CsvSink csv(out_dir + "/results.csv");
    mbdae::SummarySink summary(out_dir + "/summary.json");
    return mbdae::run(scene, opt, {&csv, &summary}).exit_code;
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
