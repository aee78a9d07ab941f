// The formulations a run can integrate with: name, factory, defaults and the time integrator
// that advances it. The table is built once and never changed (safe from any thread). A new
// formulation is its own file (a class derived from MultibodyDae) plus one entry in
// formulation_registry.cpp; the scene loader, the command line and the run find it here.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/ida_driver.h"
#include "formulation/multibody_dae.h"

namespace mbdae {

// What a factory may use from an analysis step (defaults as in a scene without these fields).
struct FormulationParameters {
  double constraint_scale = 1.0;                     // row scale of the constraint equations
  double baumgarte_alpha = 20.0, baumgarte_beta = 20.0;  // [1/s] stabilization (index1, penalty);
                                                         // a run derives them from the model (cases/scene/step_tolerances.h)
  double penalty = 1e7;  // p = penalty * largest body mass (penalty)
};

// A time integrator: advances `problem` from options.t0 to options.t1, handing each sample to
// `output` (core/ida_driver.h's integrate, SUNDIALS IDA's BDF with KLU, is the one every
// formulation uses today). A fixed-step comparison integrator is a function of this type in its
// own file and its name in the formulation's row.
using Integrator = IdaStats (*)(DaeProblem& problem, const IdaOptions& options, std::vector<double>& y,
                                std::vector<double>& yp,
                                const std::function<bool(double, const double*, const double*)>& output);

struct Formulation {
  std::string name;
  std::string description;  // one line
  // Default constraint row scale: cj^2 M at a typical step (true), else 1.
  bool automatic_scale = false;
  // Uses FormulationParameters::penalty (reported in the summary).
  bool uses_penalty = false;
  std::unique_ptr<MultibodyDae> (*make)(const System& sys, const FormulationParameters& p) = nullptr;
  // Uses the Baumgarte rates (reported in the summary), by default alpha = beta = baumgarte_rate
  // over the model's fast time scale (docs/formulation.md, "Baumgarte and penalty defaults"):
  // index1 1 (a faster stabilization makes IDA's steps alternate with error-test failures at
  // loose tolerances), penalty 5 (its constraint bias goes as 1 / beta^2).
  bool uses_baumgarte = false;
  double baumgarte_rate = 0;
  // The integrator that advances the DAE, and its name in summary.json.
  Integrator integrator = &integrate;
  const char* integrator_name = "ida";
};

// Every registered formulation, in the order they are documented (index3 first: the default).
const std::vector<Formulation>& formulation_registry();
// The entry named `name`, or null.
const Formulation* find_formulation(const std::string& name);
// "index3, index2-ggl, index1, penalty" (or with " or " before the last: `last_or`).
std::string formulation_names(bool last_or = false);

// Below this rtol "index3" runs as index2-ggl: index3's position test would ask for positions
// below their rounding there, and its error stops falling with rtol (docs/formulation.md, "index3
// hands over to index2-ggl below rtol 1e-6"). "index3-no-handover" is index3 at every rtol.
constexpr double kIndex3HandoverRtol = MultibodyDae::kSpanRtol;
// Below this rtol "index1" runs as index2-ggl: index1's velocities carry the positions' rounding
// per step, and the floor its error test keeps above that noise lets the steps' errors add up past
// 10 rtol at rtol 1e-10 (docs/formulation.md, "index1 hands over to index2-ggl below rtol 1e-9").
// "index1-no-handover" is index1 at every rtol.
constexpr double kIndex1HandoverRtol = 1e-9;
// The rtol below which a dynamics step asked for `name` runs as index2-ggl; 0 if it never does.
double handover_rtol(const std::string& name);
// The formulation that integrates when `name` is asked at `rtol`.
std::string formulation_at(const std::string& name, double rtol);

}  // namespace mbdae
