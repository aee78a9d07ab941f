// The cost of sensitivities (issue 24's target: a dynamics run with Np parameters at most
// (1 + 0.5 Np) times the plain run, on Dynamics I): the integration CPU of the scene's own run
// (index3, no sensitivities), of the same run as index2-ggl (what a scene's index3 step runs as
// with sensitivities), and with 1, 2 and 3 sensitivities (tyre stiffness, suspension damping,
// wheel mass); the kinematic sweep without and with all 18 chassis hardpoint coordinates. The
// least CPU of `repeats` runs each (default 5), printed as a table for docs/sensitivities.md.
//
//   build/verification/benchmarks/sensitivity_cost [repeats]
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "cases/mbdae.h"

namespace {

double step_cpu(const mbdae::Result& r) {
  double cpu = 0;
  for (const auto& s : r.summary["steps"])
    if (s.contains("statistics")) cpu += s["statistics"]["cpu_seconds"].get<double>();
  return cpu;
}

long steps(const mbdae::Result& r) {
  long n = 0;
  for (const auto& s : r.summary["steps"])
    if (s.contains("statistics")) n += s["statistics"]["steps"].get<long>();
  return n;
}

double least_cpu(const mbdae::Scene& scene, const mbdae::RunOptions& opt, int repeats, long* nsteps) {
  double best = 1e300;
  for (int i = 0; i < repeats; ++i) {
    const mbdae::Result r = mbdae::run(scene, opt);
    if (!r.ok()) {
      std::fprintf(stderr, "run failed: %s\n", r.message.c_str());
      std::exit(1);
    }
    best = std::min(best, step_cpu(r));
    *nsteps = steps(r);
  }
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  const int repeats = argc > 1 ? std::max(1, std::atoi(argv[1])) : 5;
  const std::string dir = std::string(MBDAE_SOURCE_DIR) + "/cases/five_point_suspension/";
  const mbdae::Scene dyn = mbdae::load_scene(dir + "dynamics_step.yaml");
  const std::vector<std::string> params = {"forces.tyre.stiffness", "forces.suspension.damping", "bodies.wheel.mass"};
  long n = 0;
  mbdae::RunOptions plain;
  const double base = least_cpu(dyn, plain, repeats, &n);
  std::printf("Dynamics I (least CPU of %d runs)\n", repeats);
  std::printf("  %-40s %8s %7s %9s %9s %8s\n", "run", "CPU [s]", "steps", "/ index3", "/ ggl", "target");
  std::printf("  %-40s %8.3f %7ld %9.2f %9s %8s\n", "index3 (the scene's), no sensitivities", base, n, 1.0, "", "");
  mbdae::RunOptions ggl;
  ggl.formulation = "index2-ggl";
  const double gbase = least_cpu(dyn, ggl, repeats, &n);
  std::printf("  %-40s %8.3f %7ld %9.2f %9.2f %8s\n", "index2-ggl, no sensitivities", gbase, n, gbase / base, 1.0, "");
  for (size_t np = 1; np <= params.size(); ++np) {
    mbdae::RunOptions opt;
    opt.sensitivities.assign(params.begin(), params.begin() + np);
    const double cpu = least_cpu(dyn, opt, repeats, &n);
    std::printf("  %-40s %8.3f %7ld %9.2f %9.2f %8.2f\n", (std::to_string(np) + " sensitivities").c_str(), cpu, n,
                cpu / base, cpu / gbase, 1 + 0.5 * np);
  }
  const mbdae::Scene kin = mbdae::load_scene(dir + "kinematics.yaml");
  mbdae::RunOptions all;
  for (int b = 1; b <= 6; ++b)
    for (int c = 0; c < 3; ++c) all.sensitivities.push_back("bodies.chassis.points.bp" + std::to_string(b) + "." + std::to_string(c));
  const double kbase = least_cpu(kin, plain, repeats, &n);
  const double kall = least_cpu(kin, all, repeats, &n);
  std::printf("Kinematic sweep (2001 samples)\n");
  std::printf("  %-40s %8.3f\n", "no sensitivities", kbase);
  std::printf("  %-40s %8.3f  (%.1f times; %.1f us per parameter and sample)\n", "18 hardpoint coordinates", kall,
              kall / kbase, 1e6 * (kall - kbase) / (18 * 2001));
  return 0;
}
