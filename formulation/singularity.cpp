#include "formulation/singularity.h"

#include <SuiteSparseQR.hpp>

#include <algorithm>
#include <cmath>

#include "formulation/mechanics.h"
#include "formulation/normalized_jacobian.h"
#include "formulation/redundancy.h"

namespace mbdae {
namespace {

// Label and constraint (index in sys.constraints) of each scalar equation (row) of Phi_q.
struct RowNames {
  std::vector<std::string> label;
  std::vector<int> constraint;
};
RowNames row_names(const System& sys) {
  RowNames out;
  for (size_t k = 0; k < sys.constraints.size(); ++k)
    for (int r = 0; r < sys.constraints[k].rows(); ++r) {
      out.label.push_back(row_label(sys.constraints[k], r));
      out.constraint.push_back(static_cast<int>(k));
    }
  return out;
}

// Equation `label` of constraint c with its weight, named by its owner.
DependentEquation dependent_equation(const Constraint& c, const std::string& label, double weight) {
  return {label, weight, constraint_group(c), c.owner};
}

double norm2(const double* x, int n) {
  double s = 0;
  for (int i = 0; i < n; ++i) s += x[i] * x[i];
  return std::sqrt(s);
}

// Inverse iteration for the smallest singular value of A (A E = Q R of full rank):
// x <- (A^T A)^-1 x = E R^-1 R^-T E^T x. Returns it; `weight` gets |x_i| / max |x|, the share of
// each equation in the near-dependency.
double smallest_singular_value(SuiteSparseQR_factorization<double>* qr, int nc, std::vector<double>& weight,
                               cholmod_common* cc) {
  cholmod_dense* x = cholmod_l_allocate_dense(nc, 1, nc, CHOLMOD_REAL, cc);
  auto* xv = static_cast<double*>(x->x);
  for (int i = 0; i < nc; ++i) xv[i] = 1.0 + 0.01 * (i % 7);  // not orthogonal to anything simple
  double lambda = 0;
  for (int it = 0; it < 50; ++it) {
    const double n0 = norm2(xv, nc);
    for (int i = 0; i < nc; ++i) xv[i] /= n0;
    cholmod_dense* b = SuiteSparseQR_solve<double>(SPQR_RTX_EQUALS_ETB, qr, x, cc);
    cholmod_dense* z = b ? SuiteSparseQR_solve<double>(SPQR_RETX_EQUALS_B, qr, b, cc) : nullptr;
    if (b) cholmod_l_free_dense(&b, cc);
    if (!z) break;
    const auto* zv = static_cast<const double*>(z->x);
    const double lambda_new = norm2(zv, nc);
    std::copy(zv, zv + nc, xv);
    cholmod_l_free_dense(&z, cc);
    const bool settled = std::fabs(lambda_new - lambda) <= 1e-10 * lambda_new;
    lambda = lambda_new;
    if (settled && it > 2) break;
  }
  const double n0 = norm2(xv, nc);
  double ymax = 0;
  for (int i = 0; i < nc; ++i) ymax = std::fmax(ymax, std::fabs(xv[i]));
  for (int i = 0; i < nc; ++i) weight[i] = ymax > 0 ? std::fabs(xv[i]) / ymax : 0.0;
  cholmod_l_free_dense(&x, cc);
  return lambda > 0 && n0 > 0 ? 1.0 / std::sqrt(lambda) : 0.0;
}

// Largest singular value of A (nc columns): power iteration on A^T A.
double largest_singular_value(cholmod_sparse* a, int nc, cholmod_common* cc) {
  cholmod_dense* x = cholmod_l_allocate_dense(nc, 1, nc, CHOLMOD_REAL, cc);
  cholmod_dense* w = cholmod_l_allocate_dense(a->nrow, 1, a->nrow, CHOLMOD_REAL, cc);
  auto* xv = static_cast<double*>(x->x);
  std::fill(xv, xv + nc, 1.0);
  double one[2] = {1, 0}, zero[2] = {0, 0}, s2 = 0;
  for (int it = 0; it < 30; ++it) {
    const double n0 = norm2(xv, nc);
    for (int i = 0; i < nc; ++i) xv[i] /= n0;
    cholmod_l_sdmult(a, 0, one, zero, x, w, cc);  // w = A x
    cholmod_l_sdmult(a, 1, one, zero, w, x, cc);  // x = A^T w
    s2 = norm2(xv, nc);
  }
  cholmod_l_free_dense(&x, cc);
  cholmod_l_free_dense(&w, cc);
  return std::sqrt(s2);
}

// The equations to name: exactly dependent ones (as the redundancy check removes them) when the
// rank is short, else those whose weight in the smallest singular vector reaches min_weight.
void name_dependent(const System& sys, const double* q, double t, const std::vector<double>& weight,
                    double min_weight, SingularityReport& report) {
  const RowNames names = row_names(sys);
  const int nc = report.equations;
  if (report.rank < nc) {
    const RedundancyReport rr = find_redundant_constraints(sys, q, t);
    for (size_t i = 0; i < rr.redundant.size(); ++i)
      report.dependent.push_back(dependent_equation(sys.constraints[rr.redundant_constraint[i]], rr.redundant[i], 1.0));
  } else {
    std::vector<int> idx;
    for (int i = 0; i < nc; ++i)
      if (weight[i] >= min_weight) idx.push_back(i);
    std::stable_sort(idx.begin(), idx.end(), [&](int i, int j) { return weight[i] > weight[j]; });
    for (int i : idx)
      report.dependent.push_back(dependent_equation(sys.constraints[names.constraint[i]], names.label[i], weight[i]));
  }
  for (const auto& d : report.dependent)
    if (std::find(report.constraints.begin(), report.constraints.end(), d.group) == report.constraints.end())
      report.constraints.push_back(d.group);
}

}  // namespace

SingularityReport diagnose_singularity(const System& sys, const double* q, double t, double min_weight) {
  SingularityReport report;
  const int nc = sys.num_constraint_rows();
  report.equations = nc;
  if (nc == 0) return report;
  std::vector<double> weight(nc, 0.0);
  cholmod_common cc;
  cholmod_l_start(&cc);
  cholmod_sparse* a = normalized_constraint_jacobian_transpose(sys, q, &cc);
  SuiteSparseQR_factorization<double>* qr =
      SuiteSparseQR_factorize<double>(SPQR_ORDERING_DEFAULT, SPQR_DEFAULT_TOL, a, &cc);
  report.rank = qr ? static_cast<int>(qr->rank) : 0;
  if (qr && report.rank == nc) report.smallest_singular_value = smallest_singular_value(qr, nc, weight, &cc);
  report.largest_singular_value = largest_singular_value(a, nc, &cc);
  if (qr) SuiteSparseQR_free<double>(&qr, &cc);
  cholmod_l_free_sparse(&a, &cc);
  cholmod_l_finish(&cc);
  name_dependent(sys, q, t, weight, min_weight, report);
  return report;
}

namespace {
double ratio(const SingularityReport& r) {
  if (r.rank < r.equations) return 0.0;
  return r.largest_singular_value > 0 ? r.smallest_singular_value / r.largest_singular_value : 0.0;
}
// The loosest rank tolerance at which check_equation_choice chooses the equations again.
constexpr double kLoosestRankTolerance = 1e-3;
}  // namespace

EquationChoiceCheck check_equation_choice(const System& all, const System& kept, const double* q, double t,
                                          double singular_ratio) {
  EquationChoiceCheck out;
  out.kept_ratio = ratio(diagnose_singularity(kept, q, t));
  out.set_aside = all.num_constraint_rows() - kept.num_constraint_rows();
  // The mechanism sets aside as many equations in every regular configuration. Near the instant
  // where the kept ones go singular, the rank decision at the default tolerance can keep a row
  // that is nearly dependent (the turntable four-bar with index1, 3e-5 s before its quarter turn:
  // 2 set aside, the new choice's s_min / s_max 7e-11); the choice is then made again at looser
  // rank tolerances, up to kLoosestRankTolerance, until it sets aside as many as at the start.
  EquationChoice again = choose_independent_equations(all, q, t);
  for (double tol = 1e-8; static_cast<int>(again.report.redundant.size()) < out.set_aside &&
                          tol <= kLoosestRankTolerance;
       tol *= 10)
    again = choose_independent_equations(all, q, t, tol);
  out.rechosen = again.report.redundant;
  out.set_aside_again = static_cast<int>(again.report.redundant.size());
  out.rechosen_ratio = ratio(diagnose_singularity(again.system, q, t));
  out.degraded = out.set_aside > 0 && out.set_aside_again == out.set_aside && out.kept_ratio < singular_ratio &&
                 out.rechosen_ratio >= singular_ratio;
  return out;
}

}  // namespace mbdae
