#include "verification/fast_mechanism/slider_crank_reference.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace mbdae {
namespace {

// Derivatives with respect to theta of the piston position x, the rod angle psi and the rod's
// centre of mass R, first and second (x1, x2, ...), from w = sqrt(l^2 - r^2 sin^2 theta):
//   x = r cos + w,  sin psi = -r sin / l,  R = (1 - b/l) P + (b/l) (x, 0),  P = r (cos, sin).
struct Geometry {
  double x, x1, x2, psi1, psi2, R1[2], R2[2];
};

Geometry geometry(const SliderCrankParameters& p, double theta) {
  const double s = std::sin(theta), c = std::cos(theta), r = p.r;
  const double w = std::sqrt(p.l * p.l - r * r * s * s);
  const double w1 = -r * r * s * c / w;
  const double w2 = -r * r * (c * c - s * s) / w - w1 * w1 / w;
  Geometry g;
  g.x = r * c + w;
  g.x1 = -r * s + w1;
  g.x2 = -r * c + w2;
  g.psi1 = -r * c / w;
  g.psi2 = r * s / w + r * c * w1 / (w * w);
  const double beta = p.b / p.l;
  const double P1[2] = {-r * s, r * c}, P2[2] = {-r * c, -r * s};
  g.R1[0] = (1 - beta) * P1[0] + beta * g.x1;
  g.R1[1] = (1 - beta) * P1[1];
  g.R2[0] = (1 - beta) * P2[0] + beta * g.x2;
  g.R2[1] = (1 - beta) * P2[1];
  return g;
}

// theta'' of M theta'' + 1/2 M' theta'^2 = tau.
double acceleration(const SliderCrankParameters& p, double theta, double rate) {
  const Geometry g = geometry(p, theta);
  const double m = p.j_crank + p.m_crank * p.a * p.a +
                   p.m_rod * (g.R1[0] * g.R1[0] + g.R1[1] * g.R1[1]) + p.j_rod * g.psi1 * g.psi1 +
                   p.m_piston * g.x1 * g.x1;
  const double half_dm = p.m_rod * (g.R1[0] * g.R2[0] + g.R1[1] * g.R2[1]) + p.j_rod * g.psi1 * g.psi2 +
                         p.m_piston * g.x1 * g.x2;
  return (p.torque - half_dm * rate * rate) / m;
}

SliderCrankSample sample(const SliderCrankParameters& p, double t, double theta, double rate) {
  const Geometry g = geometry(p, theta);
  const double s = std::sin(theta), c = std::cos(theta);
  return {t, theta, rate, g.x, g.x1 * rate, p.r * c, p.r * s, -p.r * s * rate, p.r * c * rate};
}

// One Dormand-Prince 5(4) step of y = (theta, rate); returns the 5th-order solution in y_new and
// the difference to the embedded 4th-order one in err.
void dopri_step(const SliderCrankParameters& p, const double y[2], double h, double y_new[2], double err[2]) {
  static const double a[7][6] = {
      {},
      {1.0 / 5},
      {3.0 / 40, 9.0 / 40},
      {44.0 / 45, -56.0 / 15, 32.0 / 9},
      {19372.0 / 6561, -25360.0 / 2187, 64448.0 / 6561, -212.0 / 729},
      {9017.0 / 3168, -355.0 / 33, 46732.0 / 5247, 49.0 / 176, -5103.0 / 18656},
      {35.0 / 384, 0, 500.0 / 1113, 125.0 / 192, -2187.0 / 6784, 11.0 / 84}};
  static const double e[7] = {71.0 / 57600, 0, -71.0 / 16695, 71.0 / 1920, -17253.0 / 339200, 22.0 / 525, -1.0 / 40};
  double k[7][2];
  for (int i = 0; i < 7; ++i) {
    double yi[2] = {y[0], y[1]};
    for (int j = 0; j < i; ++j) {
      yi[0] += h * a[i][j] * k[j][0];
      yi[1] += h * a[i][j] * k[j][1];
    }
    k[i][0] = yi[1];
    k[i][1] = acceleration(p, yi[0], yi[1]);
    if (i == 6) {
      y_new[0] = yi[0];  // the last stage is evaluated at the 5th-order solution (FSAL)
      y_new[1] = yi[1];
    }
  }
  err[0] = err[1] = 0;
  for (int i = 0; i < 7; ++i) {
    err[0] += h * e[i] * k[i][0];
    err[1] += h * e[i] * k[i][1];
  }
}

}  // namespace

double SliderCrankSample::value(const std::string& s) const {
  if (s == "piston_x") return piston_x;
  if (s == "piston_vx") return piston_vx;
  if (s == "pin_x") return pin_x;
  if (s == "pin_y") return pin_y;
  if (s == "pin_vx") return pin_vx;
  if (s == "pin_vy") return pin_vy;
  if (s == "crank_rate") return rate;
  throw std::out_of_range("no reference for sensor " + s);
}

std::vector<SliderCrankSample> slider_crank_reference(const SliderCrankParameters& p,
                                                      const std::vector<double>& times, double tol) {
  std::vector<SliderCrankSample> out;
  double t = 0, y[2] = {p.theta0, 0.0}, h = 1e-6;
  for (double t_out : times) {
    while (t < t_out) {
      const bool last = t + h >= t_out;
      const double step = last ? t_out - t : h;
      double y_new[2], err[2];
      dopri_step(p, y, step, y_new, err);
      double norm = 0;
      for (int i = 0; i < 2; ++i) {
        const double sc = tol * (1.0 + std::max(std::fabs(y[i]), std::fabs(y_new[i])));
        norm = std::max(norm, std::fabs(err[i]) / sc);
      }
      if (norm <= 1.0) {
        t = last ? t_out : t + step;
        y[0] = y_new[0];
        y[1] = y_new[1];
      }
      const double factor = norm > 0 ? 0.9 * std::pow(norm, -0.2) : 5.0;
      if (!(last && norm <= 1.0)) h = step * std::min(5.0, std::max(0.2, factor));  // keep h past a sample
      if (h < 1e-14) throw std::runtime_error("slider_crank_reference: step size underflow");
    }
    out.push_back(sample(p, t_out, y[0], y[1]));
  }
  return out;
}

}  // namespace mbdae
