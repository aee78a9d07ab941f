#include "core/fused_vector.h"

#include <nvector/nvector_serial.h>

namespace mbdae {

// SUNDIALS' sequence without a fused operation: z = c0 X0 (N_VScale), then z += c_i X_i
// (N_VLinearSum with b = 1 and y = z: axpy). Kept for the aliasing it allows (z one of X[1..]).
static void sundials_sequence(int nvec, double* c, N_Vector* X, N_Vector z) {
  N_VScale_Serial(c[0], X[0], z);
  for (int i = 1; i < nvec; ++i) N_VLinearSum_Serial(c[i], X[i], 1.0, z, z);
}

int fused_linear_combination(int nvec, double* c, N_Vector* X, N_Vector z) {
  if (nvec < 1) return -1;
  for (int i = 1; i < nvec; ++i)
    if (X[i] == z) {
      sundials_sequence(nvec, c, X, z);
      return 0;
    }
  const sunindextype n = NV_LENGTH_S(z);
  double* zd = NV_DATA_S(z);
  const double* x0 = NV_DATA_S(X[0]);
  // Per element the same products and sums, in the same order, as sundials_sequence (c * x is
  // exact for c = +-1, where SUNDIALS copies, negates or adds instead of multiplying).
  switch (nvec) {
    case 1:
      for (sunindextype k = 0; k < n; ++k) zd[k] = c[0] * x0[k];
      return 0;
    case 2: {
      const double* x1 = NV_DATA_S(X[1]);
      for (sunindextype k = 0; k < n; ++k) zd[k] = c[0] * x0[k] + c[1] * x1[k];
      return 0;
    }
    default: {
      constexpr int kMax = 16;  // IDA's history holds at most 6 vectors
      if (nvec > kMax) {
        sundials_sequence(nvec, c, X, z);
        return 0;
      }
      const double* x[kMax];
      for (int i = 0; i < nvec; ++i) x[i] = NV_DATA_S(X[i]);
      for (sunindextype k = 0; k < n; ++k) {
        double s = c[0] * x0[k];
        for (int i = 1; i < nvec; ++i) s += c[i] * x[i][k];
        zd[k] = s;
      }
      return 0;
    }
  }
}

void use_fused_operations(N_Vector v) { v->ops->nvlinearcombination = fused_linear_combination; }

}  // namespace mbdae
