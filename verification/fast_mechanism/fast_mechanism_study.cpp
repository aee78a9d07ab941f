// Errors of the fast mechanism against its Lagrange reference, per formulation and tolerance:
//   fast_mechanism_study [--formulations a,b] [--tols 1e-4,1e-6,...] [--atol A] [--csv FILE]
//                        [--label NAME]
// One line per run: rtol, atol (0: the scene's defaults), steps, residual evaluations, CPU
// seconds of the integration (summary.json), largest relative position and velocity errors.
// --csv: the same in the columns of verification/studies/tolerance_promise (case NAME).
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>

#include "verification/fast_mechanism/fast_mechanism_errors.h"

int main(int argc, char** argv) {
  std::vector<std::string> forms = {"index3", "index2-ggl", "index1", "penalty"};
  std::vector<double> tols = {0};
  double atol = 0;
  std::string csv_path, label = "fast mechanism";
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
    else if (a == "--csv") csv_path = v;
    else if (a == "--label") label = v;
  }
  const mbdae::Scene scene = mbdae::load_fast_mechanism();
  std::FILE* csv = csv_path.empty() ? nullptr : std::fopen(csv_path.c_str(), "w");
  if (csv)
    std::fprintf(csv, "case,formulation,rtol,steps,residual_evals,cpu_seconds,err_pos,err_vel,worst_pos,worst_vel,"
                      "status,ref_check_pos,ref_check_vel\n");
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
      std::string worst_pos, worst_vel;
      if (r.ok()) {
        const mbdae::FastMechanismErrors e = mbdae::fast_mechanism_errors(r);
        e_pos = e.position;
        e_vel = e.velocity;
        for (size_t k = 0; k < e.sensors.size(); ++k) {
          const double rel = e.error[k] / e.scale[k];
          if (rel == e_pos) worst_pos = e.sensors[k];
          if (rel == e_vel) worst_vel = e.sensors[k];
        }
      }
      if (csv)
        std::fprintf(csv, "%s,%s,%g,%ld,%ld,%.4g,%.3g,%.3g,%s,%s,%s,%.2g,%.2g\n", label.c_str(), f.c_str(), tol,
                     st["statistics"].value("steps", 0L), st["statistics"].value("residual_evaluations", 0L),
                     st["statistics"].value("cpu_seconds", 0.0), e_pos, e_vel, worst_pos.c_str(), worst_vel.c_str(),
                     r.status.c_str(), 1e-10, 1e-10);
      std::printf("%-11s %8.0e %8.1e %7ld %7ld %8.4f %10.3e %10.3e %s\n", f.c_str(), st.value("rtol", 0.0),
                  st.value("atol", 0.0), st["statistics"].value("steps", 0L),
                  st["statistics"].value("residual_evaluations", 0L), st["statistics"].value("cpu_seconds", 0.0),
                  e_pos, e_vel, r.status.c_str());
      std::fflush(stdout);
    }
  if (csv) std::fclose(csv);
  return 0;
}
