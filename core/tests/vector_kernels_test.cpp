// mbdae's vector kernels (core/vector_kernels.h) against SUNDIALS' own serial operations, bit for
// bit: the fused linear combination for 1 to 7 vectors, coefficients +-1 among them, z aliasing an
// input, and over arrays of vectors (IDAS's sensitivities); the linear sum for every special case of SUNDIALS' (coefficients 1, -1, equal, opposite,
// z aliasing x or y), scale, constant and the weighted norms.
#include "core/vector_kernels.h"

#include <gtest/gtest.h>
#include <nvector/nvector_serial.h>

#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <utility>
#include <vector>

namespace mbdae {
namespace {

struct Vectors {
  SUNContext ctx = nullptr;
  std::vector<N_Vector> v;
  Vectors(int count, int n) {
    SUNContext_Create(nullptr, &ctx);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1e3, 1e3);
    for (int i = 0; i < count; ++i) {
      v.push_back(N_VNew_Serial(n, ctx));
      for (int k = 0; k < n; ++k) NV_Ith_S(v.back(), k) = u(rng) * std::pow(10.0, (k % 9) - 4);
    }
  }
  ~Vectors() {
    for (N_Vector x : v) N_VDestroy(x);
    SUNContext_Free(&ctx);
  }
};

// N_VLinearCombination of a vector without the fused operation (N_VNew_Serial's default):
// SUNDIALS' N_VScale and N_VLinearSum sequence.
void reference(int nvec, double* c, N_Vector* X, N_Vector z) {
  ASSERT_EQ(z->ops->nvlinearcombination, nullptr);
  N_VLinearCombination(nvec, c, X, z);
}

bool same_bits(N_Vector a, N_Vector b) {
  return std::memcmp(NV_DATA_S(a), NV_DATA_S(b), NV_LENGTH_S(a) * sizeof(double)) == 0;
}

TEST(VectorKernels, LinearCombinationIsSundialsSequenceBitForBit) {
  const int n = 301;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  for (int nvec = 1; nvec <= 7; ++nvec) {
    Vectors in(nvec + 2, n);  // inputs, then two outputs (fused, reference)
    std::vector<double> c(nvec);
    for (int i = 0; i < nvec; ++i) c[i] = i == 1 ? 1.0 : i == 2 ? -1.0 : u(rng);
    N_Vector fused = in.v[nvec], ref = in.v[nvec + 1];
    fused_linear_combination(nvec, c.data(), in.v.data(), fused);
    reference(nvec, c.data(), in.v.data(), ref);
    EXPECT_TRUE(same_bits(fused, ref)) << nvec << " vectors";
  }
}

// IDAS's vector-array combination (its sensitivities): per vector as SUNDIALS' own generic
// N_VLinearCombinationVectorArray on vectors without any fused operation, for histories of 1 to
// 6 vectors and for more terms than the kernel's array holds (20).
TEST(VectorKernels, VectorArrayCombinationIsSundialsBitForBit) {
  const int n = 157, nvec = 3;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  for (int nsum : {1, 2, 3, 6, 20}) {
    Vectors in(nsum * nvec + 2 * nvec, n);
    std::vector<std::vector<N_Vector>> X(nsum);
    std::vector<N_Vector*> Xp(nsum);
    for (int j = 0; j < nsum; ++j) {
      for (int i = 0; i < nvec; ++i) X[j].push_back(in.v[j * nvec + i]);
      Xp[j] = X[j].data();
    }
    std::vector<N_Vector> ours(in.v.begin() + nsum * nvec, in.v.begin() + nsum * nvec + nvec);
    std::vector<N_Vector> theirs(in.v.begin() + nsum * nvec + nvec, in.v.end());
    std::vector<double> c(nsum);
    for (int j = 0; j < nsum; ++j) c[j] = j == 1 ? -1.0 : u(rng);
    ASSERT_EQ(theirs[0]->ops->nvlinearcombinationvectorarray, nullptr);
    ASSERT_EQ(theirs[0]->ops->nvlinearcombination, nullptr);
    N_VLinearCombinationVectorArray(nvec, nsum, c.data(), Xp.data(), theirs.data());
    EXPECT_EQ(linear_combination_vector_array(nvec, nsum, c.data(), Xp.data(), ours.data()), 0);
    for (int i = 0; i < nvec; ++i) EXPECT_TRUE(same_bits(ours[i], theirs[i])) << nsum << " terms, vector " << i;
  }
}

TEST(VectorKernels, LinearCombinationIntoOneOfItsInputs) {
  const int n = 57, nvec = 5;
  double c[nvec] = {0.3, -1.7, 1.0, 2.5, -0.25};
  for (int alias : {0, 2}) {
    Vectors a(nvec, n), b(nvec, n);  // same seed: equal contents
    fused_linear_combination(nvec, c, a.v.data(), a.v[alias]);
    reference(nvec, c, b.v.data(), b.v[alias]);
    EXPECT_TRUE(same_bits(a.v[alias], b.v[alias])) << "z = X[" << alias << "]";
  }
}

// Runs op on two equal sets of count vectors, one with mbdae's kernels and one with SUNDIALS'
// own, and compares every vector afterwards.
template <class Op>
void expect_same(int count, const char* what, Op op) {
  const int n = 211;
  Vectors a(count, n), b(count, n);  // same seed: equal contents
  for (N_Vector v : a.v) use_vector_kernels(v);
  ASSERT_EQ(b.v[0]->ops->nvlinearsum, &N_VLinearSum_Serial);
  const double ra = op(a.v), rb = op(b.v);
  EXPECT_EQ(std::memcmp(&ra, &rb, sizeof ra), 0) << what << ": " << ra << " against " << rb;
  for (int i = 0; i < count; ++i) EXPECT_TRUE(same_bits(a.v[i], b.v[i])) << what << ", vector " << i;
}

TEST(VectorKernels, SerialKernelsAreSundialsOwnBitForBit) {
  const double other = 0.7303, another = -2.917;
  const std::pair<double, double> coefficients[] = {
      {1, 1}, {1, -1}, {-1, 1}, {1, other}, {other, 1}, {-1, other}, {other, -1},
      {other, other}, {other, -other}, {other, another}, {0, other}, {other, 0}, {-1, -1}};
  for (auto [a, b] : coefficients) {
    const std::string ab = std::to_string(a) + ", " + std::to_string(b);
    expect_same(3, ("linear sum z = " + ab).c_str(), [=](std::vector<N_Vector>& v) {
      N_VLinearSum(a, v[0], b, v[1], v[2]);
      return 0.0;
    });
    expect_same(2, ("linear sum into y, " + ab).c_str(), [=](std::vector<N_Vector>& v) {
      N_VLinearSum(a, v[0], b, v[1], v[1]);
      return 0.0;
    });
    expect_same(2, ("linear sum into x, " + ab).c_str(), [=](std::vector<N_Vector>& v) {
      N_VLinearSum(a, v[0], b, v[1], v[0]);
      return 0.0;
    });
  }
  for (double c : {1.0, -1.0, other}) {
    expect_same(2, "scale", [=](std::vector<N_Vector>& v) {
      N_VScale(c, v[0], v[1]);
      return 0.0;
    });
    expect_same(1, "scale in place", [=](std::vector<N_Vector>& v) {
      N_VScale(c, v[0], v[0]);
      return 0.0;
    });
  }
  expect_same(1, "constant", [=](std::vector<N_Vector>& v) {
    N_VConst(other, v[0]);
    return 0.0;
  });
  expect_same(2, "weighted rms norm", [](std::vector<N_Vector>& v) { return N_VWrmsNorm(v[0], v[1]); });
  expect_same(2, "weighted square sum", [](std::vector<N_Vector>& v) { return N_VWSqrSumLocal(v[0], v[1]); });
  auto masked = [](std::vector<N_Vector>& v, bool local) {
    for (int k = 0; k < NV_LENGTH_S(v[2]); ++k) NV_Ith_S(v[2], k) = k % 3 == 0 ? 0.0 : 1.0;
    return local ? N_VWSqrSumMaskLocal(v[0], v[1], v[2]) : N_VWrmsNormMask(v[0], v[1], v[2]);
  };
  expect_same(3, "masked weighted rms norm", [&](std::vector<N_Vector>& v) { return masked(v, false); });
  expect_same(3, "masked weighted square sum", [&](std::vector<N_Vector>& v) { return masked(v, true); });
}

TEST(VectorKernels, ClonesInheritTheOperation) {
  Vectors in(1, 4);
  use_vector_kernels(in.v[0]);
  N_Vector clone = N_VClone(in.v[0]);
  EXPECT_EQ(clone->ops->nvlinearcombination, &fused_linear_combination);
  EXPECT_EQ(clone->ops->nvlinearcombinationvectorarray, &linear_combination_vector_array);
  EXPECT_EQ(clone->ops->nvlinearsum, in.v[0]->ops->nvlinearsum);
  EXPECT_NE(clone->ops->nvlinearsum, &N_VLinearSum_Serial);
  N_VDestroy(clone);
}

}  // namespace
}  // namespace mbdae
