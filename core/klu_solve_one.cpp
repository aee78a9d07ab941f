#include "core/klu_solve_one.h"

namespace mbdae {
namespace {

// KLU's packed column k of a block's L or U: its row indices (int), then, aligned to a double,
// its values (KLU's GET_POINTER).
struct PackedColumn {
  const int* rows;
  const double* values;
  int size;
};

inline PackedColumn column(const double* lu, const int* start, const int* length, int k) {
  const double* p = lu + start[k];
  const int size = length[k];
  return {reinterpret_cast<const int*>(p), p + (sizeof(int) * size + sizeof(double) - 1) / sizeof(double), size};
}

// X[rows[p]] -= values[p] * x for a column, four entries at a time (each row appears once in a
// column, so the order within it does not change any result).
inline void subtract_column(double* __restrict X, const PackedColumn& c, double x) {
  const int* __restrict rows = c.rows;
  const double* __restrict values = c.values;
  int p = 0;
  for (; p + 4 <= c.size; p += 4) {
    const double a0 = values[p] * x, a1 = values[p + 1] * x, a2 = values[p + 2] * x, a3 = values[p + 3] * x;
    X[rows[p]] -= a0;
    X[rows[p + 1]] -= a1;
    X[rows[p + 2]] -= a2;
    X[rows[p + 3]] -= a3;
  }
  for (; p < c.size; ++p) X[rows[p]] -= values[p] * x;
}

// L U x = x for one diagonal block of size nk (L unit lower, U's diagonal apart).
void solve_block(const klu_numeric& N, int block, int k1, int nk, double* X) {
  const double* lu = static_cast<const double*>(N.LUbx[block]);
  const double* udiag = static_cast<const double*>(N.Udiag) + k1;
  for (int k = 0; k < nk; ++k) subtract_column(X, column(lu, N.Lip + k1, N.Llen + k1, k), X[k]);
  for (int k = nk - 1; k >= 0; --k) {
    const double x = X[k] / udiag[k];
    X[k] = x;
    subtract_column(X, column(lu, N.Uip + k1, N.Ulen + k1, k), x);
  }
}

}  // namespace

void klu_solve_one(const klu_symbolic& S, const klu_numeric& N, double* b) {
  const int n = S.n;
  double* X = static_cast<double*>(N.Xwork);
  // X = P (R \ b): the gather, then the divisions in a loop of their own (it vectorizes; IEEE
  // division rounds each entry alike in either form).
  for (int k = 0; k < n; ++k) X[k] = b[N.Pnum[k]];
  if (const double* rs = N.Rs)
    for (int k = 0; k < n; ++k) X[k] /= rs[k];
  const double* udiag = static_cast<const double*>(N.Udiag);
  const double* off = static_cast<const double*>(N.Offx);
  for (int block = S.nblocks - 1; block >= 0; --block) {
    const int k1 = S.R[block], k2 = S.R[block + 1];
    if (k2 - k1 == 1)
      X[k1] /= udiag[k1];
    else
      solve_block(N, block, k1, k2 - k1, X + k1);
    if (block == 0) break;
    // The off-diagonal blocks' back substitution.
    for (int k = k1; k < k2; ++k) {
      const double x = X[k];
      for (int p = N.Offp[k]; p < N.Offp[k + 1]; ++p) X[N.Offi[p]] -= off[p] * x;
    }
  }
  for (int k = 0; k < n; ++k) b[S.Q[k]] = X[k];
}

}  // namespace mbdae
