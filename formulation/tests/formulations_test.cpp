// The stabilized index-2 (GGL) and index-1 (Baumgarte) formulations against finite differences
// and against the index-3 formulation and closed-form references:
//  a. the Newton matrix dF/dy + cj dF/dy' of each against central differences of its residual
//     on a model with every constraint and force type (index 1: exact blocks exactly, the
//     omitted d(gamma)/dq block measured);
//  b. a compound pendulum through core/ida_driver integrate(): period against the elliptic
//     integral and the trajectory against index 3, within what the tolerance promises;
//  c. constraint drift at position level: GGL at the Newton tolerance, index 1 with Baumgarte
//     bounded (and growing without it);
//  d. events (wheel contact) located at the same times as index 3.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "core/ida_driver.h"
#include "formulation/constraint_rates.h"
#include "formulation/ggl_dae.h"
#include "formulation/index1_dae.h"
#include "formulation/index3_dae.h"
#include "formulation/mechanics.h"
#include "formulation/system.h"
#include "formulation/tests/test_models.h"

namespace mbdae {
namespace {

constexpr double kPi = 3.14159265358979323846;

// --- a. Newton matrices ------------------------------------------------------------------------

struct State {
  std::vector<double> q, v, a, lambda, mu;
};

// A state off the constraint manifold (the Newton matrix must be right everywhere).
State random_state(const System& sys, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  State s;
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

Eigen::MatrixXd analytic_matrix(DaeProblem& dae, double t, double cj, const std::vector<double>& y,
                                const std::vector<double>& yp) {
  const int n = dae.size();
  const CscPattern& p = dae.jacobian_pattern();
  std::vector<double> values(p.nnz());
  dae.jacobian(t, cj, y.data(), yp.data(), values.data());
  Eigen::MatrixXd an = Eigen::MatrixXd::Zero(n, n);
  for (int c = 0; c < n; ++c)
    for (int k = p.colptr[c]; k < p.colptr[c + 1]; ++k) an(p.rowind[k], c) += values[k];
  return an;
}

// Central differences of F(t, y + e, y' + cj e) column by column.
Eigen::MatrixXd fd_matrix(DaeProblem& dae, double t, double cj, const std::vector<double>& y,
                          const std::vector<double>& yp) {
  const int n = dae.size();
  Eigen::MatrixXd fd(n, n);
  std::vector<double> rp(n), rm(n);
  const double eps = 1e-6;
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

// max over entries of |an - fd| / (1 + |fd|), with a failure per bad entry.
double compare(DaeProblem& dae, const Eigen::MatrixXd& an, const Eigen::MatrixXd& fd, double tol,
               const char* what) {
  double worst = 0;
  for (int c = 0; c < fd.cols(); ++c)
    for (int r = 0; r < fd.rows(); ++r) {
      const double err = std::fabs(an(r, c) - fd(r, c)) / (1 + std::fabs(fd(r, c)));
      worst = std::max(worst, err);
      EXPECT_LT(err, tol) << what << ": row " << dae.component_name(r) << " col "
                          << dae.component_name(c) << " analytic " << an(r, c) << " fd " << fd(r, c);
    }
  return worst;
}

TEST(Formulations, GglNewtonMatrixIsExact) {
  const System sys = build_system(testing::all_types_model());
  GglDae dae(sys, 7.0);
  const State st = random_state(sys, 3);
  const int n = dae.size(), nq = sys.nq(), nc = sys.num_constraint_rows();
  ASSERT_EQ(n, 2 * nq + 2 * nc);
  std::vector<double> y(n), yp(n, 0.0);
  std::copy(st.q.begin(), st.q.end(), y.begin());
  std::copy(st.v.begin(), st.v.end(), y.begin() + nq);
  std::copy(st.lambda.begin(), st.lambda.end(), y.begin() + 2 * nq);
  std::copy(st.mu.begin(), st.mu.end(), y.begin() + 2 * nq + nc);
  for (int i = 0; i < nq; ++i) yp[i] = st.v[i] + 0.1;
  std::copy(st.a.begin(), st.a.end(), yp.begin() + nq);
  const double cj = 37.0, t = 0.3;
  // Wheel in contact (its force derivatives in the matrix).
  for (auto& m : dae.modes) m = 1;
  const Eigen::MatrixXd an = analytic_matrix(dae, t, cj, y, yp), fd = fd_matrix(dae, t, cj, y, yp);
  const double worst = compare(dae, an, fd, 1e-6, "GGL");
  std::printf("  GGL Newton matrix (%d x %d, %d non-zeros): worst relative error %.2e\n", n, n,
              dae.jacobian_pattern().nnz(), worst);
  // The new blocks are really exercised: sum mu_k H_k (F1, q) and (H_k v)^T (F4, q).
  EXPECT_GT(fd.block(0, 0, nq, nq).cwiseAbs().maxCoeff(), cj + 1e-3);
  EXPECT_GT(fd.block(2 * nq + nc, 0, nc, nq).cwiseAbs().maxCoeff(), 1e-3);
}

TEST(Formulations, Index1NewtonMatrixExactBlocksAndOmittedGammaQ) {
  const System sys = build_system(testing::all_types_model());
  const double scale = 7.0;
  const BaumgarteParameters bg{3.0, 5.0};
  Index1Dae dae(sys, scale, bg);
  Index1Dae exact(sys, scale, bg, true);
  const State st = random_state(sys, 3);
  const int n = dae.size(), nq = sys.nq(), nc = sys.num_constraint_rows();
  const std::vector<int> off = constraint_offsets(sys);
  std::vector<double> y(n), yp(n, 0.0);
  std::copy(st.q.begin(), st.q.end(), y.begin());
  std::copy(st.v.begin(), st.v.end(), y.begin() + nq);
  std::copy(st.lambda.begin(), st.lambda.end(), y.begin() + 2 * nq);
  for (int i = 0; i < nq; ++i) yp[i] = st.v[i] + 0.1;
  std::copy(st.a.begin(), st.a.end(), yp.begin() + nq);
  const double cj = 37.0, t = 0.3;
  for (auto& m : dae.modes) m = 1;
  for (auto& m : exact.modes) m = 1;
  const Eigen::MatrixXd an = analytic_matrix(dae, t, cj, y, yp), fd = fd_matrix(dae, t, cj, y, yp);

  // The omitted block, -s d(gamma)/dq (F3 rows, q columns), by differences of gamma alone.
  Eigen::MatrixXd omitted = Eigen::MatrixXd::Zero(n, n);
  std::vector<double> gp(nc), gm(nc), qq(nq);
  const double eps = 1e-6;
  for (int c = 0; c < nq; ++c) {
    qq = st.q;
    qq[c] += eps;
    constraint_rates(sys, off, qq.data(), st.v.data(), t, nullptr, gp.data());
    qq[c] -= 2 * eps;
    constraint_rates(sys, off, qq.data(), st.v.data(), t, nullptr, gm.data());
    for (int r = 0; r < nc; ++r) omitted(2 * nq + r, c) = -scale * (gp[r] - gm[r]) / (2 * eps);
  }
  // Every block but the omitted one is exact: analytic + omitted = differences, entry by entry.
  const double worst = compare(dae, an + omitted, fd, 1e-6, "index 1 (exact blocks)");
  // The option with d(gamma)/dq by differences of the local Hessians matches the full matrix.
  const Eigen::MatrixXd an_exact = analytic_matrix(exact, t, cj, y, yp);
  const double worst_exact = compare(exact, an_exact, fd, 1e-5, "index 1 (exact_gamma_q)");

  // Size of the omitted part: against the F3 q-column block it belongs to, and against the
  // whole F3 row block as the Newton iteration sees it (q corrections are v corrections / cj,
  // so q columns count 1/cj relative to v columns).
  const Eigen::MatrixXd f3q = fd.block(2 * nq, 0, nc, nq), f3v = fd.block(2 * nq, nq, nc, nq);
  const double rel_block = omitted.norm() / f3q.norm();
  const double rel_newton = omitted.norm() / (cj * f3v.norm());
  std::printf("  index-1 Newton matrix (%d x %d): exact blocks worst relative error %.2e; with "
              "d(gamma)/dq by differences %.2e\n"
              "  omitted -s d(gamma)/dq: max |entry| %.3e, %.1f%% of the F3 q-column block, "
              "%.2e of cj |F3 v-columns| (|v| ~ 1, cj = %.0f)\n",
              n, n, worst, worst_exact, omitted.cwiseAbs().maxCoeff(), 100 * rel_block, rel_newton, cj);
  EXPECT_GT(omitted.cwiseAbs().maxCoeff(), 1e-3) << "the omitted block is not exercised";
  EXPECT_EQ((omitted.topRows(2 * nq)).cwiseAbs().maxCoeff(), 0.0);
}

// --- b. Compound pendulum ------------------------------------------------------------------------

double agm(double a, double b) {
  for (int i = 0; i < 64 && std::fabs(a - b) > 1e-16 * a; ++i) {
    const double m = 0.5 * (a + b);
    b = std::sqrt(a * b);
    a = m;
  }
  return 0.5 * (a + b);
}
double elliptic_k(double k) { return kPi / (2.0 * agm(1.0, std::sqrt(1.0 - k * k))); }

// Downward zero crossings of u from samples (t, u, u'), cubic Hermite on each bracket.
std::vector<double> downward_crossings(const std::vector<double>& t, const std::vector<double>& u,
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

struct Run {
  IdaStats stats;
  std::vector<double> t, theta, rate, violation;  // violation: max |Phi| of each (interpolated) sample
  double max_position_violation = 0, max_velocity_violation = 0, max_norm_drift = 0;
};

// Integrates `dae` from the model's initial configuration at rest; samples theta (coordinate 0)
// and its rate from the projected output, as run_scene does.
template <class Dae>
Run integrate_model(Dae& dae, const IdaOptions& o) {
  const System& sys = dae.system();
  Run run;
  std::vector<double> y(dae.size(), 0.0), yp(dae.size(), 0.0);
  std::copy(sys.q0.begin(), sys.q0.end(), y.begin());
  dae.modes = initial_modes(sys, y.data(), o.t0);
  dae.consistent_initial_values(o.t0, y, yp);
  const std::vector<int> off = constraint_offsets(sys);
  std::vector<double> q, v, a, phi(off.back());
  run.stats = integrate(dae, o, y, yp, [&](double t, const double* yy, const double*) {
    constraint_values(sys, off, yy, t, phi.data());
    run.violation.push_back(max_abs(phi.data(), off.back()));
    dae.consistent_output(t, yy, q, v, a);
    run.t.push_back(t);
    run.theta.push_back(coordinate_value(sys, 0, q.data()));
    run.rate.push_back(coordinate_rate(sys, 0, q.data(), v.data()));
    return true;
  });
  run.max_position_violation = dae.max_position_violation;
  run.max_norm_drift = dae.max_norm_drift;
  return run;
}

// Pendulum: m = 2 kg, centre of mass d = 0.5 m below the pivot, I_xx = 0.05 kg m^2 about the
// centre of mass, released at rest from 1 rad about the x axis.
constexpr double kMass = 2.0, kD = 0.5, kIxx = 0.05, kTheta0 = 1.0, kG = 9.81;
double exact_period() {
  const double i_pivot = kIxx + kMass * kD * kD;
  return 4.0 * std::sqrt(i_pivot / (kMass * kG * kD)) * elliptic_k(std::sin(kTheta0 / 2));
}

double measured_period(const Run& r) {
  const std::vector<double> c = downward_crossings(r.t, r.theta, r.rate);
  if (c.size() < 2) return 0;
  return (c.back() - c.front()) / static_cast<double>(c.size() - 1);
}

double max_diff(const std::vector<double>& a, const std::vector<double>& b) {
  double m = 0;
  for (size_t i = 0; i < std::min(a.size(), b.size()); ++i) m = std::max(m, std::fabs(a[i] - b[i]));
  return m;
}

TEST(Formulations, CompoundPendulumMatchesIndex3AndExactPeriod) {
  const System sys = build_system(testing::pendulum(kMass, kD, kIxx, kTheta0));
  const double period = exact_period();
  IdaOptions o;
  o.t1 = 5.0 * period + 0.1;
  o.output_step = 1e-3;
  o.rtol = 1e-9;
  o.atol = 1e-11;
  Index3Dae i3(sys, 2.0 / (1e-3 * 1e-3));
  GglDae ggl(sys);
  Index1Dae i1(sys);
  const Run r3 = integrate_model(i3, o), rg = integrate_model(ggl, o), r1 = integrate_model(i1, o);
  ASSERT_TRUE(r3.stats.ok) << r3.stats.message;
  ASSERT_TRUE(rg.stats.ok) << rg.stats.message;
  ASSERT_TRUE(r1.stats.ok) << r1.stats.message;
  ASSERT_EQ(rg.t.size(), r3.t.size());
  ASSERT_EQ(r1.t.size(), r3.t.size());
  // What rtol promises: a local error per step of about rtol |y|, adding up over the ~N steps
  // to a global phase error of at most ~ N rtol (BDF errors are not all of one sign, so the
  // growth is well below that). The bound below, 1e3 rtol relative on the period (about
  // 5e-7 s) and 1e3 rtol (rad) on theta at every sample, holds with a margin of about 10-100
  // (measured values printed).
  const double bound = 1e3 * o.rtol;
  struct {
    const char* name;
    const Run* r;
  } runs[] = {{"index3", &r3}, {"index2-ggl", &rg}, {"index1", &r1}};
  for (const auto& [name, r] : runs) {
    const double tp = measured_period(*r);
    const double rel = (tp - period) / period;
    const double dtheta = max_diff(r->theta, r3.theta);
    std::printf("  %-10s %5ld steps %6ld residuals: period %.12f s (exact %.12f, rel. error %.2e), "
                "max |theta - theta_index3| %.2e rad, max |Phi| %.2e\n",
                name, r->stats.steps, r->stats.residual_evals, tp, period, rel, dtheta,
                r->max_position_violation);
    EXPECT_LT(std::fabs(rel), bound) << name;
    EXPECT_LT(dtheta, bound) << name;
  }
}

// --- c. Constraint drift ----------------------------------------------------------------------

TEST(Formulations, ConstraintDrift) {
  const System sys = build_system(testing::pendulum(kMass, kD, kIxx, kTheta0));
  IdaOptions o;
  o.t1 = 30.0;
  o.output_step = 1e-2;
  o.rtol = 1e-6;
  o.atol = 1e-8;
  // GGL enforces Phi = 0 at every step: the violation is the Newton iteration's leftover,
  // bounded by the Newton test (weighted corrections below 0.33 of the tolerance rtol|q| + atol).
  GglDae ggl(sys);
  const Run rg = integrate_model(ggl, o);
  ASSERT_TRUE(rg.stats.ok) << rg.stats.message;
  double qmax = 0;
  for (double x : sys.q0) qmax = std::max(qmax, std::fabs(x));
  const double tol = o.rtol * std::max(1.0, qmax) + o.atol;
  std::printf("  GGL over %.0f s at rtol %.0e: max |Phi| %.2e (tolerance %.1e), max |Phi_q v + Phi_t| "
              "%.2e, max | |p| - 1 | %.2e\n",
              o.t1, o.rtol, rg.max_position_violation, tol, ggl.max_velocity_violation, rg.max_norm_drift);
  EXPECT_LT(rg.max_position_violation, tol);
  EXPECT_LT(ggl.max_velocity_violation, 10 * tol);

  // Index 1: the drift of Phi and Phi' is driven by each step's local error. With Baumgarte it
  // settles to a bounded level; without (alpha = beta = 0) it grows with time.
  auto late_over_early = [&](const Run& r) {
    double early = 0, late = 0;
    for (size_t i = 0; i < r.t.size(); ++i) {
      double& m = r.t[i] < o.t1 / 2 ? early : late;
      m = std::max(m, r.violation[i]);
    }
    return std::pair<double, double>(early, late);
  };
  Index1Dae stab(sys);
  Index1Dae plain(sys, 1.0, BaumgarteParameters{0.0, 0.0});
  const Run rs = integrate_model(stab, o), rp = integrate_model(plain, o);
  ASSERT_TRUE(rs.stats.ok) << rs.stats.message;
  ASSERT_TRUE(rp.stats.ok) << rp.stats.message;
  const auto [se, sl] = late_over_early(rs);
  const auto [pe, pl] = late_over_early(rp);
  std::printf("  index1 alpha = beta = %.0f/s: max |Phi| %.2e (first half %.2e, second half %.2e), "
              "max |Phi'| %.2e\n",
              stab.baumgarte().alpha, rs.max_position_violation, se, sl, stab.max_velocity_violation);
  std::printf("  index1 without stabilization: max |Phi| %.2e (first half %.2e, second half %.2e), "
              "max |Phi'| %.2e\n",
              rp.max_position_violation, pe, pl, plain.max_velocity_violation);
  // Bounded: no growth from the first to the second half, and at the tolerance's level.
  EXPECT_LT(rs.max_position_violation, 10 * tol);
  EXPECT_LT(sl, 2 * se + tol);
  // Unstabilized drift grows and is larger than the stabilized one.
  EXPECT_GT(pl, pe);
  EXPECT_GT(rp.max_position_violation, rs.max_position_violation);
}

// --- d. Events ----------------------------------------------------------------------------------

// A wheel on a vertical slider, dropped from 0.2 m above ground contact: it bounces on the tyre
// spring (no damping), so contact and lift-off alternate as events.
Model bouncing_wheel() {
  Model m;
  m.name = "bouncing_wheel";
  m.bodies.push_back(testing::make_body("wheel", 10.0, Vec3::Zero(), Vec3(0.3, 0.5, 0.3)));
  m.joints.push_back(testing::make_joint("slider", kGround, "wheel", Vec3::Zero(), "T3 ", {"z"}));
  testing::add_coordinate(m, "z", 0.5);
  ForceSpec w;
  w.name = "tyre";
  w.type = ForceSpec::Type::kWheelContact;
  w.body1 = "wheel";
  w.stiffness = 1e5;
  w.radius = 0.3;
  w.axis = Vec3(0, 1, 0);
  w.ground = TimeFunction::constant(0.0);
  m.forces.push_back(w);
  return m;
}

TEST(Formulations, WheelContactEventsMatchIndex3) {
  const System sys = build_system(bouncing_wheel());
  IdaOptions o;
  o.t1 = 1.5;
  o.output_step = 1e-2;
  o.rtol = 1e-9;
  o.atol = 1e-11;
  Index3Dae i3(sys, 10.0 / (1e-3 * 1e-3));
  GglDae ggl(sys);
  Index1Dae i1(sys);
  const Run r3 = integrate_model(i3, o), rg = integrate_model(ggl, o), r1 = integrate_model(i1, o);
  ASSERT_TRUE(r3.stats.ok && rg.stats.ok && r1.stats.ok);
  // Free fall of 0.2 m: first contact at sqrt(2 h / g).
  ASSERT_GE(r3.stats.event_times.size(), 4u);
  EXPECT_NEAR(r3.stats.event_times[0], std::sqrt(2 * 0.2 / kG), 1e-6);
  for (const Run* r : {&rg, &r1}) {
    ASSERT_EQ(r->stats.event_times.size(), r3.stats.event_times.size());
    for (size_t k = 0; k < r3.stats.event_times.size(); ++k)
      EXPECT_NEAR(r->stats.event_times[k], r3.stats.event_times[k], 1e-6) << "event " << k;
  }
  std::printf("  %zu events; first at %.9f s (free fall %.9f s); index2-ggl, index1 - index3 at the "
              "last event: %.2e, %.2e s; max |z - z_index3|: %.2e, %.2e m\n",
              r3.stats.event_times.size(), r3.stats.event_times[0], std::sqrt(2 * 0.2 / kG),
              rg.stats.event_times.back() - r3.stats.event_times.back(),
              r1.stats.event_times.back() - r3.stats.event_times.back(), max_diff(rg.theta, r3.theta),
              max_diff(r1.theta, r3.theta));
}

}  // namespace
}  // namespace mbdae
