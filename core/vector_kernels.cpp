#include "core/vector_kernels.h"

#include <nvector/nvector_serial.h>

#include <cmath>

namespace mbdae {

// SUNDIALS 6.4.1's serial kernels (src/nvector/serial/nvector_serial.c, BSD-3-Clause, Copyright
// (c) 2002-2022 Lawrence Livermore National Security and Southern Methodist University), compiled
// with this build's optimization: Debian's libsundials is built without it (-O0: about 20
// instructions per element, docs/performance.md). The same special cases and the same arithmetic
// per element in the same order (no contraction, no reassociation), so bit for bit the same.
namespace {

inline sunindextype length(N_Vector v) { return NV_LENGTH_S(v); }
inline double* at(N_Vector v) { return NV_DATA_S(v); }

void axpy(double a, N_Vector x, N_Vector y) {  // y <- a x + y
  const sunindextype n = length(x);
  const double* xd = at(x);
  double* yd = at(y);
  if (a == 1.0) {
    for (sunindextype i = 0; i < n; ++i) yd[i] += xd[i];
  } else if (a == -1.0) {
    for (sunindextype i = 0; i < n; ++i) yd[i] -= xd[i];
  } else {
    for (sunindextype i = 0; i < n; ++i) yd[i] += a * xd[i];
  }
}

// z = f(x[i], y[i]) element by element.
template <class F>
void each(N_Vector x, N_Vector y, N_Vector z, F f) {
  const sunindextype n = length(x);
  const double *xd = at(x), *yd = at(y);
  double* zd = at(z);
  for (sunindextype i = 0; i < n; ++i) zd[i] = f(xd[i], yd[i]);
}

void linear_sum(double a, N_Vector x, double b, N_Vector y, N_Vector z) {
  if (b == 1.0 && z == y) return axpy(a, x, y);
  if (a == 1.0 && z == x) return axpy(b, y, x);
  if (a == 1.0 && b == 1.0) return each(x, y, z, [](double u, double w) { return u + w; });
  if ((a == 1.0 && b == -1.0) || (a == -1.0 && b == 1.0)) {
    const bool t = a == 1.0;  // z = x - y, or y - x
    return each(t ? x : y, t ? y : x, z, [](double u, double w) { return u - w; });
  }
  if (a == 1.0 || b == 1.0) {
    const bool t = a == 1.0;  // z = c v1 + v2
    const double c = t ? b : a;
    return each(t ? y : x, t ? x : y, z, [c](double u, double w) { return (c * u) + w; });
  }
  if (a == -1.0 || b == -1.0) {
    const bool t = a == -1.0;  // z = c v1 - v2
    const double c = t ? b : a;
    return each(t ? y : x, t ? x : y, z, [c](double u, double w) { return (c * u) - w; });
  }
  if (a == b) return each(x, y, z, [a](double u, double w) { return a * (u + w); });
  if (a == -b) return each(x, y, z, [a](double u, double w) { return a * (u - w); });
  each(x, y, z, [a, b](double u, double w) { return (a * u) + (b * w); });
}

void scale(double c, N_Vector x, N_Vector z) {
  const sunindextype n = length(x);
  const double* xd = at(x);
  double* zd = at(z);
  if (z == x) {
    for (sunindextype i = 0; i < n; ++i) zd[i] *= c;
  } else if (c == 1.0) {
    for (sunindextype i = 0; i < n; ++i) zd[i] = xd[i];
  } else if (c == -1.0) {
    for (sunindextype i = 0; i < n; ++i) zd[i] = -xd[i];
  } else {
    for (sunindextype i = 0; i < n; ++i) zd[i] = c * xd[i];
  }
}

void constant(double c, N_Vector z) {
  const sunindextype n = length(z);
  double* zd = at(z);
  for (sunindextype i = 0; i < n; ++i) zd[i] = c;
}

double weighted_square_sum(N_Vector x, N_Vector w) {
  const sunindextype n = length(x);
  const double *xd = at(x), *wd = at(w);
  double sum = 0.0;
  for (sunindextype i = 0; i < n; ++i) {
    const double p = xd[i] * wd[i];
    sum += p * p;
  }
  return sum;
}

double weighted_square_sum_mask(N_Vector x, N_Vector w, N_Vector id) {
  const sunindextype n = length(x);
  const double *xd = at(x), *wd = at(w), *idd = at(id);
  double sum = 0.0;
  for (sunindextype i = 0; i < n; ++i) {
    if (idd[i] > 0.0) {
      const double p = xd[i] * wd[i];
      sum += p * p;
    }
  }
  return sum;
}

double root_mean(double sum, N_Vector x) { return sum <= 0.0 ? 0.0 : std::sqrt(sum / length(x)); }
double wrms_norm(N_Vector x, N_Vector w) { return root_mean(weighted_square_sum(x, w), x); }
double wrms_norm_mask(N_Vector x, N_Vector w, N_Vector id) {
  return root_mean(weighted_square_sum_mask(x, w, id), x);
}

}  // namespace

// SUNDIALS' sequence without a fused operation: z = c0 X(0) (N_VScale), then z += c_i X(i)
// (N_VLinearSum with b = 1 and y = z: axpy), X(i) the i-th vector. Kept for the aliasing it
// allows (z one of X[1..]) and for more than 7 vectors (IDA passes at most 6).
template <class Vectors>
static void sundials_sequence(int nvec, const double* c, Vectors X, N_Vector z) {
  scale(c[0], X(0), z);
  for (int i = 1; i < nvec; ++i) linear_sum(c[i], X(i), 1.0, z, z);
}

// z = sum_i c[i] X[i] for N vectors known at compile time: the sum over i unrolled, so that the
// loop over the elements is a plain (vectorizable) one. Per element the same products and sums,
// in the same order, as sundials_sequence (c * x is exact for c = +-1, where SUNDIALS copies,
// negates or adds instead of multiplying).
template <int N>
static int combination(const double* c, N_Vector* X, N_Vector z) {
  const sunindextype n = NV_LENGTH_S(z);
  double* zd = NV_DATA_S(z);
  const double* x[N];
  for (int i = 0; i < N; ++i) x[i] = NV_DATA_S(X[i]);
  for (sunindextype k = 0; k < n; ++k) {
    double s = c[0] * x[0][k];
    for (int i = 1; i < N; ++i) s += c[i] * x[i][k];
    zd[k] = s;
  }
  return 0;
}

int fused_linear_combination(int nvec, double* c, N_Vector* X, N_Vector z) {
  if (nvec < 1) return -1;
  // z one of X[1..]: SUNDIALS' sequence overwrites that input (z = c0 X0) before it adds it.
  bool aliased = false;
  for (int i = 1; i < nvec; ++i) aliased = aliased || X[i] == z;
  if (aliased || nvec > 7) {
    sundials_sequence(nvec, c, [X](int i) { return X[i]; }, z);
    return 0;
  }
  switch (nvec) {
    case 1: return combination<1>(c, X, z);
    case 2: return combination<2>(c, X, z);
    case 3: return combination<3>(c, X, z);
    case 4: return combination<4>(c, X, z);
    case 5: return combination<5>(c, X, z);
    case 6: return combination<6>(c, X, z);  // IDA's history holds at most 6 vectors
    default: return combination<7>(c, X, z);
  }
}

// Z[i] = sum_j c[j] X[j][i] for each i (IDAS's sensitivities: the predictor and the
// interpolation of every sensitivity vector): the fused combination per vector, as SUNDIALS'
// N_VLinearCombinationVectorArray does with it, without that function's malloc and free of its
// array of vectors at every call.
int linear_combination_vector_array(int nvec, int nsum, double* c, N_Vector** X, N_Vector* Z) {
  constexpr int kTerms = 16;  // IDAS passes at most its history's 6
  N_Vector Y[kTerms];
  for (int i = 0; i < nvec; ++i) {
    if (nsum > kTerms) {
      sundials_sequence(nsum, c, [X, i](int j) { return X[j][i]; }, Z[i]);
      continue;
    }
    for (int j = 0; j < nsum; ++j) Y[j] = X[j][i];
    if (const int flag = fused_linear_combination(nsum, c, Y, Z[i]); flag != 0) return flag;
  }
  return 0;
}

void use_vector_kernels(N_Vector v) {
  N_Vector_Ops o = v->ops;
  o->nvlinearcombination = fused_linear_combination;
  o->nvlinearcombinationvectorarray = linear_combination_vector_array;
  o->nvlinearsum = linear_sum;
  o->nvscale = scale;
  o->nvconst = constant;
  o->nvwrmsnorm = wrms_norm;
  o->nvwrmsnormmask = wrms_norm_mask;
  o->nvwsqrsumlocal = weighted_square_sum;
  o->nvwsqrsummasklocal = weighted_square_sum_mask;
}

}  // namespace mbdae
