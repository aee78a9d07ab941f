// What a failed integration leaves in summary.json and in its message: the last configuration
// reached, and, when the constraint Jacobian there is (nearly) singular, the diagnosis of
// formulation/singularity.h: "the mechanism cannot reach q4 = X at t = T: the constraint Jacobian
// becomes singular (...), the constraints that lose rank are ..., last reached configuration ...".
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "formulation/system.h"

namespace mbdae {

// The Jacobian counts as singular where the row-normalized Phi_q has s_min / s_max below this
// (the suspension's values along its kinematic drive: docs/extreme-cases.md).
constexpr double kSingularRatio = 1e-4;
// With equations set aside, a failure where the kept ones are nearly singular (below this) while
// the equations chosen again at q are not is told as a degraded choice too: the corrector can
// fail before the kept Jacobian is singular (index2-ggl on the turntable four-bar with the world
// choice: s_min / s_max 3.8e-4 at the failure, just before the quarter turn).
constexpr double kNearlySingularRatio = 1e-2;
// The message names the joints, cuts and drives with an equation of at least this weight.
constexpr double kNamedWeight = 0.5;

struct FailureDiagnosis {
  bool singular = false;
  bool degraded_choice = false;  // singular only for the equations kept: the mechanism is not
  std::string message;       // the replacement message when singular (else empty)
  nlohmann::ordered_json details;  // "last_configuration" and "singular_configuration" entries
};

// q and v at the last step reached (time t, inputs evaluated at t_input); `columns` are the
// sensors of the output file (reported in the last configuration, accelerations left out);
// `condition` is the constraint condition estimate at q (AugmentedSolver::constraint_condition).
// `all`, if given, is the system with every equation as built (sys without its redundant ones):
// a singular Jacobian is then told apart as the mechanism's or the equation choice's
// (check_equation_choice), and the message says which; a nearly singular one
// (kNearlySingularRatio) is told as the choice's when it is.
FailureDiagnosis diagnose_integration_failure(const System& sys, const std::vector<char>& modes,
                                              const std::vector<int>& columns, const double* q,
                                              const double* v, double t, double t_input,
                                              double condition, const std::string& solver_message,
                                              const System* all = nullptr);

}  // namespace mbdae
