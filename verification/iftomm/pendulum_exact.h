// The exact motion of IFToMM A01 (verification/iftomm/scenes/A01_simple_pendulum.yaml), a
// simple pendulum released at rest from the horizontal, from Jacobi's sn: the independent
// reference of iftomm_test and of the tolerance-promise tests (verification/studies).
#pragma once

#include <cmath>

namespace mbdae {

// Jacobi sn(u; k) and K(k) by the descending arithmetic-geometric mean (Abramowitz and Stegun
// 16.4.3 and 17.6): a_n, c_n of the AGM of (1, sqrt(1 - k^2)); phi_N = 2^N a_N u, then
// phi_(n-1) = (phi_n + asin(c_n / a_n sin(phi_n))) / 2; sn = sin(phi_0); K = pi / (2 a_N).
struct Agm {
  double a[40], c[40];
  int n = 0;
  explicit Agm(double k) {
    a[0] = 1;
    c[0] = k;
    double b = std::sqrt(1 - k * k);
    while (std::fabs(c[n]) > 1e-17 && n < 39) {
      a[n + 1] = 0.5 * (a[n] + b);
      c[n + 1] = 0.5 * (a[n] - b);
      b = std::sqrt(a[n] * b);
      ++n;
    }
  }
  double complete_k() const { return 3.14159265358979323846 / (2 * a[n]); }
  double sn(double u) const {
    double phi = std::ldexp(1.0, n) * a[n] * u;
    for (int i = n; i > 0; --i) phi = 0.5 * (phi + std::asin(c[i] / a[i] * std::sin(phi)));
    return std::sin(phi);
  }
};

// A01 exact: released at rest from the horizontal (phi0 = pi/2 from the downward vertical),
// phi(t) = 2 asin(k sn(K - w0 t; k)), k = sin(phi0 / 2); P1 = (L sin phi, -L cos phi).
struct PendulumExact {
  double length = 1.0, w0 = std::sqrt(9.81 / 1.0), k = std::sqrt(0.5);
  Agm agm{std::sqrt(0.5)};
  double phi(double t) const { return 2 * std::asin(k * agm.sn(agm.complete_k() - w0 * t)); }
  double x(double t) const { return length * std::sin(phi(t)); }
  double y(double t) const { return -length * std::cos(phi(t)); }
  double period() const { return 4 * agm.complete_k() / w0; }
};

}  // namespace mbdae
