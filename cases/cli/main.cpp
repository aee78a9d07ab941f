// mbdae command-line front end:
//   mbdae run SCENE.yaml --out DIR [--rtol R] [--atol A] [--output-step DT]
//                         [--formulation index3|index2-ggl|index1|penalty]
//   mbdae check SCENE.yaml | mbdae params SCENE.yaml | mbdae --version
// Exit codes (docs/errors.md): 0 success, 1 usage, 2 invalid scene, 3 solve failure, 4 output
// or resource failure (a file that cannot be written, a folder in use, out of memory),
// 128 + N stopped by signal N (SIGINT 130, SIGTERM 143).
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>
#include <new>
#include <string>

#include "cases/output/animation_sink.h"
#include "cases/cli/cli_options.h"
#include "cases/run/error_target.h"
#include "cases/mbdae.h"
#include "cases/output/sinks.h"
#include "cases/run/signals.h"
#include "core/errors.h"
#include "core/output.h"
#include "formulation/system.h"
#include "mbdae/version.h"

namespace {

// mbdae params: one line per parameter path, "path = value [unit]", in the scene's order; a
// stdout that cannot be written (a full device) is exit code 4 with a message.
int print_parameters(const mbdae::Scene& scene) {
  for (const auto& p : mbdae::parameters(scene))
    std::printf("%s = %s%s\n", p.path.c_str(), p.value.c_str(), p.unit.empty() ? "" : (" [" + p.unit + "]").c_str());
  if (std::fflush(stdout) == 0 && !std::ferror(stdout)) return 0;
  std::fprintf(stderr, "mbdae: cannot write the parameter list to stdout (%s)\n", std::strerror(errno));
  return 4;
}

}  // namespace

namespace {

int run_command(int argc, char** argv);

// Standard output (`check`'s verdict, `run`'s assembly report) that could not be written is an
// I/O failure like any other file (exit code 4), not a success: `mbdae check s.yaml > /dev/full`.
int checked_stdout(int code) {
  errno = 0;
  if (std::fflush(stdout) == 0 && !std::ferror(stdout)) return code;
  const int err = errno;
  std::fprintf(stderr, "mbdae: cannot write to standard output: %s%s\n", err ? std::strerror(err) : "write error",
               code == 0 ? " (the output files, if any, are whole)" : "");
  return code == 0 ? 4 : code;
}

}  // namespace

int main(int argc, char** argv) { return checked_stdout(run_command(argc, argv)); }

namespace {

int run_command(int argc, char** argv) {
  mbdae::CommandLine cl;
  const std::string usage_error = mbdae::parse_command_line(std::vector<std::string>(argv + 1, argv + argc), cl);
  if (!usage_error.empty()) {
    std::fprintf(stderr, "mbdae: %s\n", usage_error.c_str());
    if (cl.show_usage) mbdae::print_usage();
    return 1;
  }
  if (cl.version) {
    std::printf("mbdae %s\n", MBDAE_VERSION);
    return 0;
  }
  mbdae::RunOptions& opt = cl.options;
  if (!cl.check_only && !cl.list_params) opt.stop = mbdae::install_stop_signals();  // check, params: Ctrl-C ends it at once
  try {
    const mbdae::Scene scene = mbdae::load_scene(cl.scene_path);
    if (cl.list_params) return print_parameters(scene);
    if (cl.check_only) {
      const mbdae::System sys = mbdae::build_system(scene.model);
      std::printf("%s: ok (%d bodies, %d coordinates, %d constraint equations)\n", cl.scene_path.c_str(),
                  sys.num_bodies(), sys.nq(), sys.num_constraint_rows());
      return 0;
    }
    const std::vector<std::string> bad_overrides = mbdae::check_overrides(scene, cl);
    for (const auto& m : bad_overrides) std::fprintf(stderr, "mbdae: %s\n", m.c_str());
    if (!bad_overrides.empty()) return 1;
    mbdae::check_runnable(scene, opt);  // a scene refused here leaves the output folder as it was
    const bool animate = cl.animation || scene.animation.write;  // DIR/animation.pvd
    const mbdae::OutputRequest request{cl.out_dir, animate ? cl.out_dir : "", cl.animation_rate,
                                       !opt.sensitivities.empty(), cl.normalized_sensitivities};
    mbdae::RunSinks out = mbdae::open_sinks(scene, request);
    int tries = 0;  // an error target's later tries get fresh writers (cases/run/error_target.h)
    const mbdae::SinkFactory make_sinks = [&] {
      if (tries++ > 0) mbdae::renew_sinks(scene, request, out);
      return out.list;
    };
    const mbdae::Result r = mbdae::run_controlled(scene, opt, mbdae::error_control(scene, cl.error), make_sinks,
                                                  cl.out_dir + "/summary.json");  // load, run, write
    const bool interrupted = r.status == "interrupted";
    return interrupted && mbdae::stop_signal() ? 128 + mbdae::stop_signal() : r.exit_code;
  } catch (const mbdae::SceneError& e) {
    for (const auto& m : e.messages) std::fprintf(stderr, "%s\n", m.c_str());
    return 2;
  } catch (const mbdae::ModelError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  } catch (const mbdae::OutputError& e) {
    std::fprintf(stderr, "mbdae: %s\n", e.what());
    return 4;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "mbdae: out of memory (the scene or its output needs more memory than is available)\n");
    return 4;
  } catch (const mbdae::SolveError& e) {
    std::fprintf(stderr, "mbdae: %s\n", e.what());
    return 3;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mbdae: %s\n", e.what());
    return 3;
  }
}

}  // namespace
