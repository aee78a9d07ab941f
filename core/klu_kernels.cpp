#include "core/klu_kernels.h"

#include <cmath>

namespace mbdae {
namespace {

// KLU's packed column k of a block's L or U: its row indices (int), then, aligned to a double,
// its values (KLU's GET_POINTER).
struct PackedColumn {
  const int* rows;
  double* values;
  int size;
};

inline PackedColumn column(double* lu, const int* start, const int* length, int k) {
  double* p = lu + start[k];
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
  double* lu = static_cast<double*>(N.LUbx[block]);
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

namespace {

// The same for NR right-hand sides interleaved in X (X[NR k + r], as klu_solve keeps them): each
// factor entry's row and value are read once for all of them, the NR updates in pairs (GCC's
// vector extension: the same IEEE operations per entry as the scalar loop, so bit for bit).
typedef double Pair __attribute__((vector_size(16)));

inline Pair load_pair(const double* p) {
  Pair v;
  __builtin_memcpy(&v, p, sizeof v);
  return v;
}
inline void store_pair(double* p, Pair v) { __builtin_memcpy(p, &v, sizeof v); }

template <int NR>
inline void subtract_column_many(double* __restrict X, const PackedColumn& c, const double* x) {
  const int* __restrict rows = c.rows;
  const double* __restrict values = c.values;
  const Pair x01 = {x[0], x[1]};
  const Pair x23 = {NR > 2 ? x[2] : 0.0, NR > 3 ? x[3] : 0.0};
  for (int p = 0; p < c.size; ++p) {
    double* xr = X + NR * rows[p];
    const double v = values[p];
    const Pair vv = {v, v};
    store_pair(xr, load_pair(xr) - vv * x01);
    if constexpr (NR == 4) store_pair(xr + 2, load_pair(xr + 2) - vv * x23);
    if constexpr (NR == 3) xr[2] -= v * x[2];
  }
}

template <int NR>
void solve_block_many(const klu_numeric& N, int block, int k1, int nk, double* X) {
  double* lu = static_cast<double*>(N.LUbx[block]);
  const double* udiag = static_cast<const double*>(N.Udiag) + k1;
  for (int k = 0; k < nk; ++k) {
    double x[NR];
    for (int r = 0; r < NR; ++r) x[r] = X[NR * k + r];
    subtract_column_many<NR>(X, column(lu, N.Lip + k1, N.Llen + k1, k), x);
  }
  for (int k = nk - 1; k >= 0; --k) {
    double x[NR];
    for (int r = 0; r < NR; ++r) x[r] = X[NR * k + r] = X[NR * k + r] / udiag[k];
    subtract_column_many<NR>(X, column(lu, N.Uip + k1, N.Ulen + k1, k), x);
  }
}

// NB <= NR right-hand sides in NR lanes (the lanes beyond NB zero: three right-hand sides are
// cheaper in two pairs than in a pair and a single).
template <int NR, int NB = NR>
void solve_many(const klu_symbolic& S, const klu_numeric& N, double* const* b) {
  const int n = S.n;
  double* X = static_cast<double*>(N.Xwork);
  for (int k = 0; k < n; ++k)
    for (int r = 0; r < NR; ++r) X[NR * k + r] = r < NB ? b[r][N.Pnum[k]] : 0.0;
  if (const double* rs = N.Rs)
    for (int k = 0; k < n; ++k)
      for (int r = 0; r < NR; ++r) X[NR * k + r] /= rs[k];
  const double* udiag = static_cast<const double*>(N.Udiag);
  const double* off = static_cast<const double*>(N.Offx);
  for (int block = S.nblocks - 1; block >= 0; --block) {
    const int k1 = S.R[block], k2 = S.R[block + 1];
    if (k2 - k1 == 1)
      for (int r = 0; r < NR; ++r) X[NR * k1 + r] /= udiag[k1];
    else
      solve_block_many<NR>(N, block, k1, k2 - k1, X + NR * k1);
    if (block == 0) break;
    for (int k = k1; k < k2; ++k)
      for (int p = N.Offp[k]; p < N.Offp[k + 1]; ++p)
        for (int r = 0; r < NR; ++r) X[NR * N.Offi[p] + r] -= off[p] * X[NR * k + r];
  }
  for (int k = 0; k < n; ++k)
    for (int r = 0; r < NB; ++r) b[r][S.Q[k]] = X[NR * k + r];
}

}  // namespace

void klu_solve_many(const klu_symbolic& S, const klu_numeric& N, double* const* b, int nrhs) {
  for (int first = 0; first < nrhs;) {
    const int chunk = nrhs - first >= 4 ? 4 : nrhs - first;
    switch (chunk) {
      case 4: solve_many<4>(S, N, b + first); break;
      case 3: solve_many<4, 3>(S, N, b + first); break;
      case 2: solve_many<2>(S, N, b + first); break;
      default: klu_solve_one(S, N, b[first]);
    }
    first += chunk;
  }
}

namespace {

// KLU_scale's row scale: the largest |a| (scale 2 and up) or the sum of |a| (scale 1) of each
// row, 1 for an empty row; indexed by the original row.
void row_scale(int n, const int* Ap, const int* Ai, const double* Ax, int scale, double* Rs) {
  for (int row = 0; row < n; ++row) Rs[row] = 0;
  for (int col = 0; col < n; ++col)
    for (int p = Ap[col]; p < Ap[col + 1]; ++p) {
      const double a = std::fabs(Ax[p]);
      double& r = Rs[Ai[p]];
      if (scale == 1) r += a;
      else r = r > a ? r : a;
    }
  for (int row = 0; row < n; ++row)
    if (Rs[row] == 0.0) Rs[row] = 1.0;
}

// A's column of pivot k (the block from k1), divided by the row scale: its entries in the block
// into X (rows counted from k1), those in earlier blocks to Offx, in KLU's order.
void scatter_column(const int* Ap, const int* Ai, const double* Ax, const klu_symbolic& S, klu_numeric& N,
                    const double* Rs, int k1, int k, double* X, int& poff) {
  double* Offx = static_cast<double*>(N.Offx);
  const int oldcol = S.Q[k + k1];
  for (int p = Ap[oldcol]; p < Ap[oldcol + 1]; ++p) {
    const int oldrow = Ai[p], newrow = N.Pinv[oldrow] - k1;
    if (newrow < 0 && poff < S.nzoff) Offx[poff++] = Ax[p] / Rs[oldrow];
    else X[newrow] = Ax[p] / Rs[oldrow];
  }
}

// Column k of a block: A's column scattered into X, U's column by the left-looking update, L's
// column divided by the pivot. False at a zero pivot.
bool factor_column(const int* Ap, const int* Ai, const double* Ax, const klu_symbolic& S, klu_numeric& N,
                   const double* Rs, int block, int k, double* X, int& poff) {
  const int k1 = S.R[block];
  double* lu = static_cast<double*>(N.LUbx[block]);
  scatter_column(Ap, Ai, Ax, S, N, Rs, k1, k, X, poff);
  const PackedColumn u = column(lu, N.Uip + k1, N.Ulen + k1, k);
  for (int up = 0; up < u.size; ++up) {
    const int j = u.rows[up];
    const double ujk = X[j];
    X[j] = 0;
    u.values[up] = ujk;
    subtract_column(X, column(lu, N.Lip + k1, N.Llen + k1, j), ujk);
  }
  const double ukk = X[k];
  X[k] = 0;
  if (ukk == 0) return false;
  static_cast<double*>(N.Udiag)[k + k1] = ukk;
  const PackedColumn l = column(lu, N.Lip + k1, N.Llen + k1, k);
  for (int p = 0; p < l.size; ++p) {
    const int i = l.rows[p];
    l.values[p] = X[i] / ukk;
    X[i] = 0;
  }
  return true;
}

}  // namespace

bool klu_refactor_scaled(int* colptr, int* rowind, double* values, klu_symbolic& S, klu_numeric& N,
                         klu_common& common) {
  if (common.scale <= 0 || N.Rs == nullptr || !common.halt_if_singular)
    return klu_refactor(colptr, rowind, values, &S, &N, &common) != 0;
  common.status = KLU_OK;
  common.numerical_rank = -1;
  common.singular_col = -1;
  const int n = S.n;
  double* Rs = N.Rs;
  double* X = static_cast<double*>(N.Xwork);
  row_scale(n, colptr, rowind, values, common.scale, Rs);
  for (int k = 0; k < S.maxblock; ++k) X[k] = 0;
  int poff = 0;
  for (int block = 0; block < S.nblocks; ++block) {
    const int k1 = S.R[block], k2 = S.R[block + 1];
    if (k2 - k1 == 1) {  // a singleton: its entry is U's diagonal
      scatter_column(colptr, rowind, values, S, N, Rs, k1, 0, X, poff);
      static_cast<double*>(N.Udiag)[k1] = X[0];
      X[0] = 0;
      continue;
    }
    for (int k = 0; k < k2 - k1; ++k)
      if (!factor_column(colptr, rowind, values, S, N, Rs, block, k, X, poff)) {
        common.status = KLU_SINGULAR;
        common.numerical_rank = k + k1;
        common.singular_col = S.Q[k + k1];
        return false;
      }
  }
  // The row scale in the pivot order, as klu_solve reads it.
  for (int k = 0; k < n; ++k) X[k] = Rs[N.Pnum[k]];
  for (int k = 0; k < n; ++k) Rs[k] = X[k];
  return true;
}

}  // namespace mbdae
