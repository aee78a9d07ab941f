#include "cases/cli/cli_options.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <utility>

#include "cases/scene/analysis_types.h"
#include "cases/scene/field_ranges.h"
#include "cases/run/sensitivities.h"

namespace mbdae {
namespace {

// A number as the scene loader reads one (number_error), the message naming the option.
std::string read_number(const std::string& option, const std::string& text, double& v) {
  const std::string why = number_error(text, v);
  return why.empty() ? "" : option + ": " + why;
}

// What an option that takes a value expects, or nullptr for the others: the word after it is not
// taken as its value when it is itself an option (`--sensitivity --out d` took `--out` as the
// path, then refused `d` as an unknown argument).
const char* expected_value(const std::string& option) {
  static const std::pair<const char*, const char*> kinds[] = {
      {"--out", "a folder"},
      {"--rtol", "a number"},
      {"--atol", "a number"},
      {"--output-step", "a number"},
      {"--formulation", "a formulation"},
      {"--error-target", "a number"},
      {"--error-sensors", "sensor names separated by commas"},
      {"--sensitivity", "a parameter path"},
      {"--animation-rate", "a number"},
  };
  for (const auto& [name, kind] : kinds)
    if (option == name) return kind;
  return nullptr;
}

std::string read_option(const std::vector<std::string>& args, size_t& i, CommandLine& cl) {
  const std::string& a = args[i];
  RunOptions& opt = cl.options;
  const bool has_value = i + 1 < args.size();
  if (const char* kind = expected_value(a); kind && has_value && args[i + 1].rfind("--", 0) == 0)
    return a + ": expects " + kind + ", got '" + args[i + 1] + "'";
  if (a == "--out" && has_value) {
    cl.out_dir = args[++i];
    return cl.out_dir.empty() ? "--out: expected a folder, got ''" : "";
  }
  if ((a == "--rtol" || a == "--atol" || a == "--output-step") && has_value) {
    double v = 0;
    std::string why = read_number(a, args[++i], v);
    if (why.empty() && a == "--rtol" && !rtol_range_error(v).empty()) why = a + ": " + rtol_range_error(v);
    if (why.empty() && a == "--atol" && !atol_range_error(v).empty()) why = a + ": " + atol_range_error(v);
    if (why.empty() && a == "--output-step" && !output_step_range_error(v, 0, 0).empty())
      why = a + ": " + output_step_range_error(v, 0, 0);
    (a == "--rtol" ? opt.rtol : a == "--atol" ? opt.atol : opt.output_step) = v;
    return why;
  }
  if (a == "--formulation" && has_value) {
    opt.formulation = args[++i];
    const std::vector<std::string> known = formulations();
    if (std::find(known.begin(), known.end(), opt.formulation) != known.end()) return "";
    std::string list;
    for (const auto& f : known) list += (list.empty() ? "" : ", ") + f;
    return "--formulation: expected one of " + list + ", got '" + opt.formulation + "'";
  }
  if (a == "--error-estimate") {
    cl.error.estimate = true;
    return "";
  }
  if (a == "--error-target" && has_value) {
    const std::string why = read_number(a, args[++i], cl.error.target);
    if (!why.empty() || cl.error.target > 0) return why;
    return a + ": must be a positive error in the sensors' units, got '" + args[i] + "'";
  }
  if (a == "--error-sensors" && has_value) {
    const std::string& list = args[++i];
    size_t start = 0;
    while (start <= list.size()) {
      const size_t comma = std::min(list.find(',', start), list.size());
      const std::string name = list.substr(start, comma - start);
      if (name.empty()) return a + ": expected sensor names separated by commas, got '" + list + "'";
      cl.error.sensors.push_back(name);
      start = comma + 1;
    }
    return "";
  }
  if (a == "--sensitivity" && has_value) {  // repeatable
    opt.sensitivities.push_back(args[++i]);
    return "";
  }
  if (a == "--normalized-sensitivities") {
    cl.normalized_sensitivities = true;
    return "";
  }
  if (a == "--animation") {
    cl.animation = true;
    return "";
  }
  if (a == "--animation-rate" && has_value) {
    cl.animation = true;
    const std::string why = read_number(a, args[++i], cl.animation_rate);
    if (!why.empty() || cl.animation_rate > 0) return why;
    return a + ": must be a positive number of frames per second, got '" + args[i] + "'";
  }
  if (a == "--quiet") {
    opt.verbose = opt.progress = false;
    return "";
  }
  cl.show_usage = true;
  return has_value || a.rfind("--", 0) != 0 ? "unknown argument '" + a + "'" : a + ": a value is missing";
}

}  // namespace

void print_usage() {
  std::string names;  // the registered formulations: index3|index2-ggl|...
  for (const std::string& f : formulations()) names += (names.empty() ? "" : "|") + f;
  std::fprintf(stderr,
               "usage: mbdae run SCENE.yaml --out DIR [--rtol R] [--atol A] [--quiet] [--error-estimate]\n"
               "                  [--error-target E] [--error-sensors a,b] [--sensitivity PATH]...\n"
               "                  [--normalized-sensitivities]\n"
               "                  [--output-step DT] [--animation] [--animation-rate HZ]\n"
               "                  [--formulation %s]\n"
               "       mbdae check SCENE.yaml\n"
               "       mbdae params SCENE.yaml\n"
               "       mbdae --version\n", names.c_str());
}

std::string parse_command_line(const std::vector<std::string>& args, CommandLine& cl) {
  if (args.size() == 1 && args[0] == "--version") {
    cl.version = true;
    return "";
  }
  if (args.size() < 2 || (args[0] != "run" && args[0] != "check" && args[0] != "params")) {
    cl.show_usage = true;
    return "expected 'run SCENE.yaml', 'check SCENE.yaml' or 'params SCENE.yaml'";
  }
  cl.check_only = args[0] == "check";
  cl.list_params = args[0] == "params";
  cl.scene_path = args[1];
  if (cl.list_params && args.size() > 2) {
    cl.show_usage = true;
    return "params takes the scene only, got '" + args[2] + "'";
  }
  cl.options.verbose = cl.options.progress = true;
  for (size_t i = 2; i < args.size(); ++i) {
    const std::string why = read_option(args, i, cl);
    if (!why.empty()) return why;
  }
  if (!cl.check_only && !cl.list_params && cl.out_dir.empty()) return "--out DIR is required";
  if (!cl.error.sensors.empty() && !(cl.error.target > 0)) return "--error-sensors: needs --error-target E";
  if (cl.normalized_sensitivities && cl.options.sensitivities.empty())
    return "--normalized-sensitivities: needs --sensitivity PATH";
  return "";
}

std::vector<std::string> run_option_errors(const Scene& scene, const RunOptions& opt) {
  std::vector<std::string> out;
  auto check = [&](const char* name, double v, bool given, const std::string& why) {
    if (!given) return;
    if (!std::isfinite(v)) out.push_back(std::string(name) + ": expected a finite number, got " + format_number(v));
    else if (!why.empty()) out.push_back(std::string(name) + ": " + why);
  };
  // 0 means "not given" in RunOptions; a negative or NaN value is given and wrong.
  check("rtol", opt.rtol, opt.rtol != 0, rtol_range_error(opt.rtol));
  check("atol", opt.atol, opt.atol != 0, atol_range_error(opt.atol));
  check("output_step", opt.output_step, opt.output_step != 0, output_step_range_error(opt.output_step, 0, 0));
  if (!opt.formulation.empty()) {
    const std::vector<std::string> known = formulations();
    if (std::find(known.begin(), known.end(), opt.formulation) == known.end()) {
      std::string list;
      for (const auto& f : known) list += (list.empty() ? "" : ", ") + f;
      out.push_back("formulation: expected one of " + list + ", got '" + opt.formulation + "'");
    }
  }
  for (std::string& m : check_sensitivity_paths(scene, opt.sensitivities, opt.formulation, "sensitivities"))
    out.push_back(std::move(m));
  if (out.empty())
    for (const std::string& m : check_overrides(scene, opt)) out.push_back("output_step" + m.substr(m.find(':')));
  return out;
}

std::vector<std::string> check_overrides(const Scene& scene, const RunOptions& opt) {
  std::vector<std::string> out;
  if (!(opt.output_step > 0)) return out;
  for (const AnalysisStep& s : scene.steps) {
    if (!integrates(s)) continue;
    const std::string why = output_step_range_error(opt.output_step, s.t0, s.t_end);
    if (!why.empty()) out.push_back("--output-step: " + why);
  }
  return out;
}

std::vector<std::string> check_overrides(const Scene& scene, const CommandLine& cl) {
  std::vector<std::string> out = check_error_sensors(scene, cl.error.sensors, "--error-sensors");
  for (std::string& m : check_sensitivity_paths(scene, cl.options.sensitivities, cl.options.formulation, "--sensitivity"))
    out.push_back(std::move(m));
  for (std::string& m : check_overrides(scene, cl.options)) out.push_back(std::move(m));
  return out;
}

}  // namespace mbdae
