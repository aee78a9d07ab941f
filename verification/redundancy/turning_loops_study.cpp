// Every formulation on the two turning loops at rtol 1e-4 ... 1e-10 (default absolute
// tolerances): steps, end status and the largest error relative to its scale, against the
// Lagrange references. Prints a markdown table (docs/formulation.md, "Redundant constraints").
// Usage: turning_loops_study [rtol ...]
#include <cstdio>
#include <cstdlib>

#include "verification/redundancy/turning_loops_cases.h"

int main(int argc, char** argv) {
  using namespace mbdae;
  std::vector<double> rtols = {1e-4, 1e-6, 1e-8, 1e-10};
  if (argc > 1) {
    rtols.clear();
    for (int k = 1; k < argc; ++k) rtols.push_back(std::atof(argv[k]));
  }
  std::printf("| case | formulation | rtol | status | steps | error / scale | ratio to rtol | worst sensor |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  for (const TurningCase* c : {&kTurntableFourBar, &kPinnedGovernor}) {
    const Scene scene = load_turning_case(*c);
    for (const char* f : {"index3", "index3-positions", "index2-ggl", "index1", "penalty"}) {
      for (double rtol : rtols) {
        RunOptions opt;
        opt.formulation = f;
        opt.rtol = rtol;
        opt.verbose = false;
        opt.progress = false;
        const Result r = run(scene, opt);
        const long steps = r.summary["steps"].back()["statistics"].value("steps", 0L);
        if (!r.ok()) {
          std::printf("| %s | %s | %g | %s | %ld | | | |\n", c->scene, f, rtol, r.status.c_str(), steps);
          continue;
        }
        const TurningErrors e = turning_errors(*c, r);
        size_t w = 0;
        for (size_t k = 0; k < e.sensors.size(); ++k)
          if (e.error[k] / e.scale[k] > e.error[w] / e.scale[w]) w = k;
        std::printf("| %s | %s | %g | ok | %ld | %.3g | %.3g | %s |\n", c->scene, f, rtol, steps, e.worst,
                    e.worst / rtol, e.sensors[w].c_str());
        std::fflush(stdout);
      }
    }
  }
  return 0;
}
