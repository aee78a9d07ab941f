#include "core/klu_kernels.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <utility>
#include <vector>

namespace mbdae {
namespace {

struct Csc {
  int n = 0;
  std::vector<int> colptr, rowind;
  std::vector<double> values;
};

// Column-major dense to CSC, keeping the entries that are not zero.
Csc to_csc(const std::vector<double>& dense, int n) {
  Csc a;
  a.n = n;
  a.colptr.push_back(0);
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i)
      if (dense[j * n + i] != 0) {
        a.rowind.push_back(i);
        a.values.push_back(dense[j * n + i]);
      }
    a.colptr.push_back(static_cast<int>(a.rowind.size()));
  }
  return a;
}

// klu_solve and klu_solve_one on the same factorization and right-hand sides: equal bit for bit;
// klu_solve_many too.
// Returns the number of diagonal blocks KLU's analysis found.
int expect_same_solutions(Csc a, int scale, int btf, std::mt19937& rng) {
  klu_common common;
  klu_defaults(&common);
  common.scale = scale;
  common.btf = btf;
  klu_symbolic* s = klu_analyze(a.n, a.colptr.data(), a.rowind.data(), &common);
  EXPECT_NE(s, nullptr);
  klu_numeric* f = klu_factor(a.colptr.data(), a.rowind.data(), a.values.data(), s, &common);
  EXPECT_NE(f, nullptr);
  if (!s || !f) return 0;
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<double> b(a.n), x(a.n);
    for (double& v : b) v = u(rng) * std::pow(10.0, static_cast<int>(u(rng) * 2));
    x = b;
    EXPECT_TRUE(klu_solve(s, f, a.n, 1, b.data(), &common));
    klu_solve_one(*s, *f, x.data());
    EXPECT_EQ(std::memcmp(b.data(), x.data(), a.n * sizeof(double)), 0) << "trial " << trial;
  }
  // klu_solve_many on 1 to 9 right-hand sides (chunks of four, three, two and one): each equal
  // bit for bit to klu_solve_one on it.
  for (int nrhs = 1; nrhs <= 9; ++nrhs) {
    std::vector<std::vector<double>> many(nrhs, std::vector<double>(a.n)), one = many;
    std::vector<double*> ptrs;
    for (int r = 0; r < nrhs; ++r) {
      for (int i = 0; i < a.n; ++i) many[r][i] = one[r][i] = u(rng) * std::pow(10.0, static_cast<int>(u(rng) * 2));
      klu_solve_one(*s, *f, one[r].data());
      ptrs.push_back(many[r].data());
    }
    klu_solve_many(*s, *f, ptrs.data(), nrhs);
    for (int r = 0; r < nrhs; ++r)
      EXPECT_EQ(std::memcmp(many[r].data(), one[r].data(), a.n * sizeof(double)), 0) << nrhs << " right-hand sides, " << r;
  }
  const int blocks = s->nblocks;
  klu_free_numeric(&f, &common);
  klu_free_symbolic(&s, &common);
  return blocks;
}

// klu_refactor and klu_refactor_scaled of new values on the same pattern, each on its own
// factorization of the old values: the factors, the off-diagonal blocks and the row scale equal
// bit for bit. A zero pivot: both refuse.
bool expect_same_refactorization(Csc a, const std::vector<double>& new_values, int btf) {
  klu_common common;
  klu_defaults(&common);
  common.btf = btf;
  klu_symbolic* s = klu_analyze(a.n, a.colptr.data(), a.rowind.data(), &common);
  EXPECT_NE(s, nullptr);
  klu_numeric* theirs = s ? klu_factor(a.colptr.data(), a.rowind.data(), a.values.data(), s, &common) : nullptr;
  klu_numeric* ours = s ? klu_factor(a.colptr.data(), a.rowind.data(), a.values.data(), s, &common) : nullptr;
  EXPECT_TRUE(theirs && ours);
  if (!theirs || !ours) return false;
  std::vector<double> v = new_values;
  const bool ok_theirs = klu_refactor(a.colptr.data(), a.rowind.data(), v.data(), s, theirs, &common);
  const bool ok_ours = klu_refactor_scaled(a.colptr.data(), a.rowind.data(), v.data(), *s, *ours, common);
  EXPECT_EQ(ok_theirs, ok_ours);
  if (ok_theirs && ok_ours) {
    const auto same = [](const void* x, const void* y, size_t bytes) { return std::memcmp(x, y, bytes) == 0; };
    EXPECT_TRUE(same(theirs->Udiag, ours->Udiag, a.n * sizeof(double)));
    EXPECT_TRUE(same(theirs->Rs, ours->Rs, a.n * sizeof(double)));
    EXPECT_TRUE(same(theirs->Offx, ours->Offx, theirs->nzoff * sizeof(double)));
    // Every column of every block's L and U (their values follow the column's row indices,
    // aligned to a double: KLU's packing; the padding between is not compared).
    for (int b = 0; b < s->nblocks; ++b)
      for (int k = s->R[b]; k < s->R[b + 1] && s->R[b + 1] - s->R[b] > 1; ++k)
        for (auto [start, len] : {std::pair{theirs->Lip[k], theirs->Llen[k]}, std::pair{theirs->Uip[k], theirs->Ulen[k]}}) {
          const size_t skip = start + (sizeof(int) * len + sizeof(double) - 1) / sizeof(double);
          EXPECT_TRUE(same(static_cast<double*>(theirs->LUbx[b]) + skip, static_cast<double*>(ours->LUbx[b]) + skip,
                           len * sizeof(double)))
              << "block " << b << " column " << k;
        }
    std::vector<double> b(a.n), x(a.n);
    for (int i = 0; i < a.n; ++i) b[i] = x[i] = std::sin(1.0 + i);
    EXPECT_TRUE(klu_solve(s, theirs, a.n, 1, b.data(), &common));
    klu_solve_one(*s, *ours, x.data());
    EXPECT_TRUE(same(b.data(), x.data(), a.n * sizeof(double))) << "the solve after the refactorization";
  }
  klu_free_numeric(&theirs, &common);
  klu_free_numeric(&ours, &common);
  klu_free_symbolic(&s, &common);
  return ok_theirs;
}

// New values on a's pattern: each entry moved by up to 30 % (the diagonal kept dominant).
std::vector<double> perturbed(const Csc& a, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.7, 1.3);
  std::vector<double> v = a.values;
  for (double& x : v) x *= u(rng);
  return v;
}

// A sparse matrix with a dominant diagonal and random couplings of mixed magnitudes.
std::vector<double> random_sparse(int n, double density, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0), p(0.0, 1.0);
  std::vector<double> a(n * n, 0.0);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      if (i == j) a[j * n + i] = 4.0 + u(rng);
      else if (p(rng) < density) a[j * n + i] = u(rng) * std::pow(10.0, static_cast<int>(3 * u(rng)));
  return a;
}

TEST(KluKernels, SolveIsKluSolveBitForBitWithAndWithoutRowScaling) {
  std::mt19937 rng(7);
  const Csc a = to_csc(random_sparse(80, 0.06, rng), 80);
  for (int scale : {2, 1, 0}) expect_same_solutions(a, scale, 1, rng);
}

TEST(KluKernels, RefactorizationIsKluRefactorBitForBit) {
  std::mt19937 rng(5);
  const Csc a = to_csc(random_sparse(80, 0.06, rng), 80);
  for (int btf : {1, 0}) expect_same_refactorization(a, perturbed(a, rng), btf);
  // An exactly zero pivot in the new values: the first column's only entry.
  Csc z = to_csc(random_sparse(30, 0.0, rng), 30);
  std::vector<double> v = z.values;
  v[0] = 0;
  EXPECT_FALSE(expect_same_refactorization(z, v, 0));
}

// Block upper triangular (BTF finds several blocks, singletons among them, and off-diagonal
// entries), and the same without BTF.
TEST(KluKernels, SolveAndRefactorizationAreKlusOnBlockTriangularMatrices) {
  std::mt19937 rng(11);
  const int n = 60;
  std::vector<double> d = random_sparse(n, 0.08, rng);
  const int cuts[] = {0, 7, 8, 20, 21, 22, 40, n};
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      int bi = 0, bj = 0;
      while (cuts[bi + 1] <= i) ++bi;
      while (cuts[bj + 1] <= j) ++bj;
      if (bi > bj) d[j * n + i] = 0;  // nothing below the diagonal blocks
    }
  const Csc a = to_csc(d, n);
  EXPECT_GE(expect_same_solutions(a, 2, 1, rng), 7);
  EXPECT_EQ(expect_same_solutions(a, 2, 0, rng), 1);
  for (int btf : {1, 0}) expect_same_refactorization(a, perturbed(a, rng), btf);
}

// A saddle-point matrix as a multibody Newton matrix has: [M G^T; G 0], zero diagonal in the
// constraint rows, so partial pivoting leaves the diagonal.
TEST(KluKernels, SolveAndRefactorizationAreKlusOnASaddlePointMatrix) {
  std::mt19937 rng(3);
  const int nq = 40, nc = 15, n = nq + nc;
  std::uniform_real_distribution<double> u(-1.0, 1.0), p(0.0, 1.0);
  std::vector<double> d(n * n, 0.0);
  for (int i = 0; i < nq; ++i) d[i * n + i] = 1.0 + p(rng);
  for (int r = 0; r < nc; ++r)
    for (int j = 0; j < nq; ++j)
      if (p(rng) < 0.15 || j == (3 * r) % nq) {
        const double g = u(rng);
        d[j * n + nq + r] = g;  // G
        d[(nq + r) * n + j] = g;  // G^T
      }
  const Csc a = to_csc(d, n);
  for (int btf : {1, 0}) {
    expect_same_solutions(a, 2, btf, rng);
    expect_same_refactorization(a, perturbed(a, rng), btf);
  }
}

}  // namespace
}  // namespace mbdae
