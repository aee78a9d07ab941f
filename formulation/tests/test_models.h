// Small models shared by the formulation tests, built in code (no scene files).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "formulation/forces.h"
#include "formulation/model.h"
#include "formulation/system.h"

namespace mbdae::testing {

inline BodySpec make_body(const std::string& name, double mass, const Vec3& com, const Vec3& diag,
                          const Vec3& offdiag = Vec3::Zero()) {
  BodySpec b;
  b.name = name;
  b.mass = mass;
  b.com = com;
  b.inertia << diag[0], offdiag[0], offdiag[2], offdiag[0], diag[1], offdiag[1], offdiag[2],
      offdiag[1], diag[2];
  return b;
}

inline JointSpec make_joint(const std::string& name, const std::string& parent,
                            const std::string& child, const Vec3& anchor, const std::string& chain,
                            const std::vector<std::string>& coords) {
  JointSpec j;
  j.name = name;
  j.parent = parent;
  j.child = child;
  j.anchor = anchor;
  for (size_t k = 0; k < coords.size(); ++k) {
    ElementaryJoint e;
    e.rotation = chain[3 * k] == 'R';
    e.axis = chain[3 * k + 1] - '1';
    e.coordinate = coords[k];
    j.chain.push_back(e);
  }
  return j;
}

inline void add_coordinate(Model& m, const std::string& name, double initial,
                           CoordinateSpec::Mode mode = CoordinateSpec::Mode::kFree) {
  CoordinateSpec c;
  c.name = name;
  c.initial = initial;
  c.mode = mode;
  m.coordinates[name] = c;
}

// A compound pendulum on a revolute joint (R1) at the origin, centre of mass at (0, 0, -d).
inline Model pendulum(double mass, double d, double ixx, double theta0) {
  Model m;
  m.name = "pendulum";
  m.bodies.push_back(make_body("bob", mass, Vec3(0, 0, -d), Vec3(ixx, ixx, 0.3 * ixx)));
  m.joints.push_back(make_joint("pivot", kGround, "bob", Vec3::Zero(), "R1 ", {"theta"}));
  add_coordinate(m, "theta", theta0);
  return m;
}

// A model exercising every constraint and force type: chains R1, R1 R3, R1 R2 R3, T3, T1 R3,
// R3 T1, weld; cuts of every type; spring-damper, point force, wheel contact, user law.
// (The same model as in jacobian_fd_test.cpp, which may use this one instead of its copy.)
inline Model all_types_model() {
  Model m;
  m.name = "all_types";
  m.bodies.push_back(make_body("a", 2.0, Vec3(0.1, 0.2, -0.3), Vec3(0.3, 0.4, 0.5), Vec3(0.01, 0.02, 0.03)));
  m.bodies.push_back(make_body("b", 1.5, Vec3(0.0, 0.4, 0.1), Vec3(0.2, 0.1, 0.25)));
  m.bodies.push_back(make_body("c", 1.0, Vec3(0.2, 0.0, 0.0), Vec3(0.1, 0.1, 0.1)));
  m.bodies.push_back(make_body("d", 3.0, Vec3(0.0, 0.0, 0.1), Vec3(0.2, 0.3, 0.2)));
  m.bodies.push_back(make_body("e", 0.5, Vec3(0.1, 0.1, 0.1), Vec3(0.05, 0.04, 0.03)));
  m.bodies.push_back(make_body("f", 0.7, Vec3(0.0, 0.2, 0.0), Vec3(0.05, 0.06, 0.07)));
  m.bodies.push_back(make_body("g", 0.9, Vec3(0.0, 0.0, 0.0), Vec3(0.05, 0.06, 0.07)));
  m.bodies[0].points["p"] = Vec3(0.3, -0.1, 0.2);
  m.joints.push_back(make_joint("ja", kGround, "a", Vec3(0.1, 0, 1), "R1 ", {"qa"}));
  m.joints.push_back(make_joint("jb", "a", "b", Vec3(0.2, 0.1, -0.4), "R1 R3 ", {"qb1", "qb2"}));
  m.joints.push_back(make_joint("jc", "b", "c", Vec3(0, 0.5, 0), "R1 R2 R3 ", {"qc1", "qc2", "qc3"}));
  m.joints.push_back(make_joint("jd", kGround, "d", Vec3(1, 1, 0), "T3 ", {"qd"}));
  m.joints.push_back(make_joint("je", "d", "e", Vec3(0.1, 0.2, 0.3), "T1 R3 ", {"qe1", "qe2"}));
  m.joints.push_back(make_joint("jf", "d", "f", Vec3(-0.1, 0.2, 0.3), "R3 T1 ", {"qf1", "qf2"}));
  m.joints.push_back(make_joint("jg", "f", "g", Vec3(0.0, 0.1, 0.0), "R2 ", {"qg"}));
  add_coordinate(m, "qa", 0.3);
  add_coordinate(m, "qb1", -0.2, CoordinateSpec::Mode::kLocked);
  add_coordinate(m, "qb2", 0.4);
  add_coordinate(m, "qc1", 0.1);
  add_coordinate(m, "qc2", 0.2, CoordinateSpec::Mode::kLocked);
  add_coordinate(m, "qc3", -0.3);
  add_coordinate(m, "qd", 0.5);
  add_coordinate(m, "qe1", 0.05);
  add_coordinate(m, "qe2", 0.3);
  add_coordinate(m, "qf1", -0.4);
  add_coordinate(m, "qf2", 0.07, CoordinateSpec::Mode::kDriven);
  m.coordinates["qf2"].drive.kind = TimeFunction::Kind::kSine;
  m.coordinates["qf2"].drive.a = 0.1;
  m.coordinates["qf2"].drive.b = 2.0;
  add_coordinate(m, "qg", 0.2, CoordinateSpec::Mode::kDriven);
  m.coordinates["qg"].drive = TimeFunction::constant(0.2);
  auto cut = [&](CutSpec::Type t, const std::string& b1, const std::string& b2) {
    CutSpec c;
    c.name = "cut" + std::to_string(m.cuts.size());
    c.type = t;
    c.body1 = b1;
    c.body2 = b2;
    c.axis1 = Vec3(0.3, 0.5, 0.8);
    c.axis2 = Vec3(-0.2, 0.9, 0.1);
    c.distance = 0.7;
    m.cuts.push_back(c);
  };
  cut(CutSpec::Type::kBall, "c", "e");
  cut(CutSpec::Type::kRevolute, "c", "g");
  cut(CutSpec::Type::kUniversal, "a", "e");
  cut(CutSpec::Type::kPrismatic, "b", "g");
  cut(CutSpec::Type::kWeld, kGround, "g");
  cut(CutSpec::Type::kDistance, "a", "d");
  ForceSpec s;
  s.name = "spring";
  s.type = ForceSpec::Type::kSpringDamper;
  s.body1 = "a";
  s.point1 = "p";
  s.body2 = "c";
  s.stiffness = 100;
  s.damping = 3;
  s.free_length = 0.2;
  m.forces.push_back(s);
  ForceSpec p;
  p.name = "push";
  p.type = ForceSpec::Type::kPointForce;
  p.body1 = "b";
  p.fx = TimeFunction::constant(1.0);
  p.fz = TimeFunction::constant(-2.0);
  m.forces.push_back(p);
  ForceSpec w;
  w.name = "tyre";
  w.type = ForceSpec::Type::kWheelContact;
  w.body1 = "g";
  w.stiffness = 1000;
  w.radius = 0.3;
  w.axis = Vec3(0, 1, 0);
  w.ground = TimeFunction::constant(0.9);
  m.forces.push_back(w);
  ForceSpec u;
  u.name = "bushing";
  u.type = ForceSpec::Type::kUser;
  u.body1 = "e";
  u.body2 = kGround;
  u.law = "linear_bushing";
  u.parameters = {{"stiffness", 50.0}, {"damping", 2.0}};
  m.forces.push_back(u);
  ForceSpec s2 = s;
  s2.name = "spring_ground";
  s2.body1 = kGround;
  s2.point1 = "";
  s2.body2 = "d";
  m.forces.push_back(s2);
  return m;
}

// A state off the constraint manifold (Newton matrices and derivatives must be right
// everywhere): q0 moved by up to 0.05 per coordinate (Euler parameters renormalized), v and a
// in [-1, 1], multipliers lambda in [-10, 10] and mu in [-0.1, 0.1].
struct RandomState {
  std::vector<double> q, v, a, lambda, mu;
};
inline RandomState random_state(const System& sys, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  RandomState s;
  const int nq = sys.nq(), nc = sys.num_constraint_rows();
  s.q = sys.q0;
  for (int i = 0; i < nq; ++i) s.q[i] += 0.05 * u(gen);
  for (int b = 0; b < sys.num_bodies(); ++b) Eigen::Map<Vec4>(s.q.data() + 7 * b + 3).normalize();
  s.v.resize(nq);
  s.a.resize(nq);
  for (int i = 0; i < nq; ++i) {
    s.v[i] = u(gen);
    s.a[i] = u(gen);
  }
  s.lambda.resize(nc);
  s.mu.resize(nc);
  for (auto& l : s.lambda) l = 10 * u(gen);
  for (auto& m : s.mu) m = 0.1 * u(gen);
  return s;
}

// The DAE vectors of a random state, n unknowns: y = [q, v, lambda (, mu with_mu)], rest 0;
// y' = [v + 0.1, a, 0 ...] (q' differs from v, so the rows F1 are exercised).
inline void dae_vectors(const RandomState& s, int n, bool with_mu, std::vector<double>& y,
                        std::vector<double>& yp) {
  const int nq = static_cast<int>(s.q.size()), nc = static_cast<int>(s.lambda.size());
  y.assign(n, 0.0);
  yp.assign(n, 0.0);
  std::copy(s.q.begin(), s.q.end(), y.begin());
  std::copy(s.v.begin(), s.v.end(), y.begin() + nq);
  std::copy(s.lambda.begin(), s.lambda.end(), y.begin() + 2 * nq);
  if (with_mu) std::copy(s.mu.begin(), s.mu.end(), y.begin() + 2 * nq + nc);
  for (int i = 0; i < nq; ++i) yp[i] = s.v[i] + 0.1;
  std::copy(s.a.begin(), s.a.end(), yp.begin() + nq);
}

// A number in scientific notation, for test properties (std::to_string prints 0.000000).
inline std::string sci(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%.2e", x);
  return b;
}

// A force element's local Jacobians dQ/dq, dQ/dv (force_eval at t = 0.2, in contact) against
// central differences: the largest relative difference |analytic - fd| / (1 + |fd|), where, and
// the size of the generalized force (a zero force would check nothing).
struct ForceCheck {
  double worst = 0, force_norm = 0;
  std::string where;
};
inline ForceCheck check_force_jacobians(const Force& f, const LocalState& x, const LocalState& v) {
  ForceCheck out;
  Vec14 q0 = Vec14::Zero();
  Mat14 dx = Mat14::Zero(), dv = Mat14::Zero();
  force_eval(f, x, v, 0.2, true, q0, &dx, &dv);
  out.force_norm = q0.norm();
  const double eps = 1e-6;
  for (int l = 0; l < 14; ++l) {
    if ((l < 7 && f.bi < 0) || (l >= 7 && f.bj < 0)) continue;
    for (int which = 0; which < 2; ++which) {
      Vec14 p = local_vector(which ? v : x), m = p;
      p[l] += eps;
      m[l] -= eps;
      Vec14 qp = Vec14::Zero(), qm = Vec14::Zero();
      force_eval(f, which ? x : local_state(p), which ? local_state(p) : v, 0.2, true, qp, nullptr, nullptr);
      force_eval(f, which ? x : local_state(m), which ? local_state(m) : v, 0.2, true, qm, nullptr, nullptr);
      const Vec14 fd = (qp - qm) / (2 * eps);
      const Mat14& an = which ? dv : dx;
      for (int k = 0; k < 14; ++k) {
        const double err = std::fabs(an(k, l) - fd(k)) / (1 + std::fabs(fd(k)));
        if (err > out.worst) {
          out.worst = err;
          out.where = f.name + (which ? " dQ/dv " : " dQ/dq ") + std::to_string(k) + "," + std::to_string(l);
        }
      }
    }
  }
  return out;
}

// The Newton matrix dF/dy + cj dF/dy' of a DAE (its sparse pattern and values) against central
// differences of its residual at a random state (cj = 37, t = 0.3): the largest relative
// difference |analytic - fd| / (1 + |fd|) and where it is.
struct NewtonCheck {
  double worst = 0;
  std::string where;
};
// The Newton matrix dF/dy + cj dF/dy' from the DAE's sparse pattern and values, as a dense matrix.
template <class Dae>
Eigen::MatrixXd analytic_matrix(Dae& dae, double t, double cj, const std::vector<double>& y,
                                const std::vector<double>& yp) {
  const int n = dae.size();
  const auto& p = dae.jacobian_pattern();
  std::vector<double> values(p.nnz());
  dae.jacobian(t, cj, y.data(), yp.data(), values.data());
  Eigen::MatrixXd an = Eigen::MatrixXd::Zero(n, n);
  for (int c = 0; c < n; ++c)
    for (int k = p.colptr[c]; k < p.colptr[c + 1]; ++k) an(p.rowind[k], c) += values[k];
  return an;
}

// The same by central differences of F(t, y + e, y' + cj e), column by column.
template <class Dae>
Eigen::MatrixXd fd_matrix(Dae& dae, double t, double cj, const std::vector<double>& y,
                          const std::vector<double>& yp) {
  const int n = dae.size();
  const double eps = 1e-6;
  Eigen::MatrixXd fd(n, n);
  std::vector<double> rp(n), rm(n);
  for (int c = 0; c < n; ++c) {
    std::vector<double> yy = y, yyp = yp, ym = y, ymp = yp;
    yy[c] += eps;
    yyp[c] += cj * eps;
    ym[c] -= eps;
    ymp[c] -= cj * eps;
    dae.residual(t, yy.data(), yyp.data(), rp.data());
    dae.residual(t, ym.data(), ymp.data(), rm.data());
    for (int r = 0; r < n; ++r) fd(r, c) = (rp[r] - rm[r]) / (2 * eps);
  }
  return fd;
}

template <class Dae>
NewtonCheck check_newton_matrix(Dae& dae, const RandomState& st, bool with_mu) {
  std::vector<double> y, yp;
  dae_vectors(st, dae.size(), with_mu, y, yp);
  const double cj = 37.0, t = 0.3;
  const Eigen::MatrixXd an = analytic_matrix(dae, t, cj, y, yp), fd = fd_matrix(dae, t, cj, y, yp);
  NewtonCheck out;
  for (int c = 0; c < an.cols(); ++c)
    for (int r = 0; r < an.rows(); ++r) {
      const double err = std::fabs(an(r, c) - fd(r, c)) / (1 + std::fabs(fd(r, c)));
      if (err > out.worst) {
        out.worst = err;
        out.where = "row " + dae.component_name(r) + " col " + dae.component_name(c) + " analytic " +
                    std::to_string(an(r, c)) + " fd " + std::to_string(fd(r, c));
      }
    }
  return out;
}

// Crank (length 1) and rocker (length 1) on revolute joints about z at (0,0,0) and (2,0,0),
// coupler (length 2) from the crank's tip; the cut closes the coupler on the rocker's tip with
// another revolute joint about z. A parallelogram: crank and rocker stay parallel.
inline Model four_bar(double angle) {
  Model m;
  m.bodies.push_back(make_body("crank", 1, Vec3(0.5, 0, 0), Vec3(0.01, 0.1, 0.1)));
  m.bodies.push_back(make_body("coupler", 1, Vec3(1, 0, 0), Vec3(0.01, 0.3, 0.3)));
  m.bodies.push_back(make_body("rocker", 1, Vec3(0.5, 0, 0), Vec3(0.01, 0.1, 0.1)));
  m.bodies[0].points["tip"] = Vec3(1, 0, 0);
  m.bodies[1].points["end"] = Vec3(2, 0, 0);
  m.bodies[2].points["tip"] = Vec3(1, 0, 0);
  m.joints.push_back(make_joint("j1", kGround, "crank", Vec3(0, 0, 0), "R3 ", {"a"}));
  JointSpec j2 = make_joint("j2", "crank", "coupler", Vec3::Zero(), "R3 ", {"b"});
  j2.anchor_point = "tip";
  m.joints.push_back(j2);
  m.joints.push_back(make_joint("j3", kGround, "rocker", Vec3(2, 0, 0), "R3 ", {"c"}));
  add_coordinate(m, "a", angle);
  add_coordinate(m, "b", -angle);
  add_coordinate(m, "c", angle);
  CutSpec cut;
  cut.name = "close";
  cut.type = CutSpec::Type::kRevolute;
  cut.body1 = "coupler";
  cut.point1 = "end";
  cut.body2 = "rocker";
  cut.point2 = "tip";
  cut.axis1 = cut.axis2 = Vec3::UnitZ();
  m.cuts.push_back(cut);
  return m;
}

}  // namespace mbdae::testing
