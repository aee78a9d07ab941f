#include "formulation/mechanics.h"

#include "core/finite_check.h"
#include "formulation/sensors.h"

#include <cmath>
#include <cstdlib>

namespace mbdae {
namespace {

inline Vec4 p_of(const double* q, int b) { return Eigen::Map<const Vec4>(q + 7 * b + 3); }

// Adds a local 14 x 14 block (rows and columns both local to bodies bi, bj).
void add_local_block(int bi, int bj, const Mat14& m, int row0, int col0, bool with_r,
                     SparseAssembler& a) {
  // The local coordinates that enter (global index, skipping ground and, without r, the
  // positions), once; then the same add() sequence, column by column.
  int local[14], global[14], n = 0;
  for (int l = 0; l < 14; ++l) {
    const int g = global_index(bi, bj, l);
    if (g < 0 || (!with_r && l % 7 < 3)) continue;
    local[n] = l;
    global[n++] = g;
  }
  for (int c = 0; c < n; ++c)
    for (int r = 0; r < n; ++r) a.add(row0 + global[r], col0 + global[c], m(local[r], local[c]));
}
}  // namespace

std::vector<int> constraint_offsets(const System& sys) {
  std::vector<int> off;
  int n = 0;
  for (const auto& c : sys.constraints) {
    off.push_back(n);
    n += c.rows();
  }
  off.push_back(n);
  return off;
}

std::vector<char> initial_modes(const System& sys, const double* q, double t) {
  std::vector<char> modes(sys.forces.size(), 1);
  for (size_t k = 0; k < sys.forces.size(); ++k) {
    const Force& f = sys.forces[k];
    if (force_has_switch(f)) modes[k] = force_switch_value(f, gather(q, f.bi, f.bj), t) > 0;
  }
  return modes;
}

void mass_times(const System& sys, const double* q, const double* acc, double* out) {
  for (int b = 0; b < sys.num_bodies(); ++b) {
    const SystemBody& body = sys.bodies[b];
    const double* a = acc + 7 * b;
    double* o = out + 7 * b;
    for (int k = 0; k < 3; ++k) o[k] = body.mass * a[k];
    const Mat34 l = L_matrix(p_of(q, b));
    Eigen::Map<Vec4>(o + 3) = 4.0 * l.transpose() * (body.inertia * (l * Eigen::Map<const Vec4>(a + 3)));
  }
}

void generalized_forces(const System& sys, const std::vector<char>& modes, const double* q,
                        const double* v, double t, double* out, const CoordinateTurns* turns) {
  for (int b = 0; b < sys.num_bodies(); ++b) {
    const SystemBody& body = sys.bodies[b];
    double* o = out + 7 * b;
    for (int k = 0; k < 3; ++k) o[k] = body.mass * sys.gravity[k];
    const Vec4 p = p_of(q, b), pd = p_of(v, b);
    Eigen::Map<Vec4>(o + 3) =
        -8.0 * L_matrix(pd).transpose() * (body.inertia * (L_matrix(p) * pd));
  }
  for (size_t k = 0; k < sys.forces.size(); ++k) {
    const Force& f = sys.forces[k];
    const Vec14 ql = force_local(sys, k, modes, q, v, t, turns);
    for (int l = 0; l < 14; ++l) {
      const int g = global_index(f.bi, f.bj, l);
      if (g >= 0) out[g] += ql[l];
    }
  }
}

Vec14 force_local(const System& sys, size_t k, const std::vector<char>& modes, const double* q, const double* v,
                  double t, const CoordinateTurns* turns) {
  const Force& f = sys.forces[k];
  Vec14 ql = Vec14::Zero();
  const LoadInput in = load_input(sys, f, modes, q, v, t, false, turns);
  force_eval(f, gather(q, f.bi, f.bj), gather(v, f.bi, f.bj), t, modes[k], ql, nullptr, nullptr, &in);
  return ql;
}

void body_momentum(const System& sys, int b, const double* q, const double* v, const double* acc, double* out) {
  const SystemBody& body = sys.bodies[b];
  const double* a = acc + 7 * b;
  for (int k = 0; k < 3; ++k) out[k] = body.mass * (a[k] - sys.gravity[k]);
  const Vec4 p = p_of(q, b), pd = p_of(v, b);
  const Mat34 l = L_matrix(p);
  Eigen::Map<Vec4>(out + 3) = 4.0 * l.transpose() * (body.inertia * (l * Eigen::Map<const Vec4>(a + 3))) +
                              8.0 * L_matrix(pd).transpose() * (body.inertia * (l * pd));
}

void constraint_values(const System& sys, const std::vector<int>& off, const double* q, double t,
                       double* phi) {
  for (size_t k = 0; k < sys.constraints.size(); ++k) {
    const Constraint& c = sys.constraints[k];
    constraint_value(c, gather(q, c.bi, c.bj), t, phi + off[k]);
  }
}

void constraint_rates(const System& sys, const std::vector<int>& off, const double* q,
                      const double* v, double t, double* phi_t, double* gamma) {
  for (size_t k = 0; k < sys.constraints.size(); ++k) {
    const Constraint& c = sys.constraints[k];
    double pt[3], ptt[3];
    constraint_time_derivatives(c, t, pt, ptt);
    if (phi_t)
      for (int r = 0; r < c.rows(); ++r) phi_t[off[k] + r] = pt[r];
    if (gamma)
      constraint_gamma(c, gather(q, c.bi, c.bj), gather(v, c.bi, c.bj), ptt, gamma + off[k]);
  }
}

namespace {
// out += J^T lambda for constraint c's rows (global columns of its two bodies).
void add_rows_transposed(const Constraint& c, const Row14* rows, const double* lambda, double* out) {
  for (int r = 0; r < c.rows(); ++r) {
    const double lam = lambda[r];
    for (int l = 0; l < 14; ++l) {
      const int g = global_index(c.bi, c.bj, l);
      if (g >= 0) out[g] += rows[r](l) * lam;
    }
  }
}
}  // namespace

void add_constraint_forces(const System& sys, const std::vector<int>& off, const double* q,
                           const double* lambda, double* out) {
  Row14 rows[3];
  for (size_t k = 0; k < sys.constraints.size(); ++k) {
    const Constraint& c = sys.constraints[k];
    constraint_jacobian(c, gather(q, c.bi, c.bj), rows);
    add_rows_transposed(c, rows, lambda + off[k], out);
  }
}

void constraint_jacobian_rows(const System& sys, const double* q, std::vector<Row14>& rows) {
  rows.resize(3 * sys.constraints.size());  // sized once: no allocation after the first call
  for (size_t k = 0; k < sys.constraints.size(); ++k) {
    const Constraint& c = sys.constraints[k];
    constraint_jacobian(c, gather(q, c.bi, c.bj), rows.data() + 3 * k);
  }
}

void constraint_jacobian_times(const System& sys, const std::vector<int>& off, const double* q,
                               const double* v, double* out) {
  Row14 rows[3];
  for (size_t k = 0; k < sys.constraints.size(); ++k) {
    const Constraint& c = sys.constraints[k];
    constraint_jacobian(c, gather(q, c.bi, c.bj), rows);
    const Vec14 vl = gather_local(v, c.bi, c.bj);
    for (int r = 0; r < c.rows(); ++r) out[off[k] + r] = rows[r].dot(vl);
  }
}

double max_abs(const double* x, int n) {
  // Four running maxima that the compiler turns into packed max instructions: `a > m ? a : m`
  // is the instruction's own rule, and skips a NaN entry as max_num does; the maximum is exact,
  // so the order does not change it.
  double m[4] = {0, 0, 0, 0};
  int i = 0;
  for (; i + 4 <= n; i += 4)
    for (int k = 0; k < 4; ++k) {
      const double a = std::fabs(x[i + k]);
      m[k] = a > m[k] ? a : m[k];
    }
  for (; i < n; ++i) m[0] = max_num(m[0], std::fabs(x[i]));
  return max_num(max_num(m[0], m[1]), max_num(m[2], m[3]));
}

void assemble_mass(const System& sys, const double* q, double scale, int row0, int col0,
                   SparseAssembler& a) {
  for (int b = 0; b < sys.num_bodies(); ++b) {
    const SystemBody& body = sys.bodies[b];
    const int o = 7 * b;
    for (int k = 0; k < 3; ++k) a.add(row0 + o + k, col0 + o + k, scale * body.mass);
    const Mat34 l = L_matrix(p_of(q, b));
    const Mat4 m = 4.0 * scale * l.transpose() * body.inertia * l;
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) a.add(row0 + o + 3 + r, col0 + o + 3 + c, m(r, c));
  }
}

void assemble_weights(const System& sys, double wr, double wp, int row0, int col0,
                      SparseAssembler& a) {
  for (int b = 0; b < sys.num_bodies(); ++b) {
    const int o = 7 * b;
    for (int k = 0; k < 3; ++k) a.add(row0 + o + k, col0 + o + k, wr);
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) a.add(row0 + o + 3 + r, col0 + o + 3 + c, r == c ? wp : 0.0);
  }
}

void assemble_inertia_derivatives(const System& sys, const double* q, const double* v,
                                  const double* acc, int row0, int colq, int colv,
                                  SparseAssembler& a) {
  for (int b = 0; b < sys.num_bodies(); ++b) {
    const Mat3& j = sys.bodies[b].inertia;
    const Vec4 p = p_of(q, b), pd = p_of(v, b), pdd = p_of(acc, b);
    const Mat34 l = L_matrix(p), ld = L_matrix(pd);
    // d(4 L^T J L a)/dp = 4 [P(J L a) - L^T J L(a)];  d(8 L(p')^T J L p')/dp = -8 L(p')^T J L(p').
    const Mat4 dq = 4.0 * (P_matrix(j * (l * pdd)) - l.transpose() * j * L_matrix(pdd)) -
                    8.0 * ld.transpose() * j * ld;
    // d(8 L(p')^T J L p')/dp' = 8 [P(J L p') + L(p')^T J L].
    const Mat4 dv = 8.0 * (P_matrix(j * (l * pd)) + ld.transpose() * j * l);
    const int o = 7 * b + 3;
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) {
        a.add(row0 + o + r, colq + o + c, dq(r, c));
        if (colv >= 0) a.add(row0 + o + r, colv + o + c, dv(r, c));
      }
  }
}

namespace {

// L(p) y and L(p)^T w without the 3 x 4 matrix: L(p) = [-e, e0 I - [e]x], e = p's vector part.
inline Vec3 L_times(const Vec4& p, const Vec4& y) {
  const Vec3 e = p.tail<3>(), yv = y.tail<3>();
  return p[0] * yv - e.cross(yv) - y[0] * e;
}
inline Vec4 Lt_times(const Vec4& p, const Vec3& w) {
  const Vec3 e = p.tail<3>();
  Vec4 r;
  r[0] = -e.dot(w);
  r.tail<3>() = p[0] * w + e.cross(w);
  return r;
}

}  // namespace

void inertia_derivatives_times(const System& sys, const double* q, const double* v, const double* acc, int row0,
                               int colq, int colv, int count, const double* const* x, double* const* out) {
  for (int b = 0; b < sys.num_bodies(); ++b) {
    const Mat3& j = sys.bodies[b].inertia;
    const int o = 7 * b + 3;
    const Vec4 p = p_of(q, b), pd = p_of(v, b), pdd = p_of(acc, b);
    const Vec3 jla = j * L_times(p, pdd), jlpd = j * L_times(p, pd);
    for (int i = 0; i < count; ++i) {
      const Vec4 xq = Eigen::Map<const Vec4>(x[i] + colq + o), xv = Eigen::Map<const Vec4>(x[i] + colv + o);
      // As assemble_inertia_derivatives' blocks times (xq, xv), with P(w) x = L(x)^T w.
      const Vec4 r = 4.0 * (Lt_times(xq, jla) - Lt_times(p, j * L_times(pdd, xq))) -
                     8.0 * Lt_times(pd, j * L_times(pd, xq)) +
                     8.0 * (Lt_times(xv, jlpd) + Lt_times(pd, j * L_times(p, xv)));
      Eigen::Map<Vec4>(out[i] + row0 + o) += r;
    }
  }
}

namespace {

// Force k's local Jacobians (dQ/dpos, dQ/dvel) and, for a load with expression components, the
// chain through the components to the bodies they read (dQ/d(component), the components'
// derivatives in `in`).
struct ForceDerivatives {
  Mat14 dx, dv;
  Mat14x3 dqin;
  LoadInput in;
};

void force_derivatives(const System& sys, size_t k, const std::vector<char>& modes, const double* q,
                       const double* v, double t, const CoordinateTurns* turns, ForceDerivatives& d) {
  const Force& f = sys.forces[k];
  Vec14 ql = Vec14::Zero();
  d.dx.setZero();
  d.dv.setZero();
  d.in = load_input(sys, f, modes, q, v, t, f.has_expression(), turns);  // a joint spring's turns
  if (!f.has_expression()) {
    force_eval(f, gather(q, f.bi, f.bj), gather(v, f.bi, f.bj), t, modes[k], ql, &d.dx, &d.dv, &d.in);
  } else {
    d.dqin.setZero();
    force_eval(f, gather(q, f.bi, f.bj), gather(v, f.bi, f.bj), t, modes[k], ql, &d.dx, &d.dv, &d.in, &d.dqin);
  }
}

// The chain's entry of local row l and read body slot (7 r + m): d(Q_l)/d(q), d(Q_l)/d(v).
inline void chain_entry(const ForceDerivatives& d, int l, int slot, double& wq, double& wv) {
  wq = wv = 0;
  for (int c = 0; c < 3; ++c) {
    wq += d.dqin(l, c) * d.in.dq[c][slot];
    wv += d.dqin(l, c) * d.in.dv[c][slot];
  }
}

}  // namespace

void assemble_force_derivatives(const System& sys, const std::vector<char>& modes,
                                const double* q, const double* v, double t, int row0, int colq,
                                int colv, SparseAssembler& a, const CoordinateTurns* turns) {
  ForceDerivatives d;
  for (size_t k = 0; k < sys.forces.size(); ++k) {
    const Force& f = sys.forces[k];
    force_derivatives(sys, k, modes, q, v, t, turns, d);
    if (f.has_expression())
      for (size_t r = 0; r < f.reads.size(); ++r)
        for (int m = 0; m < 7; ++m) {
          const int col = 7 * f.reads[r] + m, slot = 7 * static_cast<int>(r) + m;
          for (int l = 0; l < 14; ++l) {
            const int g = global_index(f.bi, f.bj, l);
            if (g < 0) continue;
            double wq, wv;
            chain_entry(d, l, slot, wq, wv);
            a.add(row0 + g, colq + col, -wq);
            if (colv >= 0) a.add(row0 + g, colv + col, -wv);
          }
        }
    add_local_block(f.bi, f.bj, -d.dx, row0, colq, true, a);
    if (colv >= 0) add_local_block(f.bi, f.bj, -d.dv, row0, colv, true, a);
  }
}

void force_derivatives_times(const System& sys, const std::vector<char>& modes, const double* q, const double* v,
                             double t, int row0, int colq, int colv, int count, const double* const* x,
                             double* const* out, const CoordinateTurns* turns) {
  ForceDerivatives d;
  for (size_t k = 0; k < sys.forces.size(); ++k) {
    const Force& f = sys.forces[k];
    force_derivatives(sys, k, modes, q, v, t, turns, d);
    for (int i = 0; i < count; ++i) {
      // The local blocks times the local x (ground's entries zero), scattered to the bodies' rows.
      Vec14 r = d.dx * gather_local(x[i] + colq, f.bi, f.bj);
      if (colv >= 0) r += d.dv * gather_local(x[i] + colv, f.bi, f.bj);
      for (int l = 0; l < 14; ++l) {
        const int g = global_index(f.bi, f.bj, l);
        if (g < 0) continue;
        double sum = r[l];
        if (f.has_expression())
          for (size_t rd = 0; rd < f.reads.size(); ++rd)
            for (int m = 0; m < 7; ++m) {
              const int col = 7 * f.reads[rd] + m;
              double wq, wv;
              chain_entry(d, l, 7 * static_cast<int>(rd) + m, wq, wv);
              sum += wq * x[i][colq + col] + (colv >= 0 ? wv * x[i][colv + col] : 0.0);
            }
        out[i][row0 + g] -= sum;
      }
    }
  }
}

// The local columns (bit l, 0..13) that row r of a constraint can make non-zero: orientation-only
// equations (norm, dot-1, rotation coordinates) do not depend on r; row k of a point constraint
// depends on r only through r_k; ground's columns are left out. Leaving the structural zeros out
// of the pattern shrinks the sparse LU; one mask per row keeps the test out of the entry loop.
static unsigned structural_columns(const Constraint& c, int r) {
  constexpr unsigned kBoth = 1u | 1u << 7, kRotations = 0x78u * kBoth;  // local 3..6 of each body
  unsigned translations = 0x7u * kBoth, rotations = kRotations;
  switch (c.type) {
    case Constraint::Type::kNorm: translations = 0, rotations = 0x78u; break;  // its own body only
    case Constraint::Type::kDot1:
    case Constraint::Type::kOrientation: translations = 0; break;
    case Constraint::Type::kCoordinate: translations = c.coord.rotation ? 0 : translations; break;
    case Constraint::Type::kPoint: {
      int comp = 0;
      for (int k = 0, row = 0; k < 3; ++k)
        if ((c.mask & (1 << k)) && row++ == r) comp = k;
      translations = kBoth << comp;
      break;
    }
    default: break;
  }
  unsigned m = translations | rotations;
  if (c.bi < 0) m &= ~0x7Fu;
  if (c.bj < 0) m &= ~(0x7Fu << 7);
  return m;
}

void assemble_constraint_jacobian(const System& sys, const std::vector<int>& off,
                                  const double* q, double scale, int row0, int col0, int row0t,
                                  int col0t, SparseAssembler& a) {
  Row14 rows[3];
  for (size_t k = 0; k < sys.constraints.size(); ++k) {
    const Constraint& c = sys.constraints[k];
    constraint_jacobian(c, gather(q, c.bi, c.bj), rows);
    for (int r = 0; r < c.rows(); ++r) {
      const int row = off[k] + r;
      for (unsigned m = structural_columns(c, r); m; m &= m - 1) {
        const int l = __builtin_ctz(m), g = global_index(c.bi, c.bj, l);
        if (row0 >= 0) a.add(row0 + row, col0 + g, scale * rows[r](l));
        if (row0t >= 0) a.add(row0t + g, col0t + row, rows[r](l));
      }
    }
  }
}

ConstraintRowsPattern constraint_rows_pattern(const System& sys) {
  ConstraintRowsPattern p;
  p.rowptr.push_back(0);
  for (size_t k = 0; k < sys.constraints.size(); ++k) {
    const Constraint& c = sys.constraints[k];
    for (int r = 0; r < c.rows(); ++r) {
      for (unsigned m = structural_columns(c, r); m; m &= m - 1) {
        const int l = __builtin_ctz(m), g = global_index(c.bi, c.bj, l);
        if (g < 0) continue;
        p.col.push_back(g);
        p.local.push_back(static_cast<unsigned char>(l));
      }
      p.source.push_back(static_cast<int>(3 * k) + r);
      p.rowptr.push_back(static_cast<int>(p.col.size()));
    }
  }
  return p;
}

void add_constraint_forces(const ConstraintRowsPattern& p, const std::vector<Row14>& rows, const double* lambda,
                           double* out) {
  const int n = static_cast<int>(p.source.size());
  for (int i = 0; i < n; ++i) {
    const double* row = rows[p.source[i]].data();
    const double lam = lambda[i];
    for (int e = p.rowptr[i]; e < p.rowptr[i + 1]; ++e) out[p.col[e]] += row[p.local[e]] * lam;
  }
}

void constraint_rows_products(const ConstraintRowsPattern& p, const std::vector<Row14>& rows, const double* a,
                              const double* lambda, double* out_q, double* out_c) {
  const int n = static_cast<int>(p.source.size());
  for (int i = 0; i < n; ++i) {
    const double* row = rows[p.source[i]].data();
    double s = 0;
    for (int e = p.rowptr[i]; e < p.rowptr[i + 1]; ++e) {
      const double v = row[p.local[e]];
      out_q[p.col[e]] += v * lambda[i];
      s += v * a[p.col[e]];
    }
    out_c[i] = s;
  }
}

void assemble_constraint_hessian(const System& sys, const std::vector<int>& off, const double* q,
                                 const double* lambda, int row0, int col0, SparseAssembler& a) {
  for (size_t k = 0; k < sys.constraints.size(); ++k) {
    const Constraint& c = sys.constraints[k];
    Mat14 h = Mat14::Zero();
    constraint_hessian(c, gather(q, c.bi, c.bj), lambda + off[k], h);
    add_local_block(c.bi, c.bj, h, row0, col0, constraint_hessian_touches_r(c), a);
  }
}

}  // namespace mbdae
