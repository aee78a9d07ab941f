// Reference functions for pendulum tests (formulation and engine verification tests):
// the exact period of a pendulum through the complete elliptic integral of the first kind,
// and zero crossings located on sampled output.
#pragma once

#include <cmath>
#include <vector>

namespace mbdae::testing {

// Arithmetic-geometric mean; quadratic convergence.
inline double agm(double a, double b) {
  for (int i = 0; i < 64 && std::fabs(a - b) > 1e-16 * a; ++i) {
    const double m = 0.5 * (a + b);
    b = std::sqrt(a * b);
    a = m;
  }
  return 0.5 * (a + b);
}

// Complete elliptic integral of the first kind, modulus k: K(k) = pi / (2 AGM(1, sqrt(1 - k^2))).
// A pendulum released at rest from theta0 has the period 4 sqrt(I / (m g d)) K(sin(theta0 / 2)).
inline double elliptic_k(double k) {
  return 3.14159265358979323846 / (2.0 * agm(1.0, std::sqrt(1.0 - k * k)));
}

// Times where u crosses zero downwards, from samples t_i, u_i, u'_i. On each bracketing interval
// the cubic Hermite interpolant (error O(h^4 u'''')) is solved by bisection.
inline std::vector<double> downward_crossings(const std::vector<double>& t, const std::vector<double>& u,
                                              const std::vector<double>& du) {
  std::vector<double> out;
  for (size_t i = 0; i + 1 < t.size(); ++i) {
    if (!(u[i] > 0 && u[i + 1] <= 0)) continue;
    const double h = t[i + 1] - t[i];
    auto p = [&](double s) {
      const double s2 = s * s, s3 = s2 * s;
      return (2 * s3 - 3 * s2 + 1) * u[i] + (s3 - 2 * s2 + s) * h * du[i] +
             (-2 * s3 + 3 * s2) * u[i + 1] + (s3 - s2) * h * du[i + 1];
    };
    double lo = 0, hi = 1;
    for (int k = 0; k < 80; ++k) {
      const double mid = 0.5 * (lo + hi);
      (p(mid) > 0 ? lo : hi) = mid;
    }
    out.push_back(t[i] + 0.5 * (lo + hi) * h);
  }
  return out;
}

}  // namespace mbdae::testing
