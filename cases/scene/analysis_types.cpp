#include "cases/scene/analysis_types.h"

#include <algorithm>
#include <stdexcept>

#include "cases/run/run_stages.h"

namespace mbdae {
namespace {

// The fields of a step that integrates in time, kinematics and dynamics alike.
std::vector<std::string> integration_fields() {
  return {"type", "t0", "t_end", "output_step", "rtol", "atol", "max_step", "max_steps", "constraint_scale", "formulation",
          "baumgarte_alpha", "baumgarte_beta", "penalty", "newton_convergence", "newton_solve", "output_projection",
          "length_scale", "time_scale", "atol_rotation", "atol_velocity", "error_estimate", "error_target", "error_sensors", "quiet_until",
          "quiet_sensors", "initial_velocities"};
}

std::vector<AnalysisType> make_analysis_types() {
  using T = AnalysisStep::Type;
  return {
      {"assembly", T::kAssembly, false, {"type", "hold", "t0", "mode_check", "mode_check_deg"}, assembly_stage},
      {"equilibrium", T::kEquilibrium, false, {"type", "hold", "release", "unknowns", "t0"}, equilibrium_stage},
      {"kinematics", T::kKinematics, true, integration_fields(), integration_stage},
      {"dynamics", T::kDynamics, true, integration_fields(), integration_stage},
  };
}

}  // namespace

const std::vector<AnalysisType>& analysis_types() {
  static const std::vector<AnalysisType> table = make_analysis_types();
  return table;
}

const AnalysisType* find_analysis_type(const std::string& name) {
  for (const AnalysisType& a : analysis_types())
    if (a.name == name) return &a;
  return nullptr;
}

const AnalysisType& analysis_type(AnalysisStep::Type type) {
  for (const AnalysisType& a : analysis_types())
    if (a.type == type) return a;
  throw std::logic_error("analysis type without a registry entry");
}

const std::vector<std::string>& analysis_fields() {
  static const std::vector<std::string> all = [] {
    std::vector<std::string> out;
    for (const AnalysisType& a : analysis_types())
      for (const std::string& f : a.fields)
        if (std::find(out.begin(), out.end(), f) == out.end()) out.push_back(f);
    return out;
  }();
  return all;
}

std::string analysis_type_names() {
  std::string s;
  for (const AnalysisType& a : analysis_types()) s += (s.empty() ? "" : ", ") + a.name;
  return s;
}

}  // namespace mbdae
