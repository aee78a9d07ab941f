// Errors of the fast mechanism against its Lagrange reference, per formulation and tolerance:
//   fast_mechanism_study [--formulations a,b] [--tols 1e-4,1e-6,...] [--atol A]
// One line per run: rtol, atol (0: the scene's defaults), steps, residual evaluations, CPU
// seconds of the integration (summary.json), largest relative position and velocity errors.
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>

#include "verification/fast_mechanism/fast_mechanism_errors.h"

int main(int argc, char** argv) {
  std::vector<std::string> forms = {"index3", "index2-ggl", "index1", "penalty"};
  std::vector<double> tols = {0};
  double atol = 0;
  auto split = [](const std::string& s) {
    std::vector<std::string> out;
    std::stringstream ss(s);
    for (std::string x; std::getline(ss, x, ',');) out.push_back(x);
    return out;
  };
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i], v = argv[i + 1];
    if (a == "--formulations") forms = split(v);
    else if (a == "--tols") {
      tols.clear();
      for (const auto& t : split(v)) tols.push_back(std::atof(t.c_str()));
    } else if (a == "--atol") atol = std::atof(v.c_str());
  }
  const mbdae::Scene scene = mbdae::load_fast_mechanism();
  std::printf("%-11s %8s %8s %7s %7s %8s %10s %10s %s\n", "formulation", "rtol", "atol", "steps", "res", "cpu_s",
              "err_pos", "err_vel", "status");
  for (const auto& f : forms)
    for (double tol : tols) {
      mbdae::RunOptions opt;
      opt.formulation = f;
      opt.rtol = tol;
      opt.atol = atol;
      const mbdae::Result r = mbdae::run(scene, opt);
      const auto& st = r.summary["steps"].back();
      double e_pos = NAN, e_vel = NAN;
      if (r.ok()) {
        const mbdae::FastMechanismErrors e = mbdae::fast_mechanism_errors(r);
        e_pos = e.position;
        e_vel = e.velocity;
      }
      std::printf("%-11s %8.0e %8.1e %7ld %7ld %8.4f %10.3e %10.3e %s\n", f.c_str(), st.value("rtol", 0.0),
                  st.value("atol", 0.0), st["statistics"].value("steps", 0L),
                  st["statistics"].value("residual_evaluations", 0L), st["statistics"].value("cpu_seconds", 0.0),
                  e_pos, e_vel, r.status.c_str());
      std::fflush(stdout);
    }
  return 0;
}
