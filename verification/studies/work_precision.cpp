// Work-precision study: error against run time for a scene, a list of formulations and a ladder
// of tolerances.
//
// For every formulation the build accepts (the scene is reloaded with `formulation: NAME` on its
// integration step; a name the loader rejects is skipped with a note) and every tau of the
// ladder, the scene runs with rtol = tau, atol = atol_ratio * tau (default 1e-6 tau, the
// suspension tests' ladder: the rods' Euler parameters pass through zero, where only atol limits
// their error), N times. Recorded: the median CPU time of the integration step (summary:
// statistics.cpu_seconds, which includes the output samples' acceleration solves and sensors), the same
// without output samples (N more runs with samples at t0 and t_end only: IDA runs in one-step
// mode and interpolates samples, so the steps should be identical; their count is recorded and a
// difference is reported), the median wall time of the whole
// scene (assembly and equilibrium included), steps and residual evaluations, the maximum over the
// output samples of |wheel_z - ref|, |wheel_vz - ref|, |wheel_az - ref| (the samples both runs
// have), and the constraint violation at the integrator's steps: position level
// (statistics.max_position_violation_steps) and, when the summary has it, velocity level.
//
// The reference is the same scene with index2-ggl (--ref-formulation) at a much tighter tolerance. It is shown to be
// converged by a second run at 10x looser rtol and atol: their difference is printed and
// stored, and must be well below the smallest error of the ladder.
//
//   work_precision [--scene FILE] [--label NAME] [--formulations index3,index2-ggl,index1]
//                  [--tols 1e-3,1e-4,...] [--atol-ratio 1e-6] [--ref-rtol 1e-12] [--ref-atol 1e-16]
//                  [--ref-formulation index2-ggl]
//                  [--repeat 3] [--t-end T] [--newton-convergence C] [--csv FILE] [--meta FILE]
//                  [--short]
//
// --short: dynamics I, tau = 1e-5 and 1e-7, one repetition (the ctest entry). It then fails
// (exit 1) on a real failure only: the reference or its check does not run or is not converged,
// a run of an accepted formulation fails or gives a non-finite error, or the error does not
// decrease from the looser to the tighter tolerance. Exit 2: bad arguments or scene.
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cases/mbdae.h"
#include "cases/scene/scene.h"
#include "core/errors.h"

namespace {

using json = nlohmann::ordered_json;

const char* kSignals[3] = {"wheel_z", "wheel_vz", "wheel_az"};

struct Options {
  std::string scene = "cases/five_point_suspension/dynamics_step.yaml";
  std::string label;
  std::vector<std::string> formulations = {"index3", "index2-ggl", "index1"};
  std::vector<double> tols = {1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10};
  double atol_ratio = 1e-6;
  double ref_rtol = 1e-12, ref_atol = 1e-16;
  // index2-ggl: index3's error per unit step reaches index 3's floor (about 1.3e-9 m on dynamics
  // I) from rtol 1e-8 on; index2-ggl's error keeps falling (1.5e-10 m at 1e-10).
  std::string ref_formulation = "index2-ggl";
  int repeat = 3;
  double t_end = 0;               // > 0: shorten the integration
  double newton_convergence = 0;  // > 0: override the scene's
  std::string csv, meta;
  bool short_run = false;
};

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

bool parse_double(const std::string& s, double& v) {
  char* end = nullptr;
  v = std::strtod(s.c_str(), &end);
  return end && *end == '\0' && end != s.c_str() && std::isfinite(v);
}

[[noreturn]] void usage(const std::string& why) {
  std::fprintf(stderr,
               "work_precision: %s\n"
               "usage: work_precision [--scene FILE] [--label NAME] [--formulations a,b,c] [--tols t1,t2,...]\n"
               "                      [--atol-ratio R] [--ref-rtol R] [--ref-atol A] [--repeat N] [--t-end T]\n"
               "                      [--newton-convergence C] [--csv FILE] [--meta FILE] [--short]\n",
               why.c_str());
  std::exit(2);
}

Options parse(int argc, char** argv) {
  Options o;
  bool tols_given = false, repeat_given = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) usage("missing value after " + a);
      return argv[++i];
    };
    auto number = [&]() {
      const std::string s = value();
      double v;
      if (!parse_double(s, v) || !(v > 0)) usage(a + " expects a positive number, got '" + s + "'");
      return v;
    };
    if (a == "--scene") o.scene = value();
    else if (a == "--label") o.label = value();
    else if (a == "--formulations") o.formulations = split(value());
    else if (a == "--tols") {
      o.tols.clear();
      for (const auto& t : split(value())) {
        double v;
        if (!parse_double(t, v) || !(v > 0) || v > 0.5) usage("--tols: bad tolerance '" + t + "'");
        o.tols.push_back(v);
      }
      tols_given = true;
    } else if (a == "--atol-ratio") o.atol_ratio = number();
    else if (a == "--ref-rtol") o.ref_rtol = number();
    else if (a == "--ref-atol") o.ref_atol = number();
    else if (a == "--ref-formulation") o.ref_formulation = value();
    else if (a == "--repeat") {
      o.repeat = static_cast<int>(number());
      repeat_given = true;
    } else if (a == "--t-end") o.t_end = number();
    else if (a == "--newton-convergence") o.newton_convergence = number();
    else if (a == "--csv") o.csv = value();
    else if (a == "--meta") o.meta = value();
    else if (a == "--short") o.short_run = true;
    else usage("unknown argument '" + a + "'");
  }
  if (o.short_run) {
    if (!tols_given) o.tols = {1e-5, 1e-7};
    if (!repeat_given) o.repeat = 1;
  }
  if (o.tols.empty()) usage("no tolerances");
  if (o.formulations.empty()) usage("no formulations");
  if (o.repeat < 1) o.repeat = 1;
  std::sort(o.tols.begin(), o.tols.end(), std::greater<double>());
  return o;
}

std::string resolve(const std::string& path) {
  namespace fs = std::filesystem;
  if (fs::exists(path)) return path;
  const fs::path p = fs::path(MBDAE_SOURCE_DIR) / path;
  if (fs::exists(p)) return p.string();
  return path;
}

// The scene with the integration step set to `formulation` (and t_end / newton_convergence
// when given), loaded through the scene loader so that it validates the formulation name.
mbdae::Scene scene_with(const Options& o, const std::string& path, const std::string& formulation) {
  YAML::Node root = YAML::LoadFile(path);
  YAML::Node analysis = root["analysis"];
  auto patch = [&](YAML::Node step) {
    if (!step.IsMap() || !step["type"]) return;
    const std::string type = step["type"].as<std::string>();
    if (type != "dynamics" && type != "kinematics") return;
    step["formulation"] = formulation;
    if (o.t_end > 0) step["t_end"] = o.t_end;
    if (o.newton_convergence > 0) step["newton_convergence"] = o.newton_convergence;
  };
  if (analysis.IsSequence())
    for (std::size_t k = 0; k < analysis.size(); ++k) patch(analysis[k]);
  else
    patch(analysis);
  YAML::Emitter e;
  e << root;
  return mbdae::load_scene_text(e.c_str(), path);
}

const json* integration_step(const json& summary) {
  if (!summary.contains("steps")) return nullptr;
  for (const auto& s : summary["steps"])
    if (s.contains("type") && (s["type"] == "dynamics" || s["type"] == "kinematics")) return &s;
  return nullptr;
}

double stat(const json* step, const char* key) {
  if (!step || !step->contains("statistics") || !(*step)["statistics"].contains(key)) return NAN;
  return (*step)["statistics"][key].get<double>();
}

// The velocity-level constraint violation, if the formulation reports one.
double velocity_violation(const json* step) {
  if (!step || !step->contains("statistics")) return NAN;
  const json& st = (*step)["statistics"];
  if (st.contains("max_velocity_violation_steps")) return st["max_velocity_violation_steps"].get<double>();
  for (auto& [k, v] : st.items())
    if (k.find("velocity_violation") != std::string::npos && v.is_number()) return v.get<double>();
  return NAN;
}

std::string g(double x, int digits = 4) {
  if (!std::isfinite(x)) return "";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", digits, x);
  return buf;
}

struct Run {
  std::string formulation;
  double tol = 0, rtol = 0, atol = 0;
  int exit_code = 0;
  std::string status, message;
  double t_reached = NAN;
  double cpu = NAN, wall = NAN, cpu_no_output = NAN, steps_no_output = NAN;
  double steps = NAN, rhs = NAN, jac = NAN;
  double err[3] = {NAN, NAN, NAN};
  long compared = 0;
  double viol_pos = NAN, viol_vel = NAN, norm_drift = NAN;
  mbdae::Result outcome;
};

double median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// The same scene with output samples at t0 and t_end only: IDA runs in one-step mode and samples
// are interpolated, so the steps are the same and the CPU time is that of the integration alone.
mbdae::Scene without_output(mbdae::Scene scene) {
  for (auto& s : scene.steps)
    if (s.type == mbdae::AnalysisStep::Type::kDynamics || s.type == mbdae::AnalysisStep::Type::kKinematics)
      s.output_step = s.t_end - s.t0;
  return scene;
}

Run run(const mbdae::Scene& scene, const std::string& formulation, double tol, double rtol, double atol,
        int repeat, bool time_without_output = true) {
  Run r;
  r.formulation = formulation;
  r.tol = tol;
  r.rtol = rtol;
  r.atol = atol;
  std::vector<double> cpus, walls;
  for (int k = 0; k < repeat; ++k) {
    mbdae::RunOptions opt;
    opt.verbose = false;
    opt.progress = false;
    opt.rtol = rtol;
    opt.atol = atol;
    const auto w0 = std::chrono::steady_clock::now();
    mbdae::Result out;
    try {
      out = mbdae::run(scene, opt);
    } catch (const std::exception& e) {
      r.exit_code = 3;
      r.status = "exception";
      r.message = e.what();
      return r;
    }
    walls.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count());
    const json* step = integration_step(out.summary);
    cpus.push_back(stat(step, "cpu_seconds"));
    if (k == 0) {
      r.exit_code = out.exit_code;
      r.status = out.summary.value("status", "?");
      r.message = out.summary.value("message", "");
      if (step) {
        r.t_reached = step->value("t_reached", NAN);
        // index3 below rtol 1e-6 and index1 below 1e-9 run as index2-ggl and say so
        // (formulation_asked): not a warning.
        if (step->contains("formulation") && (*step)["formulation"] != formulation &&
            step->value("formulation_asked", std::string()) != formulation)
          std::printf("  WARNING: asked for %s, the summary says %s\n", formulation.c_str(),
                      (*step)["formulation"].get<std::string>().c_str());
      }
      r.steps = stat(step, "steps");
      r.rhs = stat(step, "residual_evaluations");
      r.jac = stat(step, "jacobian_evaluations");
      r.viol_pos = stat(step, "max_position_violation_steps");
      r.norm_drift = stat(step, "max_euler_norm_drift");
      r.viol_vel = velocity_violation(step);
      r.outcome = std::move(out);
      if (r.exit_code != 0) break;  // a failure is not timed again
    }
  }
  r.cpu = median(cpus);
  r.wall = median(walls);
  if (time_without_output && r.exit_code == 0) {
    const mbdae::Scene bare = without_output(scene);
    std::vector<double> bare_cpus;
    for (int k = 0; k < repeat; ++k) {
      mbdae::RunOptions opt;
      opt.verbose = false;
      opt.progress = false;
      opt.rtol = rtol;
      opt.atol = atol;
      try {
        const mbdae::Result out = mbdae::run(bare, opt);
        const json* step = integration_step(out.summary);
        if (out.exit_code != 0) break;
        bare_cpus.push_back(stat(step, "cpu_seconds"));
        r.steps_no_output = stat(step, "steps");
      } catch (const std::exception&) {
      }
    }
    r.cpu_no_output = median(bare_cpus);
    if (r.steps_no_output != r.steps)
      std::printf("  note: %s at tau %s takes %s steps without output samples, %s with them: the samples "
                  "change the solution\n", formulation.c_str(), g(tol).c_str(), g(r.steps_no_output, 10).c_str(),
                  g(r.steps, 10).c_str());
  }
  return r;
}

int column(const mbdae::Result& r, const std::string& name) {
  auto it = std::find(r.columns.begin(), r.columns.end(), name);
  return it == r.columns.end() ? -1 : static_cast<int>(it - r.columns.begin());
}

// Max |a - b| of each signal over the output samples both runs have (matched by time).
void compare(const mbdae::Result& a, const mbdae::Result& b, double err[3], long& compared) {
  compared = 0;
  int ca[3], cb[3];
  for (int s = 0; s < 3; ++s) {
    ca[s] = column(a, kSignals[s]);
    cb[s] = column(b, kSignals[s]);
    err[s] = (ca[s] < 0 || cb[s] < 0) ? NAN : 0.0;
  }
  size_t i = 0, j = 0;
  while (i < a.rows() && j < b.rows()) {
    const double ta = a.data[0][i], tb = b.data[0][j];
    const double eps = 1e-9 * std::max(1.0, std::fabs(ta));
    if (ta < tb - eps) { ++i; continue; }
    if (tb < ta - eps) { ++j; continue; }
    for (int s = 0; s < 3; ++s)
      if (ca[s] >= 0 && cb[s] >= 0) {
        const double d = std::fabs(a.data[ca[s]][i] - b.data[cb[s]][j]);
        err[s] = std::isfinite(d) ? std::max(err[s], d) : NAN;
        if (!std::isfinite(d)) ca[s] = -1;
      }
    ++compared;
    ++i;
    ++j;
  }
  if (compared == 0)
    for (int s = 0; s < 3; ++s) err[s] = NAN;
}

std::string csv_field(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  if (s.find_first_of(",\"") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

}  // namespace

int main(int argc, char** argv) {
  Options o = parse(argc, argv);
  const std::string path = resolve(o.scene);
  if (o.label.empty()) o.label = std::filesystem::path(path).stem().string();

  // The reference scene (index3) and the formulations the build accepts.
  mbdae::Scene ref_scene;
  try {
    ref_scene = scene_with(o, path, o.ref_formulation);
  } catch (const mbdae::SceneError& e) {
    std::fprintf(stderr, "work_precision: cannot load %s:\n%s\n", path.c_str(), e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "work_precision: cannot load %s: %s\n", path.c_str(), e.what());
    return 2;
  }
  double t_end = 0;
  for (const auto& s : ref_scene.steps)
    if (s.type == mbdae::AnalysisStep::Type::kDynamics || s.type == mbdae::AnalysisStep::Type::kKinematics)
      t_end = s.t_end;
  std::printf("work_precision: %s (%s), t in [0, %g] s%s\n", o.label.c_str(), path.c_str(), t_end,
              o.t_end > 0 ? "  ** shortened with --t-end **" : "");
  std::printf("ladder: rtol = tau, atol = %g tau, tau in {", o.atol_ratio);
  for (size_t k = 0; k < o.tols.size(); ++k) std::printf("%s%g", k ? ", " : "", o.tols[k]);
  std::printf("}; %d repetition(s), CPU = median of the integration step's cpu_seconds\n", o.repeat);

  std::vector<std::pair<std::string, mbdae::Scene>> accepted;
  json skipped = json::object();
  for (const auto& f : o.formulations) {
    try {
      accepted.emplace_back(f, scene_with(o, path, f));
    } catch (const std::exception& e) {
      std::string msg = e.what();
      std::printf("note: formulation '%s' skipped, the build rejects it: %s\n", f.c_str(), msg.c_str());
      skipped[f] = msg;
    }
  }

  bool failed = false;
  auto fail = [&](const std::string& why) {
    std::printf("FAILURE: %s\n", why.c_str());
    failed = true;
  };

  // Reference and its convergence check.
  std::printf("reference: %s, rtol %g, atol %g ...\n", o.ref_formulation.c_str(), o.ref_rtol, o.ref_atol);
  std::fflush(stdout);
  Run ref = run(ref_scene, o.ref_formulation, o.ref_rtol, o.ref_rtol, o.ref_atol, 1, false);
  Run check = run(ref_scene, o.ref_formulation, 10 * o.ref_rtol, 10 * o.ref_rtol, 10 * o.ref_atol, 1, false);
  std::printf("  reference: %s, %s steps, cpu %s s; check at rtol %g, atol %g: %s, %s steps\n", ref.status.c_str(),
              g(ref.steps).c_str(), g(ref.cpu).c_str(), check.rtol, check.atol, check.status.c_str(),
              g(check.steps).c_str());
  if (ref.exit_code != 0) {
    fail("the reference run failed: " + ref.message);
    return 1;
  }
  double check_diff[3];
  long check_n = 0;
  compare(check.outcome, ref.outcome, check_diff, check_n);
  std::printf("  reference converged? max |check - reference| over %ld samples: wheel_z %s m, wheel_vz %s m/s, "
              "wheel_az %s m/s^2\n",
              check_n, g(check_diff[0], 3).c_str(), g(check_diff[1], 3).c_str(), g(check_diff[2], 3).c_str());
  if (check.exit_code != 0) fail("the reference check run failed: " + check.message);
  json ref_signal_range = json::object();
  for (int s = 0; s < 3; ++s) {
    const int c = column(ref.outcome, kSignals[s]);
    if (c < 0) continue;
    double lo = 1e300, hi = -1e300;
    for (const std::vector<double>& row : ref.outcome.row_major()) {
      lo = std::min(lo, row[c]);
      hi = std::max(hi, row[c]);
    }
    ref_signal_range[kSignals[s]] = {lo, hi};
  }

  // The ladder.
  std::vector<Run> runs;
  std::printf("\n%-11s %8s %8s %9s %9s %9s %7s %7s %10s %10s %10s %10s %10s  %s\n", "formulation", "rtol", "atol",
              "cpu_s", "cpu_noout", "wall_s", "steps", "res", "err_z", "err_vz", "err_az", "viol_pos", "viol_vel", "status");
  for (auto& [f, scene] : accepted) {
    for (double tau : o.tols) {
      Run r = run(scene, f, tau, tau, o.atol_ratio * tau, o.repeat);
      compare(r.outcome, ref.outcome, r.err, r.compared);
      std::printf("%-11s %8.0e %8.0e %9.4f %9.4f %9.4f %7s %7s %10s %10s %10s %10s %10s  %s%s\n", f.c_str(), r.rtol,
                  r.atol, r.cpu, r.cpu_no_output, r.wall, g(r.steps, 7).c_str(), g(r.rhs, 7).c_str(), g(r.err[0], 3).c_str(),
                  g(r.err[1], 3).c_str(), g(r.err[2], 3).c_str(), g(r.viol_pos, 3).c_str(), g(r.viol_vel, 3).c_str(),
                  r.status.c_str(), r.exit_code ? (" at t = " + g(r.t_reached, 6) + ": " + r.message).c_str() : "");
      std::fflush(stdout);
      r.outcome = mbdae::Result{};  // rows no longer needed
      runs.push_back(std::move(r));
    }
  }

  // Is the reference good enough for the errors it measures?
  double smallest = INFINITY;
  for (const auto& r : runs)
    if (r.exit_code == 0 && std::isfinite(r.err[0])) smallest = std::min(smallest, r.err[0]);
  if (std::isfinite(smallest) && std::isfinite(check_diff[0])) {
    std::printf("\nreference check: |check - reference| (wheel_z) = %s m, smallest ladder error %s m (ratio %s)\n",
                g(check_diff[0], 3).c_str(), g(smallest, 3).c_str(), g(smallest / check_diff[0], 3).c_str());
    if (check_diff[0] > 0.1 * smallest)
      std::printf("WARNING: the reference is not 10x more accurate than the best run; the smallest errors are "
                  "not resolved\n");
    if (o.short_run && check_diff[0] > smallest) fail("the reference is not converged");
  }

  if (o.short_run) {
    for (const auto& r : runs) {
      if (r.exit_code != 0) fail(r.formulation + " at tau " + g(r.tol) + " failed: " + r.message);
      for (int s = 0; s < 3; ++s)
        if (!std::isfinite(r.err[s])) fail(r.formulation + " at tau " + g(r.tol) + ": no finite error for " + kSignals[s]);
    }
    for (size_t k = 1; k < runs.size(); ++k)
      if (runs[k].formulation == runs[k - 1].formulation && runs[k].exit_code == 0 && runs[k - 1].exit_code == 0 &&
          !(runs[k].err[0] < runs[k - 1].err[0]))
        fail(runs[k].formulation + ": wheel_z error does not decrease from tau " + g(runs[k - 1].tol) + " to " +
             g(runs[k].tol));
  }

  if (!o.csv.empty()) {
    std::filesystem::path p(o.csv);
    if (p.has_parent_path()) std::filesystem::create_directories(p.parent_path());
    std::ofstream f(o.csv);
    f << "formulation,tol,rtol,atol,cpu_median,steps,rhs_evals,err_z,err_vz,err_az,viol_pos,viol_vel,"
         "status,wall_median,cpu_no_output_median,steps_no_output,jac_evals,euler_norm_drift,t_reached,compared_samples,"
         "message\n";
    for (const auto& r : runs)
      f << r.formulation << ',' << g(r.tol) << ',' << g(r.rtol) << ',' << g(r.atol) << ',' << g(r.cpu, 4) << ','
        << g(r.steps, 10) << ',' << g(r.rhs, 10) << ',' << g(r.err[0], 4) << ',' << g(r.err[1], 4) << ','
        << g(r.err[2], 4) << ',' << g(r.viol_pos, 3) << ',' << g(r.viol_vel, 3) << ',' << r.status << ','
        << g(r.wall, 4) << ',' << g(r.cpu_no_output, 4) << ',' << g(r.steps_no_output, 10) << ',' << g(r.jac, 10) << ',' << g(r.norm_drift, 3) << ',' << g(r.t_reached, 8) << ','
        << r.compared << ',' << csv_field(r.message) << '\n';
    std::printf("wrote %s\n", o.csv.c_str());
  }
  if (!o.meta.empty()) {
    json m;
    m["label"] = o.label;
    m["scene"] = std::filesystem::path(path).lexically_proximate(MBDAE_SOURCE_DIR).string();
    m["t_end"] = t_end;
    m["t_end_shortened"] = o.t_end > 0;
    m["atol_ratio"] = o.atol_ratio;
    m["repeat"] = o.repeat;
    m["newton_convergence_override"] = o.newton_convergence > 0 ? json(o.newton_convergence) : json(nullptr);
    m["formulations_requested"] = o.formulations;
    json ran = json::array();
    for (const auto& a : accepted) ran.push_back(a.first);
    m["formulations_run"] = ran;
    m["formulations_skipped"] = skipped;
    m["reference"] = {{"formulation", o.ref_formulation}, {"rtol", ref.rtol}, {"atol", ref.atol}, {"status", ref.status},
                      {"steps", ref.steps}, {"cpu_seconds", ref.cpu}, {"signal_range", ref_signal_range}};
    m["reference_check"] = {{"rtol", check.rtol}, {"atol", check.atol}, {"status", check.status},
                            {"message", check.message}, {"samples", check_n},
                            {"diff_z", std::isfinite(check_diff[0]) ? json(check_diff[0]) : json(nullptr)},
                            {"diff_vz", std::isfinite(check_diff[1]) ? json(check_diff[1]) : json(nullptr)},
                            {"diff_az", std::isfinite(check_diff[2]) ? json(check_diff[2]) : json(nullptr)}};
    std::filesystem::path p(o.meta);
    if (p.has_parent_path()) std::filesystem::create_directories(p.parent_path());
    std::ofstream(o.meta) << m.dump(2) << '\n';
    std::printf("wrote %s\n", o.meta.c_str());
  }
  if (failed) {
    std::printf("work_precision: FAILED\n");
    return 1;
  }
  std::printf("work_precision: done\n");
  return 0;
}
