#include "cases/run/failure_diagnosis.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "formulation/sensors.h"
#include "formulation/singularity.h"

namespace mbdae {
namespace {

std::string num(double x, int digits = 6) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.*g", digits, x);
  return buf;
}

}  // namespace

namespace {

using json = nlohmann::ordered_json;

// The last configuration: driven coordinates (their value and the drive's), then the sensors of
// the output file (no accelerations: they need a solve at a configuration that may be
// singular). `reached` and `targets` receive the same as text.
json last_configuration(const System& sys, const std::vector<char>& modes, const std::vector<int>& columns,
                        const double* q, const double* v, double t, double t_input, std::string& reached,
                        std::string& targets) {
  std::vector<double> values(sys.sensors.size(), 0.0);
  evaluate_sensors(sys, modes, q, v, nullptr, t_input, values.data());
  json coords = json::object(), drives = json::object(), sensors = json::object();
  std::ostringstream r, g;
  for (int k = 0; k < static_cast<int>(sys.coordinates.size()); ++k) {
    const JointCoordinate& c = sys.coordinates[k];
    const double value = coordinate_value(sys, k, q);
    coords[c.name] = value;
    if (c.merged || c.spec.mode != CoordinateSpec::Mode::kDriven) continue;
    const double target = c.spec.drive.value(t_input);
    drives[c.name] = {{"reached", value}, {"drive", target}};
    g << (g.tellp() > 0 ? ", " : "") << c.name << " = " << num(target, 10);
    r << (r.tellp() > 0 ? ", " : "") << c.name << " = " << num(value, 10);
  }
  for (int s : columns) {
    const Sensor& sensor = sys.sensors[s];
    if (sensor.type == SensorSpec::Type::kAcceleration) continue;
    sensors[sensor.name] = values[s];
    if (drives.contains(sensor.name)) continue;  // already listed
    r << (r.tellp() > 0 ? ", " : "") << sensor.name << " = " << num(values[s], 10);
  }
  reached = r.str();
  targets = g.str();
  return {{"t", t}, {"drives", drives}, {"coordinates", coords}, {"sensors", sensors}};
}

// Whether the equations set aside as redundant at the start (`all` has them) are no longer the
// dependent ones at q: then the message says so instead of a singular configuration.
void check_degraded_choice(const System& sys, const System& all, const double* q, double t, double t_input,
                           double singular_ratio, const std::string& reached, const std::string& solver_message,
                           FailureDiagnosis& out) {
  const EquationChoiceCheck ck = check_equation_choice(all, sys, q, t_input, singular_ratio);
  out.degraded_choice = ck.degraded;
  out.details["equation_choice"] = {{"degraded", ck.degraded},         {"kept_ratio", ck.kept_ratio},
                                    {"rechosen_ratio", ck.rechosen_ratio}, {"set_aside", ck.set_aside},
                                    {"set_aside_again", ck.set_aside_again}, {"rechosen", ck.rechosen}};
  if (!ck.degraded) return;
  out.message = "the equations set aside as redundant at the start are no longer the dependent ones at t = " +
                num(t, 10) + " (a degraded equation choice, not a singular configuration): the kept equations' "
                "row-normalized Jacobian has s_min / s_max = " + num(ck.kept_ratio, 3) +
                ", with the equations chosen again there " + num(ck.rechosen_ratio, 3) +
                "; last reached configuration: " + reached + " (solver: " + solver_message + ")";
}

std::string singular_message(const SingularityReport& r, double t, double condition, const std::string& reached,
                             const std::string& targets, const std::string& solver_message) {
  std::ostringstream os;
  if (!targets.empty())
    os << "the mechanism cannot reach " << targets << " at t = " << num(t, 10) << ": ";
  else
    os << "the mechanism reached a singular configuration at t = " << num(t, 10) << ": ";
  os << "the constraint Jacobian becomes singular (condition estimate " << num(condition, 3)
     << ", smallest singular value of the row-normalized Jacobian " << num(r.smallest_singular_value, 3)
     << ", largest " << num(r.largest_singular_value, 3) << "), the constraints that lose rank are ";
  // Joints, cuts and drives whose equations weigh at least half the largest in the dependent
  // combination (the Euler-parameter norms, bodies' own equations, are left to summary.json).
  std::vector<std::string> named;
  for (const auto& d : r.dependent) {
    const std::string& g = d.group;
    if (d.weight < kNamedWeight || d.owner == Constraint::Owner::kNorm) continue;
    if (std::find(named.begin(), named.end(), g) == named.end()) named.push_back(g);
  }
  for (size_t i = 0; i < named.size(); ++i) os << (i ? ", " : "") << named[i];
  os << " (largest weights first; all in summary.json); last reached configuration (t = " << num(t, 10)
     << "): " << reached << " (solver: " << solver_message << ")";
  return os.str();
}

}  // namespace

FailureDiagnosis diagnose_integration_failure(const System& sys, const std::vector<char>& modes,
                                              const std::vector<int>& columns, const double* q,
                                              const double* v, double t, double t_input,
                                              double condition, const std::string& solver_message,
                                              const System* all) {
  FailureDiagnosis out;
  std::string reached, targets;
  out.details["last_configuration"] = last_configuration(sys, modes, columns, q, v, t, t_input, reached, targets);
  const SingularityReport r = diagnose_singularity(sys, q, t_input);
  const double ratio = r.largest_singular_value > 0 ? r.smallest_singular_value / r.largest_singular_value : 0.0;
  out.singular = r.rank < r.equations || ratio < kSingularRatio;
  json dependent = json::array();
  for (const auto& d : r.dependent) dependent.push_back({{"equation", d.label}, {"weight", d.weight}});
  out.details["constraint_jacobian"] = {{"singular", out.singular},
                                        {"condition_estimate", condition},
                                        {"smallest_singular_value", r.smallest_singular_value},
                                        {"largest_singular_value", r.largest_singular_value},
                                        {"rank", r.rank},
                                        {"equations", r.equations},
                                        {"losing_rank", r.constraints},
                                        {"dependent_equations", dependent}};
  const bool set_aside = all && all->num_constraint_rows() > sys.num_constraint_rows();
  if (set_aside && (out.singular || ratio < kNearlySingularRatio)) {
    check_degraded_choice(sys, *all, q, t, t_input, out.singular ? kSingularRatio : kNearlySingularRatio, reached,
                          solver_message, out);
    if (out.degraded_choice) return out;
  }
  if (!out.singular) return out;
  out.message = singular_message(r, t, condition, reached, targets, solver_message);
  return out;
}

}  // namespace mbdae
