// Dispatch of the force functions (forces.h) through the force-type table (force_types.h); the
// laws themselves are in formulation/forces/, one file each.
#include "formulation/forces.h"

#include <algorithm>
#include <cmath>

#include "formulation/force_types.h"

namespace mbdae {

void force_eval(const Force& f, const LocalState& x, const LocalState& v, double t,
                bool in_contact, Vec14& q, Mat14* dqx, Mat14* dqv, const LoadInput* in,
                Mat14x3* dqin) {
  force_type(f.type).eval(f, x, v, t, in_contact, q, dqx, dqv, in, dqin);
}

// A parameter named by the load's expressions, else one of its type's parameters (force_types.h).
double* force_parameter(Force& f, const std::string& p) {
  for (size_t k = 0; k < f.parameter_names.size(); ++k)
    if (f.parameter_names[k] == p) return &f.parameters[k];
  const ForceParameter* row = find_force_parameter(force_type(f.type), p);
  return row ? row->value(f) : nullptr;
}

Vec14 force_parameter_derivative(const Force& f, const LocalState& x, const LocalState& v, double t,
                                 bool in_contact, const std::string& parameter) {
  // Generalized forces are affine in these parameters, so a central difference is exact up to
  // rounding; the step is relative to the parameter's size.
  Force g = f;
  double* p = force_parameter(g, parameter);
  const double base = *p, h = 1e-3 * std::max(1.0, std::fabs(base));
  Vec14 qp = Vec14::Zero(), qm = Vec14::Zero();
  *p = base + h;
  force_eval(g, x, v, t, in_contact, qp, nullptr, nullptr);
  *p = base - h;
  force_eval(g, x, v, t, in_contact, qm, nullptr, nullptr);
  return (qp - qm) / (2 * h);
}

bool force_has_switch(const Force& f) { return force_type(f.type).switch_value != nullptr; }

double force_switch_value(const Force& f, const LocalState& x, double t) {
  const ForceSwitchFn g = force_type(f.type).switch_value;
  return g ? g(f, x, t) : 0.0;
}

double force_length(const Force& f, const LocalState& x, double t) { return force_type(f.type).length(f, x, t); }

double force_magnitude(const Force& f, const LocalState& x, const LocalState& v, double t,
                       bool in_contact, const LoadInput* in) {
  return force_type(f.type).magnitude(f, x, v, t, in_contact, in);
}

double force_potential(const Force& f, const LocalState& x, double t, bool in_contact, const LoadInput* in) {
  const ForcePotentialFn u = force_type(f.type).potential;
  return u ? u(f, x, t, in_contact, in) : 0.0;
}

}  // namespace mbdae
