#include "verification/redundancy/turning_loops_reference.h"

#include <cmath>
#include <functional>
#include <stdexcept>

namespace mbdae {
namespace {

constexpr double kOmega = 6.283185307179586, kG = 9.81;

// One body of the loop as a function of theta: centre of mass (x, z) in the turning frame and
// angle phi, each with its first and second derivatives.
struct BodyJet {
  double m, ixx, iyy, izz;
  double x, x1, x2, z, z1, z2, phi, phi1, phi2;
};

// The loop's kinematics at theta: its bodies, an extra generalized force (springs) from
// (theta, rate), and the tracked point (x, z) with dx/dtheta, dz/dtheta.
struct LoopKinematics {
  std::vector<BodyJet> bodies;
  double force = 0;
  double px = 0, pz = 0, px1 = 0, pz1 = 0;
};
using Kinematics = std::function<LoopKinematics(double theta, double rate)>;

double acceleration(const Kinematics& kin, double theta, double rate) {
  const LoopKinematics k = kin(theta, rate);
  double m = 0, c = 0, q = k.force;
  for (const BodyJet& b : k.bodies) {
    m += b.m * (b.x1 * b.x1 + b.z1 * b.z1) + b.iyy * b.phi1 * b.phi1;
    c += b.m * (b.x1 * b.x2 + b.z1 * b.z2) + b.iyy * b.phi1 * b.phi2;
    q += -b.m * kG * b.z1 + b.m * kOmega * kOmega * b.x * b.x1 +
         kOmega * kOmega * (b.ixx - b.izz) * std::sin(b.phi) * std::cos(b.phi) * b.phi1;
  }
  return (q - c * rate * rate) / m;
}

LoopSample sample(const Kinematics& kin, double t, double theta, double rate) {
  const LoopKinematics k = kin(theta, rate);
  const double psi = kOmega * t, cs = std::cos(psi), sn = std::sin(psi);
  const double vx = k.px1 * rate, vz = k.pz1 * rate, vy = kOmega * k.px;  // turning-frame velocity
  LoopSample s;
  s.t = t;
  s.theta = theta;
  s.rate = rate;
  s.point[0] = cs * k.px;
  s.point[1] = sn * k.px;
  s.point[2] = k.pz;
  s.velocity[0] = cs * vx - sn * vy;
  s.velocity[1] = sn * vx + cs * vy;
  s.velocity[2] = vz;
  return s;
}

// Classical RK4 with steps of at most `step`, landing on each output time.
std::vector<LoopSample> integrate(const Kinematics& kin, double theta, double rate, const std::vector<double>& times,
                                  double step) {
  std::vector<LoopSample> out;
  double t = 0;
  for (double t_out : times) {
    if (t_out < t) throw std::invalid_argument("reference: times must increase from 0");
    const int n = static_cast<int>(std::ceil((t_out - t) / step - 1e-9));
    const double h = n > 0 ? (t_out - t) / n : 0.0;
    for (int i = 0; i < n; ++i) {
      auto f = [&](double th, double w) { return acceleration(kin, th, w); };
      const double k1x = rate, k1v = f(theta, rate);
      const double k2x = rate + 0.5 * h * k1v, k2v = f(theta + 0.5 * h * k1x, k2x);
      const double k3x = rate + 0.5 * h * k2v, k3v = f(theta + 0.5 * h * k2x, k3x);
      const double k4x = rate + h * k3v, k4v = f(theta + h * k3x, k4x);
      theta += h / 6 * (k1x + 2 * k2x + 2 * k3x + k4x);
      rate += h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
    }
    t = t_out;
    out.push_back(sample(kin, t, theta, rate));
  }
  return out;
}

// u(phi) = (cos phi, -sin phi) in (x, z), and its derivatives.
struct Dir {
  double x, z, x1, z1, x2, z2;
};
Dir dir(double phi) {
  const double c = std::cos(phi), s = std::sin(phi);
  return {c, -s, -s, -c, -c, s};
}

LoopKinematics four_bar(double th) {
  const double ax = 0.1, az = 0.2, bx = 0.5, bz = 0.2, l1 = 0.1, l2 = 0.35, l3 = 0.3;
  const Dir u1 = dir(th);
  const double cx = ax + l1 * u1.x, cz = az + l1 * u1.z;
  // Coupler end D: the circles about C (l2) and B (l3), on the branch above the line C-B.
  const double dx = bx - cx, dz = bz - cz, d = std::hypot(dx, dz);
  const double a = (l2 * l2 - l3 * l3 + d * d) / (2 * d), h = std::sqrt(l2 * l2 - a * a);
  const double ex = dx / d, ez = dz / d;
  const double px = cx + a * ex - h * ez, pz = cz + a * ez + h * ex;
  const double beta = std::atan2(-(pz - cz), px - cx), gamma = std::atan2(-(pz - bz), px - bx);
  const Dir u2 = dir(beta), u3 = dir(gamma);
  // Closure l1 u1 + l2 u2 - l3 u3 = const: [l2 u2', -l3 u3'] (beta', gamma') = -l1 u1'.
  const double m11 = l2 * u2.x1, m12 = -l3 * u3.x1, m21 = l2 * u2.z1, m22 = -l3 * u3.z1;
  const double det = m11 * m22 - m12 * m21;
  auto solve = [&](double r1, double r2, double& y1, double& y2) {
    y1 = (r1 * m22 - m12 * r2) / det;
    y2 = (m11 * r2 - m21 * r1) / det;
  };
  double b1, g1, b2, g2;
  solve(-l1 * u1.x1, -l1 * u1.z1, b1, g1);
  solve(-(l1 * u1.x2 + l2 * u2.x2 * b1 * b1 - l3 * u3.x2 * g1 * g1),
        -(l1 * u1.z2 + l2 * u2.z2 * b1 * b1 - l3 * u3.z2 * g1 * g1), b2, g2);
  LoopKinematics k;
  k.bodies.push_back({0.5, 2.0e-5, 4.5e-4, 4.5e-4, ax + 0.05 * u1.x, 0.05 * u1.x1, 0.05 * u1.x2, az + 0.05 * u1.z,
                      0.05 * u1.z1, 0.05 * u1.z2, th, 1, 0});
  const double hc = 0.175;
  k.bodies.push_back({1.0, 4.0e-5, 1.03e-2, 1.03e-2, cx + hc * u2.x, l1 * u1.x1 + hc * u2.x1 * b1,
                      l1 * u1.x2 + hc * (u2.x2 * b1 * b1 + u2.x1 * b2), cz + hc * u2.z, l1 * u1.z1 + hc * u2.z1 * b1,
                      l1 * u1.z2 + hc * (u2.z2 * b1 * b1 + u2.z1 * b2), beta, b1, b2});
  const double hr = 0.15;
  k.bodies.push_back({0.8, 3.0e-5, 6.1e-3, 6.1e-3, bx + hr * u3.x, hr * u3.x1 * g1, hr * (u3.x2 * g1 * g1 + u3.x1 * g2),
                      bz + hr * u3.z, hr * u3.z1 * g1, hr * (u3.z2 * g1 * g1 + u3.z1 * g2), gamma, g1, g2});
  k.px = px;
  k.pz = pz;
  k.px1 = l3 * u3.x1 * g1;
  k.pz1 = l3 * u3.z1 * g1;
  return k;
}

LoopKinematics governor(double al, double rate) {
  const double a = 0.05, h = 1.0, e = 0.25, l = 0.3, c = 0.05, ca = 0.45, la = 0.5;
  const double ca_ = std::cos(al), sa = std::sin(al);
  // Pin P on arm A, and the sleeve height s = Pz - w, w = sqrt(l^2 - D^2), D = Px - c.
  const double pxx = a + e * ca_, px1 = -e * sa, px2 = -e * ca_;
  const double pzz = h - e * sa, pz1 = -e * ca_, pz2 = e * sa;
  const double dd = pxx - c, d1 = px1, d2 = px2;
  const double w = std::sqrt(l * l - dd * dd), w1 = -dd * d1 / w, w2 = -(d1 * d1 + dd * d2 + w1 * w1) / w;
  const double s = pzz - w, s1 = pz1 - w1, s2 = pz2 - w2;
  // Link A from the sleeve hinge (c, s) to P: angle atan2(-w, D); (X, Y) = (D, -w), X^2 + Y^2 = l^2.
  const double phil = std::atan2(-w, dd);
  const double phil1 = (dd * -w1 - -w * d1) / (l * l), phil2 = (dd * -w2 - -w * d2) / (l * l);
  LoopKinematics k;
  // Arms (B mirrors A: x -> -x, phi -> -phi).
  for (double sg : {1.0, -1.0})
    k.bodies.push_back({2.2, 1.0e-4, 3.0e-2, 3.0e-2, sg * (a + ca * ca_), sg * (-ca * sa), sg * (-ca * ca_),
                        h - ca * sa, -ca * ca_, ca * sa, sg * al, sg, 0});
  // Links: centre of mass midway between the sleeve hinge and the pin.
  for (double sg : {1.0, -1.0})
    k.bodies.push_back({0.2, 1.0e-5, 1.6e-3, 1.6e-3, sg * 0.5 * (c + pxx), sg * 0.5 * px1, sg * 0.5 * px2,
                        0.5 * (s + pzz), 0.5 * (s1 + pz1), 0.5 * (s2 + pz2), sg * phil, sg * phil1, sg * phil2});
  // Sleeve: on the axis, turning with the spindle (no rotation in the plane).
  k.bodies.push_back({1.5, 2.0e-3, 2.0e-3, 2.0e-3, 0, 0, 0, s, s1, s2, 0, 0, 0});
  // Spring-damper from the spindle point (0, 0.2) to the sleeve: length s - 0.2.
  const double len = s - 0.2, len_rate = s1 * rate;
  k.force = -(200.0 * (len - 0.4) + 2.0 * len_rate) * s1;
  k.px = a + la * ca_;
  k.pz = h - la * sa;
  k.px1 = -la * sa;
  k.pz1 = -la * ca_;
  return k;
}

}  // namespace

std::vector<LoopSample> turntable_four_bar_reference(double theta0, double rate0, const std::vector<double>& times,
                                                     double step) {
  return integrate([](double th, double) { return four_bar(th); }, theta0, rate0, times, step);
}

std::vector<LoopSample> governor_reference(double theta0, double rate0, const std::vector<double>& times,
                                           double step) {
  return integrate(governor, theta0, rate0, times, step);
}

}  // namespace mbdae
