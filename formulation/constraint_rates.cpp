#include "formulation/constraint_rates.h"

#include <algorithm>
#include <cmath>

#include "formulation/constraints.h"

namespace mbdae {

void row_hessians(const Constraint& c, const LocalState& s, Mat14* h) {
  for (int r = 0; r < c.rows(); ++r) {
    double w[3] = {0, 0, 0};
    w[r] = 1.0;
    h[r].setZero();
    constraint_hessian(c, s, w, h[r]);
  }
}

namespace {

// Whether local column l of a constraint's Hessian-vector rows is in the pattern: for the
// constraints whose Hessian has no position (r) entries, the rows of H_i w, and of
// d(v^T H_i v)/dq, vanish in the r columns.
inline bool in_pattern(const Constraint& c, int l) {
  return global_index(c.bi, c.bj, l) >= 0 && (l % 7 >= 3 || constraint_hessian_touches_r(c));
}

// H x for a constraint row's local Hessian; without position entries (!touches_r) only its
// two 4 x 4 rotation blocks' rows and columns (the assembly leaves the rest out as well).
Vec14 hessian_times(const Mat14& h, const Vec14& x, bool touches_r) {
  if (touches_r) return h.lazyProduct(x);
  static constexpr int kRot[8] = {3, 4, 5, 6, 10, 11, 12, 13};
  Vec14 out = Vec14::Zero();
  for (int a : kRot) {
    double sum = 0;
    for (int b : kRot) sum += h(a, b) * x[b];
    out[a] = sum;
  }
  return out;
}

// The Hessian terms of one constraint for one x (local vectors): f1 += sum mu_r H_r x,
// f2 += sum lambda_r H_r x and g[r] = (H_r v)^T x, from the row Hessians h.
void hessian_terms(const Constraint& c, const Mat14* h, const Vec14& x, const Vec14& vl, const double* mu,
                   const double* lambda, Vec14& f1, Vec14& f2, double* g) {
  const bool touches_r = constraint_hessian_touches_r(c);
  for (int r = 0; r < c.rows(); ++r) {
    const Vec14 hx = hessian_times(h[r], x, touches_r);
    f1 += mu[r] * hx;
    f2 += lambda[r] * hx;
    g[r] = vl.dot(hx);
  }
}

}  // namespace

void velocity_rows(const Constraint& c, const Row14* rows, const double* v, double t, double* out) {
  double pt[3], ptt[3];
  constraint_time_derivatives(c, t, pt, ptt);
  const Vec14 vl = gather_local(v, c.bi, c.bj);
  for (int r = 0; r < c.rows(); ++r) out[r] = rows[r].dot(vl) + pt[r];
}

void constraint_hessian_terms(const Constraint& c, const LocalState& s, const Vec14& x, const Vec14& v,
                              const double* mu, const double* lambda, Vec14& f1, Vec14& f2, double* g, Mat14* h,
                              bool& have_h) {
  if (constraint_hessian_products(c, s, x, v, mu, lambda, f1, f2, g)) return;
  if (!have_h) row_hessians(c, s, h);
  have_h = true;
  hessian_terms(c, h, x, v, mu, lambda, f1, f2, g);
}

void velocity_constraint_values(const System& sys, const std::vector<int>& off, const double* q,
                                const double* v, double t, double* out) {
  Row14 rows[3];
  for (size_t k = 0; k < sys.constraints.size(); ++k) {
    const Constraint& c = sys.constraints[k];
    constraint_jacobian(c, gather(q, c.bi, c.bj), rows);
    velocity_rows(c, rows, v, t, out + off[k]);
  }
}

void velocity_constraint_values(const System& sys, const std::vector<int>& off,
                                const std::vector<Row14>& cached, const double* v, double t, double* out) {
  for (size_t k = 0; k < sys.constraints.size(); ++k)
    velocity_rows(sys.constraints[k], cached.data() + 3 * k, v, t, out + off[k]);
}

void stabilized_acceleration_constraints(const System& sys, const std::vector<int>& off,
                                         const std::vector<Row14>& cached, const double* q,
                                         const double* v, const double* a, double t, double alpha,
                                         double beta, double* out) {
  double phi[3], pt[3], ptt[3], gamma[3];
  for (size_t k = 0; k < sys.constraints.size(); ++k) {
    const Constraint& c = sys.constraints[k];
    const Row14* rows = cached.data() + 3 * k;
    const LocalState s = gather(q, c.bi, c.bj);
    const Vec14 vl = gather_local(v, c.bi, c.bj), al = gather_local(a, c.bi, c.bj);
    constraint_value(c, s, t, phi);
    constraint_time_derivatives(c, t, pt, ptt);
    constraint_gamma(c, s, gather(v, c.bi, c.bj), ptt, gamma);
    for (int r = 0; r < c.rows(); ++r) {
      out[off[k] + r] = rows[r].dot(al) - gamma[r] + 2.0 * alpha * (rows[r].dot(vl) + pt[r]) +
                        beta * beta * phi[r];
    }
  }
}

void assemble_hessian_vector_rows(const System& sys, const std::vector<int>& off, const double* q,
                                  const double* w1, double s1, const double* w2, double s2,
                                  int row0, int col0, SparseAssembler& a) {
  Mat14 h[3];
  for (size_t k = 0; k < sys.constraints.size(); ++k) {
    const Constraint& c = sys.constraints[k];
    row_hessians(c, gather(q, c.bi, c.bj), h);
    const Vec14 x1 = gather_local(w1, c.bi, c.bj);
    const Vec14 x2 = w2 ? gather_local(w2, c.bi, c.bj) : Vec14::Zero();
    for (int r = 0; r < c.rows(); ++r) {
      // H symmetric: row r of d(Phi_q w)/dq is w^T H_r = (H_r w)^T.
      Vec14 hw = s1 * (h[r] * x1);
      if (w2) hw += s2 * (h[r] * x2);
      for (int l = 0; l < 14; ++l)
        if (in_pattern(c, l)) a.add(row0 + off[k] + r, col0 + global_index(c.bi, c.bj, l), hw[l]);
    }
  }
}

void assemble_gamma_position_derivative_fd(const System& sys, const std::vector<int>& off,
                                           const double* q, const double* v, double scale,
                                           int row0, int col0, SparseAssembler& a) {
  Mat14 hp[3], hm[3];
  for (size_t k = 0; k < sys.constraints.size(); ++k) {
    const Constraint& c = sys.constraints[k];
    // Hessians of norm, point and orientation rows are constant (quadratic in p): no third
    // derivatives.
    const bool constant_hessian = c.type == Constraint::Type::kNorm ||
                                  c.type == Constraint::Type::kPoint ||
                                  c.type == Constraint::Type::kOrientation;
    const LocalState s = gather(q, c.bi, c.bj);
    const Vec14 x = local_vector(s), vl = gather_local(v, c.bi, c.bj);
    double d[3][14] = {};
    if (!constant_hessian && !a.recording()) {
      for (int l = 0; l < 14; ++l) {
        if (!in_pattern(c, l)) continue;
        const double eps = 1e-6 * std::max(1.0, std::fabs(x[l]));
        Vec14 xp = x, xm = x;
        xp[l] += eps;
        xm[l] -= eps;
        row_hessians(c, local_state(xp), hp);
        row_hessians(c, local_state(xm), hm);
        for (int r = 0; r < c.rows(); ++r)
          d[r][l] = (vl.dot(hp[r] * vl) - vl.dot(hm[r] * vl)) / (2.0 * eps);
      }
    }
    for (int r = 0; r < c.rows(); ++r)
      for (int l = 0; l < 14; ++l)
        if (in_pattern(c, l))
          a.add(row0 + off[k] + r, col0 + global_index(c.bi, c.bj, l), scale * d[r][l]);
  }
}

}  // namespace mbdae
