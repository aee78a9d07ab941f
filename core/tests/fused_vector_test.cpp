// The fused linear combination (core/fused_vector.h) against SUNDIALS' own sequence without it:
// bit for bit, for 1 to 7 vectors, coefficients +-1 among them, and z aliasing an input.
#include "core/fused_vector.h"

#include <gtest/gtest.h>
#include <nvector/nvector_serial.h>

#include <cmath>
#include <cstring>
#include <random>
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

TEST(FusedVector, LinearCombinationIsSundialsSequenceBitForBit) {
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

TEST(FusedVector, LinearCombinationIntoOneOfItsInputs) {
  const int n = 57, nvec = 5;
  double c[nvec] = {0.3, -1.7, 1.0, 2.5, -0.25};
  for (int alias : {0, 2}) {
    Vectors a(nvec, n), b(nvec, n);  // same seed: equal contents
    fused_linear_combination(nvec, c, a.v.data(), a.v[alias]);
    reference(nvec, c, b.v.data(), b.v[alias]);
    EXPECT_TRUE(same_bits(a.v[alias], b.v[alias])) << "z = X[" << alias << "]";
  }
}

TEST(FusedVector, ClonesInheritTheOperation) {
  Vectors in(1, 4);
  use_fused_operations(in.v[0]);
  N_Vector clone = N_VClone(in.v[0]);
  EXPECT_EQ(clone->ops->nvlinearcombination, &fused_linear_combination);
  N_VDestroy(clone);
}

}  // namespace
}  // namespace mbdae
