// Does the tolerance keep its promise? For a scene, each formulation and each rtol of a list, the
// run with the model's default absolute tolerances (the scene's rtol, atol, atol_rotation and
// atol_velocity removed) is compared with a reference: the same scene with index2-ggl at
// rtol 1e-11 (default atol), shown converged by a check at 10 times looser rtol. Errors: the
// largest |x - x_ref| over the common output samples of every position-like sensor (unit m or
// rad) and every velocity-like sensor (m/s or rad/s), divided by the scale of its quantity, the
// largest |x_ref| over the samples and over the sensors of the same unit (a sensor that stays
// near zero is measured against the model's lengths, not against itself). The promise
// (issue 13): both within 10 rtol.
//
//   tolerance_promise --scene FILE [--label NAME] [--formulations a,b] [--tols 1e-4,1e-6,1e-8]
//                     [--t-end T] [--ref-rtol 1e-11] [--csv FILE]
// One CSV row per run: scene label, formulation, rtol, steps, residual evaluations, CPU seconds
// of the integration (summary.json), position and velocity errors / scale, their ratios to rtol.
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "cases/mbdae.h"

namespace {

struct Options {
  std::string scene, label, csv;
  std::vector<std::string> formulations = {"index3", "index3-positions", "index2-ggl", "index1", "penalty"};
  std::vector<double> tols = {1e-4, 1e-6, 1e-8};
  double t_end = 0, ref_rtol = 1e-11;
};

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string x; std::getline(ss, x, ',');)
    if (!x.empty()) out.push_back(x);
  return out;
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i], v = argv[i + 1];
    if (a == "--scene") o.scene = v;
    else if (a == "--label") o.label = v;
    else if (a == "--csv") o.csv = v;
    else if (a == "--formulations") o.formulations = split(v);
    else if (a == "--t-end") o.t_end = std::atof(v.c_str());
    else if (a == "--ref-rtol") o.ref_rtol = std::atof(v.c_str());
    else if (a == "--tols") {
      o.tols.clear();
      for (const auto& t : split(v)) o.tols.push_back(std::atof(t.c_str()));
    } else {
      std::fprintf(stderr, "tolerance_promise: unknown argument '%s'\n", a.c_str());
      std::exit(2);
    }
  }
  if (o.scene.empty()) {
    std::fprintf(stderr, "usage: tolerance_promise --scene FILE [--label L] [--formulations a,b] [--tols t,...] "
                         "[--t-end T] [--ref-rtol R] [--csv FILE]\n");
    std::exit(2);
  }
  if (o.label.empty()) o.label = std::filesystem::path(o.scene).stem().string();
  return o;
}

// The scene with its integration steps' tolerances removed (model defaults) and t_end set.
mbdae::Scene default_tolerance_scene(const Options& o) {
  YAML::Node root = YAML::LoadFile(o.scene);
  YAML::Node analysis = root["analysis"];
  for (std::size_t k = 0; k < analysis.size(); ++k) {
    YAML::Node step = analysis[k];
    const std::string type = step["type"].as<std::string>();
    if (type != "dynamics" && type != "kinematics") continue;
    for (const char* key : {"rtol", "atol", "atol_rotation", "atol_velocity", "formulation"}) step.remove(key);
    if (o.t_end > 0) step["t_end"] = o.t_end;
  }
  YAML::Emitter e;
  e << root;
  return mbdae::load_scene_text(e.c_str(), o.scene);
}

struct Errors {
  double position = NAN, velocity = NAN;
  std::string worst_position, worst_velocity;
};

bool is_position(const std::string& u) { return u == "m" || u == "rad"; }
bool is_velocity(const std::string& u) { return u == "m/s" || u == "rad/s"; }

// Largest |x - x_ref| / scale of the unit, over the samples both results have (matched by time).
Errors compare(const mbdae::Result& r, const mbdae::Result& ref) {
  std::map<std::string, double> scale;  // per unit
  for (size_t c = 1; c < ref.columns.size(); ++c)
    for (double x : ref.data[c]) scale[ref.units[c]] = std::max(scale[ref.units[c]], std::fabs(x));
  Errors e;
  e.position = e.velocity = 0;
  for (size_t c = 1; c < ref.columns.size(); ++c) {
    const std::string& u = ref.units[c];
    const int rc = r.column_index(ref.columns[c]);
    if (rc < 0 || !(is_position(u) || is_velocity(u)) || !(scale[u] > 0)) continue;
    double err = 0;
    for (size_t i = 0, j = 0; i < r.rows() && j < ref.rows();) {
      const double ti = r.data[0][i], tj = ref.data[0][j], tiny = 1e-9 * std::max(1.0, std::fabs(tj));
      if (ti < tj - tiny) ++i;
      else if (tj < ti - tiny) ++j;
      else {
        const double d = std::fabs(r.data[rc][i] - ref.data[c][j]);
        err = std::isfinite(d) ? std::max(err, d) : INFINITY;
        ++i, ++j;
      }
    }
    double& worst = is_position(u) ? e.position : e.velocity;
    if (err / scale[u] >= worst) {
      worst = err / scale[u];
      (is_position(u) ? e.worst_position : e.worst_velocity) = ref.columns[c];
    }
  }
  return e;
}

struct Stats {
  double steps = NAN, residuals = NAN, cpu = NAN;
};

Stats stats(const mbdae::Result& r) {
  Stats s;
  for (const auto& st : r.summary["steps"])
    if (st.contains("statistics") && st["statistics"].contains("steps")) {
      s.steps = st["statistics"].value("steps", 0.0);
      s.residuals = st["statistics"].value("residual_evaluations", 0.0);
      s.cpu = st["statistics"].value("cpu_seconds", 0.0);
    }
  return s;
}

mbdae::Result run(const mbdae::Scene& scene, const std::string& formulation, double rtol) {
  mbdae::RunOptions opt;
  opt.formulation = formulation;
  opt.rtol = rtol;
  return mbdae::run(scene, opt);
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse(argc, argv);
  const mbdae::Scene scene = default_tolerance_scene(o);
  const mbdae::Result ref = run(scene, "index2-ggl", o.ref_rtol);
  const mbdae::Result check = run(scene, "index2-ggl", 10 * o.ref_rtol);
  if (!ref.ok() || !check.ok()) {
    std::fprintf(stderr, "tolerance_promise: the reference failed: %s %s\n", ref.message.c_str(), check.message.c_str());
    return 1;
  }
  const Errors c = compare(check, ref);
  std::printf("# %s: reference index2-ggl rtol %g (%g steps); check at rtol %g differs by %.2g (positions), "
              "%.2g (velocities) of the scales\n",
              o.label.c_str(), o.ref_rtol, stats(ref).steps, 10 * o.ref_rtol, c.position, c.velocity);
  std::FILE* csv = o.csv.empty() ? nullptr : std::fopen(o.csv.c_str(), "w");
  if (csv)
    std::fprintf(csv, "case,formulation,rtol,steps,residual_evals,cpu_seconds,err_pos,err_vel,worst_pos,worst_vel,"
                      "status,ref_check_pos,ref_check_vel\n");
  std::printf("%-16s %8s %8s %8s %8s %10s %10s %8s %8s %s\n", "formulation", "rtol", "steps", "res", "cpu_s",
              "err_pos", "err_vel", "pos/rtol", "vel/rtol", "status");
  for (const auto& f : o.formulations)
    for (double tol : o.tols) {
      const mbdae::Result r = run(scene, f, tol);
      const Stats s = stats(r);
      const Errors e = r.ok() ? compare(r, ref) : Errors{};
      std::printf("%-16s %8.0e %8.0f %8.0f %8.3f %10.3e %10.3e %8.2g %8.2g %s %s/%s\n", f.c_str(), tol, s.steps,
                  s.residuals, s.cpu, e.position, e.velocity, e.position / tol, e.velocity / tol, r.status.c_str(),
                  e.worst_position.c_str(), e.worst_velocity.c_str());
      std::fflush(stdout);
      if (csv)
        std::fprintf(csv, "%s,%s,%g,%.0f,%.0f,%.4g,%.3g,%.3g,%s,%s,%s,%.2g,%.2g\n", o.label.c_str(), f.c_str(), tol,
                     s.steps, s.residuals, s.cpu, e.position, e.velocity, e.worst_position.c_str(),
                     e.worst_velocity.c_str(), r.status.c_str(), c.position, c.velocity);
    }
  if (csv) std::fclose(csv);
  return 0;
}
