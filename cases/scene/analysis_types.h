// The analysis types a scene's `analysis` list may hold: name, the step fields that apply to it,
// whether it integrates in time, and the stage of run() that carries it out. The table is built
// once and never changed. A new analysis is its stage (its own file in cases/), its solver in
// formulation/, a value of AnalysisStep::Type, and one entry in analysis_types.cpp; the loader,
// the run and the Python package find it here.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cases/scene/scene.h"

namespace mbdae {

struct RunContext;

struct AnalysisType {
  std::string name;                // as written in the scene: `type: dynamics`
  AnalysisStep::Type type;
  bool integrates = false;         // a time span with output samples (t0, t_end, output_step, ...)
  std::vector<std::string> fields;  // the step fields that apply to it ("type" included)
  // The stage of run() (cases/run/run_stages.h): false when the step failed (recorded in the context).
  bool (*stage)(RunContext& c, const AnalysisStep& step, nlohmann::ordered_json& js) = nullptr;
};

// Every registered analysis type, in the order they are documented.
const std::vector<AnalysisType>& analysis_types();
// The entry named `name`, or null.
const AnalysisType* find_analysis_type(const std::string& name);
// The entry of a step's type (every AnalysisStep::Type has one).
const AnalysisType& analysis_type(AnalysisStep::Type type);
// Every field of any analysis type (the keys an analysis step may have at all).
const std::vector<std::string>& analysis_fields();
// "assembly, equilibrium, kinematics, dynamics"
std::string analysis_type_names();
// True for the steps that integrate in time (kinematics, dynamics).
inline bool integrates(const AnalysisStep& s) { return analysis_type(s.type).integrates; }

}  // namespace mbdae
