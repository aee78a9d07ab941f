#include "formulation/analyses.h"

#include <cmath>
#include <sstream>

#include "core/klu_solver.h"
#include "formulation/augmented_solver.h"
#include "formulation/forces.h"
#include "formulation/mechanics.h"

namespace mbdae {

AssemblyResult assemble_positions(const System& sys, const std::vector<int>& held, double t,
                                  std::vector<double>& q) {
  System s = sys;
  for (int k : held) s.constraints.push_back(hold_constraint(sys, k, sys.coordinates[k].spec.initial));
  AugmentedSolver solver(s);
  const PositionSolveResult r = solver.positions(q.data(), t, 1e-12, 200);
  AssemblyResult out;
  out.converged = r.converged;
  out.iterations = r.iterations;
  out.residual = r.residual;
  if (!r.converged) {
    std::ostringstream os;
    os << "assembly did not converge after " << r.iterations << " iterations: max constraint violation "
       << r.residual << "; most violated: " << r.worst;
    out.message = os.str();
  }
  return out;
}

System with_force_parameters(const System& sys, const std::vector<std::pair<int, std::string>>& parameters,
                             const std::vector<double>& values) {
  System out = sys;
  for (size_t p = 0; p < parameters.size() && p < values.size(); ++p)
    *force_parameter(out.forces[parameters[p].first], parameters[p].second) = values[p];
  return out;
}

namespace {

// Static equilibrium as a root of F(x), x = [q, lambda, p] (p: the force parameters solved for):
//   F = [ Phi_q^T lambda - Q(q, 0, t),  Phi(q),  q_r ]
// where the held coordinates are extra constraints and q_r are the held coordinates released
// (their multipliers become the unknown parameters' equations). `sys` is a working copy whose
// force parameters take the values of p.
struct EquilibriumProblem {
  System sys;
  const EquilibriumOptions* o = nullptr;
  std::vector<int> off, release_rows;
  std::vector<char> modes;
  std::vector<double> zeros, work;
  int nq = 0, nc = 0, np = 0, first_hold = 0;
  int size() const { return nq + nc + np; }
};

// Empty when the problem is well posed, else the reason.
std::string setup_equilibrium(const System& sys_in, const std::vector<double>& q, const EquilibriumOptions& o,
                              EquilibriumProblem& e) {
  e.sys = sys_in;
  e.o = &o;
  e.first_hold = static_cast<int>(e.sys.constraints.size());
  for (int k : o.hold) e.sys.constraints.push_back(hold_constraint(e.sys, k, coordinate_value(e.sys, k, q.data())));
  e.off = constraint_offsets(e.sys);
  e.nq = e.sys.nq();
  e.nc = e.off.back();
  e.np = static_cast<int>(o.parameters.size());
  for (int k : o.release)
    for (size_t h = 0; h < o.hold.size(); ++h)
      if (o.hold[h] == k) e.release_rows.push_back(e.off[e.first_hold + h]);
  if (static_cast<int>(e.release_rows.size()) != e.np)
    return "equilibrium needs one released held coordinate per unknown parameter";
  e.zeros.assign(e.nq, 0.0);
  e.work.assign(e.nq, 0.0);
  e.modes = initial_modes(e.sys, q.data(), o.t);
  return "";
}

double& parameter(EquilibriumProblem& e, int p) {
  return *force_parameter(e.sys.forces[e.o->parameters[p].first], e.o->parameters[p].second);
}

void set_parameters(EquilibriumProblem& e, const double* x) {
  for (int p = 0; p < e.np; ++p) parameter(e, p) = x[e.nq + e.nc + p];
}

// x0 = [q, lambda from the acceleration-level solve at rest, the parameters' scene values].
std::vector<double> initial_unknowns(EquilibriumProblem& e, const std::vector<double>& q) {
  std::vector<double> x(e.size(), 0.0), a(e.nq);
  std::copy(q.begin(), q.end(), x.begin());
  AugmentedSolver aug(e.sys);
  aug.accelerations(e.modes, q.data(), e.zeros.data(), e.o->t, a.data(), x.data() + e.nq);
  for (int p = 0; p < e.np; ++p) x[e.nq + e.nc + p] = parameter(e, p);
  return x;
}

// F(x) into out; returns the force scale at x, max(1, |Q(x)|).
double equilibrium_residual(EquilibriumProblem& e, const double* x, double* out) {
  set_parameters(e, x);
  generalized_forces(e.sys, e.modes, x, e.zeros.data(), e.o->t, e.work.data());
  double force_scale = 1.0;
  for (int i = 0; i < e.nq; ++i) {
    out[i] = -e.work[i];
    force_scale = std::fmax(force_scale, std::fabs(e.work[i]));
  }
  add_constraint_forces(e.sys, e.off, x, x + e.nq, out);
  constraint_values(e.sys, e.off, x, e.o->t, out + e.nq);
  for (int p = 0; p < e.np; ++p) out[e.nq + e.nc + p] = x[e.nq + e.release_rows[p]];
  return force_scale;
}

// dF/dx (pattern or values, as the assembler is set).
void assemble_equilibrium(EquilibriumProblem& e, const double* x, SparseAssembler& a) {
  const int nq = e.nq, nc = e.nc;
  set_parameters(e, x);
  assemble_force_derivatives(e.sys, e.modes, x, e.zeros.data(), e.o->t, 0, 0, -1, a);
  assemble_constraint_hessian(e.sys, e.off, x, x + nq, 0, 0, a);
  assemble_constraint_jacobian(e.sys, e.off, x, 1.0, nq, 0, 0, nq, a);
  for (int p = 0; p < e.np; ++p) {
    const int k = e.o->parameters[p].first;
    const Force& fo = e.sys.forces[k];
    const Vec14 d = force_parameter_derivative(fo, gather(x, fo.bi, fo.bj), LocalState{}, e.o->t, e.modes[k],
                                               e.o->parameters[p].second);
    for (int l = 0; l < 14; ++l) {
      const int b = l < 7 ? fo.bi : fo.bj;
      if (b >= 0) a.add(7 * b + l % 7, nq + nc + p, -d[l]);
    }
    a.add(nq + nc + p, nq + e.release_rows[p], 1.0);
  }
}

// The merit's two parts: force rows (and parameter rows) over the force scale, constraint rows.
struct Merit {
  double force = 0, constraint = 0;
  double value() const { return std::fmax(force, constraint); }
};
Merit merit(const EquilibriumProblem& e, const double* f, double force_scale) {
  Merit m;
  m.force = max_abs(f, e.nq) / force_scale;
  m.constraint = max_abs(f + e.nq, e.nc);
  for (int p = 0; p < e.np; ++p) m.force = std::fmax(m.force, std::fabs(f[e.nq + e.nc + p]) / force_scale);
  return m;
}

// Damped Newton on F(x) = 0 from x; returns the merit reached, `message` set on a failure of the
// linear algebra. The merit's force scale is that of the iterate (max(1, |Q|) at x), and a trial
// point is compared on the same scale: a scale taken over every evaluation (trials included)
// changed between the two merits compared.
Merit newton_equilibrium(EquilibriumProblem& e, std::vector<double>& x, int& iterations, std::string& message) {
  const int n = e.size();
  SparseAssembler a;
  a.begin_pattern(n, n);
  assemble_equilibrium(e, x.data(), a);
  a.finalize();
  KluSolver klu;
  klu.analyze(a.pattern());
  std::vector<double> values(a.pattern().nnz()), f(n), dx(n), trial(n), ftrial(n);
  double scale = equilibrium_residual(e, x.data(), f.data());
  Merit m = merit(e, f.data(), scale);
  for (iterations = 0; iterations < e.o->max_iterations; ++iterations) {
    if (m.force < 1e-13 && m.constraint < 1e-13) break;
    a.begin_values(values.data());
    assemble_equilibrium(e, x.data(), a);
    if (!klu.factor(values.data())) {
      message = "equilibrium Jacobian is singular";
      break;
    }
    for (int i = 0; i < n; ++i) dx[i] = -f[i];
    if (!klu.solve(dx.data())) {
      message = "equilibrium Newton step: the KLU solve failed";
      break;
    }
    double alpha = 1.0, trial_scale = scale;
    Merit mt = m;
    for (int ls = 0; ls < 20; ++ls, alpha *= 0.5) {
      for (int i = 0; i < n; ++i) trial[i] = x[i] + alpha * dx[i];
      trial_scale = equilibrium_residual(e, trial.data(), ftrial.data());
      mt = merit(e, ftrial.data(), scale);  // on the iterate's scale, as m
      if (mt.value() < m.value() || mt.value() < 1e-12) break;
    }
    if (!(mt.value() < m.value())) break;  // no decrease: at rounding level (or stuck)
    x.swap(trial);
    f.swap(ftrial);
    scale = trial_scale;
    m = merit(e, f.data(), scale);
  }
  set_parameters(e, x.data());
  return m;
}

}  // namespace

EquilibriumResult solve_equilibrium(const System& sys, std::vector<double>& q, const EquilibriumOptions& o) {
  EquilibriumResult res;
  EquilibriumProblem e;
  res.message = setup_equilibrium(sys, q, o, e);
  if (!res.message.empty()) return res;
  std::vector<double> x = initial_unknowns(e, q);
  const Merit m = newton_equilibrium(e, x, res.iterations, res.message);
  res.force_residual = m.force;
  res.constraint_residual = m.constraint;
  res.converged = res.message.empty() && m.force < 1e-10 && m.constraint < 1e-12;
  if (!res.converged && res.message.empty()) {
    std::ostringstream os;
    os << "equilibrium did not converge: relative force residual " << m.force << ", constraint residual "
       << m.constraint;
    res.message = os.str();
  }
  std::copy(x.begin(), x.begin() + e.nq, q.begin());
  for (int p = 0; p < e.np; ++p) res.parameter_values.push_back(x[e.nq + e.nc + p]);
  for (size_t h = 0; h < o.hold.size(); ++h) res.hold_reactions.push_back(x[e.nq + e.off[e.first_hold + h]]);
  return res;
}

}  // namespace mbdae
