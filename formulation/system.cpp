#include "formulation/system.h"

#include <algorithm>
#include <cmath>

#include "core/errors.h"
#include "formulation/force_types.h"
#include "formulation/model_rules.h"
#include "formulation/system_build.h"

namespace mbdae {

int System::num_constraint_rows() const {
  int n = 0;
  for (const auto& c : constraints) n += c.rows();
  return n;
}

int System::coordinate_index(const std::string& name) const {
  for (size_t k = 0; k < coordinates.size(); ++k)
    if (coordinates[k].name == name) return static_cast<int>(k);
  return -1;
}

int System::force_index(const std::string& name) const {
  for (size_t k = 0; k < forces.size(); ++k)
    if (forces[k].name == name) return static_cast<int>(k);
  return -1;
}

std::vector<double> System::breakpoints() const {
  std::vector<double> t;
  auto add = [&](const TimeFunction& f) {
    for (double b : f.breakpoints()) t.push_back(b);
  };
  for (const auto& c : constraints)
    if (c.type == Constraint::Type::kCoordinate) add(c.target);
  for (const auto& f : forces) {
    add(f.fx);
    add(f.fy);
    add(f.fz);
    add(f.ground);
  }
  std::sort(t.begin(), t.end());
  t.erase(std::unique(t.begin(), t.end()), t.end());
  return t;
}

Constraint hold_constraint(const System& sys, int k, double value) {
  const JointCoordinate& jc = sys.coordinates[k];
  Constraint c;
  c.type = Constraint::Type::kCoordinate;
  c.coord = jc.function;
  c.bi = jc.function.body_parent;
  c.bj = jc.function.body_child;
  c.target = TimeFunction::constant(value);
  c.owner = Constraint::Owner::kHold;
  c.owner_name = jc.name;
  c.label = "hold " + jc.name;
  return c;
}

double coordinate_value(const System& sys, int k, const double* q) {
  const JointCoordinate& jc = sys.coordinates[k];
  if (jc.merged) return jc.value_if_merged;
  const LocalState s = gather(q, jc.function.body_parent, jc.function.body_child);
  return coordinate_slope(jc.function, s).value;
}

double coordinate_rate(const System& sys, int k, const double* q, const double* v) {
  const JointCoordinate& jc = sys.coordinates[k];
  if (jc.merged) return 0.0;
  const LocalState s = gather(q, jc.function.body_parent, jc.function.body_child);
  return coordinate_slope(jc.function, s).grad.dot(
      gather_local(v, jc.function.body_parent, jc.function.body_child));
}

bool counts_turns(const System& sys, int k) {
  const JointCoordinate& jc = sys.coordinates[k];
  return !jc.merged && jc.function.rotation && jc.function.index != 1;
}

double continuous_coordinate(const System& sys, int k, double raw, double t, const CoordinateTurns* turns) {
  if (!counts_turns(sys, k)) return raw;
  double reference = sys.coordinates[k].spec.initial;
  if (turns) {
    reference = turns->value[k];
    if (turns->timed) reference += turns->rate[k] * (t - turns->time);
  }
  if (!std::isfinite(reference)) return raw;
  return raw + 2 * M_PI * std::round((reference - raw) / (2 * M_PI));
}

CoordinateTurns initial_turns(const System& sys) {
  CoordinateTurns turns;
  turns.value.resize(sys.coordinates.size());
  turns.rate.assign(sys.coordinates.size(), 0.0);
  for (size_t k = 0; k < sys.coordinates.size(); ++k) turns.value[k] = sys.coordinates[k].spec.initial;
  return turns;
}

std::vector<int> coordinates_with_turns(const System& sys) {
  std::vector<char> read(sys.coordinates.size(), 0);
  for (const Force& f : sys.forces)
    if (force_type(f.type).attach == ForceAttach::kCoordinate && !f.wrap && f.coordinate_index >= 0)
      read[f.coordinate_index] = 1;
  for (const Sensor& s : sys.sensors)
    if (s.type == SensorSpec::Type::kCoordinate && s.unwrap && s.target >= 0) read[s.target] = 1;
  std::vector<int> out;
  for (int k = 0; k < static_cast<int>(read.size()); ++k)
    if (read[k] && counts_turns(sys, k)) out.push_back(k);
  return out;
}

// Only the coordinates whose turns are read: a coordinate's jet costs thousands of instructions,
// and a mechanism has one per joint angle (docs/performance.md).
void update_turns(const System& sys, const double* q, const double* v, double t, CoordinateTurns& turns) {
  for (const int k : sys.turn_coordinates) {
    // One slope (value and gradient, coordinate_jet's without its Hessian) for the value and the
    // rate: coordinate_value and coordinate_rate would evaluate it twice.
    const CoordinateFunction& f = sys.coordinates[k].function;
    const ScalarSlope jet = coordinate_slope(f, gather(q, f.body_parent, f.body_child));
    const double value = continuous_coordinate(sys, k, jet.value, t, &turns);
    const double rate = jet.grad.dot(gather_local(v, f.body_parent, f.body_child));
    if (!std::isfinite(value) || !std::isfinite(rate)) continue;  // the run stops on it elsewhere
    turns.value[k] = value;
    turns.rate[k] = rate;
  }
  turns.time = t;
  turns.timed = true;
}

System build_system(const Model& model) {
  // The model's rules (formulation/model_rules.h), the same the loader reports in full: the
  // first problem refuses the model, so the stages below meet only valid references.
  const std::vector<ModelIssue> issues = check_model(model);
  if (!issues.empty())
    throw ModelError(issues.front().item.file, issues.front().item.line, issues.front().shown_field(),
                     issues.front().message);
  System sys;
  sys.name = model.name;
  sys.gravity = model.gravity;
  const ModelIndex index = resolve_tree(model);
  merge_locked_joints(index, sys);
  add_joint_constraints(index, sys);
  add_cut_constraints(index, sys);
  add_forces_and_sensors(index, sys);
  sys.turn_coordinates = coordinates_with_turns(sys);
  return sys;
}

}  // namespace mbdae
