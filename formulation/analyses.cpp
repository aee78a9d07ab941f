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

// The Newton iteration's merit is max(|Q residual| / force scale, |Phi|). The force scale is
// that of the iterate (max(1, |Q|) at x), and a trial point is compared on the same scale: a
// scale taken over every evaluation (trials included) changed between the two merits compared.
EquilibriumResult solve_equilibrium(const System& sys_in, std::vector<double>& q,
                                    const EquilibriumOptions& o) {
  EquilibriumResult res;
  System sys = sys_in;
  const int first_hold = static_cast<int>(sys.constraints.size());
  for (int k : o.hold) sys.constraints.push_back(hold_constraint(sys, k, coordinate_value(sys, k, q.data())));
  const std::vector<int> off = constraint_offsets(sys);
  const int nq = sys.nq(), nc = off.back(), np = static_cast<int>(o.parameters.size());
  const int n = nq + nc + np;
  std::vector<int> release_rows;
  for (int k : o.release)
    for (size_t h = 0; h < o.hold.size(); ++h)
      if (o.hold[h] == k) release_rows.push_back(off[first_hold + h]);
  if (static_cast<int>(release_rows.size()) != np) {
    res.message = "equilibrium needs one released held coordinate per unknown parameter";
    return res;
  }
  const std::vector<double> zeros(nq, 0.0);
  std::vector<char> modes = initial_modes(sys, q.data(), o.t);

  // Unknowns x = [q, lambda, params]. Initial multipliers from the acceleration-level solve.
  std::vector<double> x(n, 0.0);
  std::copy(q.begin(), q.end(), x.begin());
  {
    AugmentedSolver aug(sys);
    std::vector<double> a(nq);
    aug.accelerations(modes, q.data(), zeros.data(), o.t, a.data(), x.data() + nq);
  }
  for (int p = 0; p < np; ++p)
    x[nq + nc + p] = *force_parameter(sys.forces[o.parameters[p].first], o.parameters[p].second);

  auto set_parameters = [&](const double* xv) {
    for (int p = 0; p < np; ++p)
      *force_parameter(sys.forces[o.parameters[p].first], o.parameters[p].second) = xv[nq + nc + p];
  };
  std::vector<double> f(n), work(nq);
  // Returns the force scale at xv, max(1, |Q(xv)|).
  auto residual = [&](const double* xv, double* out) {
    set_parameters(xv);
    generalized_forces(sys, modes, xv, zeros.data(), o.t, work.data());
    double force_scale = 1.0;
    for (int i = 0; i < nq; ++i) {
      out[i] = -work[i];
      force_scale = std::fmax(force_scale, std::fabs(work[i]));
    }
    add_constraint_forces(sys, off, xv, xv + nq, out);
    constraint_values(sys, off, xv, o.t, out + nq);
    for (int p = 0; p < np; ++p) out[nq + nc + p] = xv[nq + release_rows[p]];
    return force_scale;
  };
  auto assemble = [&](const double* xv, SparseAssembler& a) {
    set_parameters(xv);
    assemble_force_derivatives(sys, modes, xv, zeros.data(), o.t, 0, 0, -1, a);
    assemble_constraint_hessian(sys, off, xv, xv + nq, 0, 0, a);
    assemble_constraint_jacobian(sys, off, xv, 1.0, nq, 0, 0, nq, a);
    for (int p = 0; p < np; ++p) {
      const Force& fo = sys.forces[o.parameters[p].first];
      const Vec14 d = force_parameter_derivative(fo, gather(xv, fo.bi, fo.bj), LocalState{}, o.t,
                                                 modes[o.parameters[p].first], o.parameters[p].second);
      for (int l = 0; l < 14; ++l) {
        const int b = l < 7 ? fo.bi : fo.bj;
        if (b >= 0) a.add(7 * b + l % 7, nq + nc + p, -d[l]);
      }
      a.add(nq + nc + p, nq + release_rows[p], 1.0);
    }
  };
  SparseAssembler a;
  a.begin_pattern(n, n);
  assemble(x.data(), a);
  a.finalize();
  KluSolver klu;
  klu.analyze(a.pattern());
  std::vector<double> values(a.pattern().nnz()), dx(n), trial(n), ftrial(n);

  auto norms = [&](const double* fv, double force_scale, double& fr, double& cr) {
    fr = max_abs(fv, nq) / force_scale;
    cr = max_abs(fv + nq, nc);
    for (int p = 0; p < np; ++p) fr = std::fmax(fr, std::fabs(fv[nq + nc + p]) / force_scale);
  };
  double scale = residual(x.data(), f.data());
  double fr, cr;
  norms(f.data(), scale, fr, cr);
  auto merit = [&](double frv, double crv) { return std::fmax(frv, crv); };
  for (res.iterations = 0; res.iterations < o.max_iterations; ++res.iterations) {
    if (fr < 1e-13 && cr < 1e-13) break;
    a.begin_values(values.data());
    assemble(x.data(), a);
    if (!klu.factor(values.data())) {
      res.message = "equilibrium Jacobian is singular";
      break;
    }
    for (int i = 0; i < n; ++i) dx[i] = -f[i];
    if (!klu.solve(dx.data())) {
      res.message = "equilibrium Newton step: the KLU solve failed";
      break;
    }
    double alpha = 1.0, frt = fr, crt = cr, trial_scale = scale;
    for (int ls = 0; ls < 20; ++ls, alpha *= 0.5) {
      for (int i = 0; i < n; ++i) trial[i] = x[i] + alpha * dx[i];
      trial_scale = residual(trial.data(), ftrial.data());
      norms(ftrial.data(), scale, frt, crt);  // on the iterate's scale, as fr
      if (merit(frt, crt) < merit(fr, cr) || merit(frt, crt) < 1e-12) break;
    }
    if (!(merit(frt, crt) < merit(fr, cr))) {
      // No decrease: we are at rounding level (or stuck).
      break;
    }
    x = trial;
    f = ftrial;
    scale = trial_scale;
    norms(f.data(), scale, fr, cr);
  }
  set_parameters(x.data());
  res.force_residual = fr;
  res.constraint_residual = cr;
  res.converged = res.message.empty() && fr < 1e-10 && cr < 1e-12;
  if (!res.converged && res.message.empty()) {
    std::ostringstream os;
    os << "equilibrium did not converge: relative force residual " << fr << ", constraint residual " << cr;
    res.message = os.str();
  }
  std::copy(x.begin(), x.begin() + nq, q.begin());
  for (int p = 0; p < np; ++p) {
    res.parameter_values.push_back(x[nq + nc + p]);
  }
  for (size_t h = 0; h < o.hold.size(); ++h) res.hold_reactions.push_back(x[nq + off[first_hold + h]]);
  return res;
}

}  // namespace mbdae
