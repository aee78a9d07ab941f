// The stabilized index-2 (GGL) and index-1 (Baumgarte) formulations against finite differences
// and against the index-3 formulation and closed-form references:
//  a. the Newton matrix dF/dy + cj dF/dy' of each against central differences of its residual
//     on a model with every constraint and force type (index 1: exact blocks exactly, the
//     omitted d(gamma)/dq block measured);
//  b. a compound pendulum through core/ida_driver integrate(): period against the elliptic
//     integral and the trajectory against an index-3 reference, within what the tolerance
//     promises;
//  c. constraint drift at position level: GGL at the Newton tolerance, index 1 with Baumgarte
//     bounded (and growing without it);
//  d. events (wheel contact): contact and lift-off times against the closed form.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <random>

#include "core/ida_driver.h"
#include "formulation/constraint_rates.h"
#include "formulation/ggl_dae.h"
#include "formulation/index1_dae.h"
#include "formulation/index3_dae.h"
#include "formulation/mechanics.h"
#include "formulation/redundancy.h"
#include "formulation/system.h"
#include "formulation/tolerance_scales.h"
#include "formulation/twin_sensitivities.h"
#include "formulation/tests/integrate_model.h"
#include "formulation/tests/test_models.h"

namespace mbdae {
namespace {

using mbdae::testing::downward_crossings;
using mbdae::testing::elliptic_k;
using mbdae::testing::integrate_model;
using mbdae::testing::measured_period;
using mbdae::testing::RunResult;

constexpr double kPi = 3.14159265358979323846;

// --- a. Newton matrices ------------------------------------------------------------------------

using testing::random_state;
using State = testing::RandomState;

using testing::analytic_matrix;
using testing::fd_matrix;

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
  std::vector<double> y, yp;
  testing::dae_vectors(st, n, true, y, yp);
  const double cj = 37.0, t = 0.3;
  // Wheel in contact (its force derivatives in the matrix).
  for (auto& m : dae.state().modes) m = 1;
  const Eigen::MatrixXd an = analytic_matrix(dae, t, cj, y, yp), fd = fd_matrix(dae, t, cj, y, yp);
  const double worst = compare(dae, an, fd, 1e-6, "GGL");
  std::printf("  GGL Newton matrix (%d x %d, %d non-zeros): worst relative error %.2e\n", n, n,
              dae.jacobian_pattern().nnz(), worst);
  // The new blocks are really exercised: sum mu_k H_k (F1, q) and (H_k v)^T (F4, q).
  EXPECT_GT(fd.block(0, 0, nq, nq).cwiseAbs().maxCoeff(), cj + 1e-3);
  EXPECT_GT(fd.block(2 * nq + nc, 0, nc, nq).cwiseAbs().maxCoeff(), 1e-3);
}

// Each formulation on one system: index3, index2-ggl, index1 and penalty.
struct EveryFormulation {
  explicit EveryFormulation(const System& sys)
      : i3(sys, 3.0, true), ggl(sys, 7.0), i1(sys, 5.0, BaumgarteParameters{10.0, 20.0}),
        pen(sys, 5.0, BaumgarteParameters{10.0, 20.0}, false, 1e7) {}
  std::vector<MultibodyDae*> all() { return {&i3, &ggl, &i1, &pen}; }
  Index3Dae i3;
  GglDae ggl;
  Index1Dae i1, pen;
};

// F_y' x (MultibodyDae::derivative_times, the sensitivities' F_y' s') against the residual's own
// central difference in y', exact for a residual affine in y': every formulation, every row.
TEST(Formulations, DerivativeTimesIsTheResidualsDerivativeInYp) {
  const System sys = build_system(testing::all_types_model());
  EveryFormulation f(sys);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (MultibodyDae* dae : f.all()) {
    const int n = dae->size();
    std::vector<double> y, yp, x(n), ypp(n), ypm(n), rp(n), rm(n), out(n);
    testing::dae_vectors(random_state(sys, 5), n, dae == &f.ggl, y, yp);
    for (double& v : x) v = u(rng);
    for (int i = 0; i < n; ++i) {
      ypp[i] = yp[i] + x[i];
      ypm[i] = yp[i] - x[i];
    }
    ASSERT_EQ(dae->residual(0.3, y.data(), ypp.data(), rp.data()), 0);
    ASSERT_EQ(dae->residual(0.3, y.data(), ypm.data(), rm.data()), 0);
    dae->derivative_times(y.data(), x.data(), out.data());
    double worst = 0, largest = 0;
    for (int i = 0; i < n; ++i) {
      const double fd = 0.5 * (rp[i] - rm[i]);
      worst = std::max(worst, std::fabs(out[i] - fd) / (1 + std::fabs(fd)));
      largest = std::max(largest, std::fabs(fd));
    }
    std::printf("  F_y' x of a %d-unknown DAE: largest %.3g, worst relative difference %.2e\n", n, largest, worst);
    EXPECT_LT(worst, 1e-12);
    EXPECT_GT(largest, 0.1);  // not trivially zero
  }
}

// F_y x without the assembly (MultibodyDae::jacobian_times, the sensitivities' F_y s) against the
// assembled Newton matrix at cj = 0 times x: every formulation, two x at once, added to what
// out holds, the wheel in contact and out of it.
TEST(Formulations, JacobianTimesIsTheAssembledMatrixAtCjZeroTimesX) {
  const System sys = build_system(testing::all_types_model());
  EveryFormulation f(sys);
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (MultibodyDae* dae : f.all())
    for (char mode : {0, 1}) {
      for (auto& m : dae->state().modes) m = mode;
      const int n = dae->size();
      std::vector<double> y, yp, values(dae->jacobian_pattern().nnz());
      testing::dae_vectors(random_state(sys, 7), n, dae == &f.ggl, y, yp);
      std::vector<double> x[2], out[2], ref[2];
      for (int i = 0; i < 2; ++i) {
        x[i].resize(n);
        out[i].resize(n);
        ref[i].assign(n, 0.0);
        for (double& v : x[i]) v = u(rng);
        for (double& v : out[i]) v = u(rng);
      }
      ASSERT_EQ(dae->jacobian(0.3, 0.0, y.data(), yp.data(), values.data()), 0);
      const double* xs[2] = {x[0].data(), x[1].data()};
      double* outs[2] = {out[0].data(), out[1].data()};
      const std::vector<double> before[2] = {out[0], out[1]};
      dae->jacobian_times(0.3, y.data(), yp.data(), 2, xs, outs);
      double worst = 0, largest = 0;
      for (int i = 0; i < 2; ++i) {
        csc_multiply(dae->jacobian_pattern(), values.data(), x[i].data(), ref[i].data());
        for (int k = 0; k < n; ++k) {
          const double got = out[i][k] - before[i][k];
          worst = std::max(worst, std::fabs(got - ref[i][k]) / (1 + std::fabs(ref[i][k])));
          largest = std::max(largest, std::fabs(ref[i][k]));
        }
      }
      std::printf("  F_y x of a %d-unknown DAE (wheel %s): largest %.3g, worst relative difference %.2e\n", n,
                  mode ? "in contact" : "off", largest, worst);
      EXPECT_LT(worst, 1e-12);
      EXPECT_GT(largest, 1.0);
    }
}

// F_p over the terms a parameter reaches (formulation/parameter_reach.h) against the twins' whole
// residuals: the sensitivity residual at s = s' = 0 is F_p. Force numbers (a spring's, a user
// law's, the tyre's), a mass, an inertia and gravity reach bodies and forces; a centre of mass,
// a cut's length and a drive's amplitude reach constraints' terms (GglDae gives them; index1
// does not, and takes the whole residuals).
TEST(Formulations, ReachedParameterDifferenceIsTheWholeResidualsDifference) {
  const Model base = testing::all_types_model();
  const System sys = build_system(base);
  struct Case {
    const char* what;
    std::function<void(Model&, double)> set;
    bool local;
  };
  const std::vector<Case> cases = {
      {"spring stiffness", [](Model& m, double d) { m.forces[0].stiffness += d; }, true},
      {"user law parameter", [](Model& m, double d) { m.forces[3].parameters["stiffness"] += d; }, true},
      {"tyre radius", [](Model& m, double d) { m.forces[2].radius += d; }, true},
      {"mass of a", [](Model& m, double d) { m.bodies[0].mass += d; }, true},
      {"inertia of b", [](Model& m, double d) { m.bodies[1].inertia(0, 0) += d; }, true},
      {"gravity z", [](Model& m, double d) { m.gravity[2] += d; }, true},
      {"centre of mass of b", [](Model& m, double d) { m.bodies[1].com[0] += d; }, true},
      {"distance cut's length", [](Model& m, double d) { m.cuts[5].distance += d; }, true},
      {"drive's amplitude", [](Model& m, double d) { m.coordinates["qf2"].drive.a += d; }, true}};
  std::vector<double> y, yp;
  testing::dae_vectors(random_state(sys, 9), 2 * sys.nq() + 2 * sys.num_constraint_rows(), true, y, yp);
  for (const Case& c : cases) {
    const double d = 1e-4;
    std::vector<std::unique_ptr<System>> systems;
    auto twin_of = [&](double delta) {
      Model m = base;
      c.set(m, delta);
      systems.push_back(std::make_unique<System>(build_system(m)));
      return std::make_unique<GglDae>(*systems.back(), 7.0);
    };
    std::vector<double> r[2];
    bool local = false;
    for (int whole = 0; whole < 2; ++whole) {
      GglDae run(sys, 7.0);
      std::vector<ParameterTwins> twins(1);
      twins[0].plus = twin_of(d);
      twins[0].minus = twin_of(-d);
      twins[0].delta = d;
      twins[0].whole_residuals = whole == 1;
      for (auto& m : run.state().modes) m = 1;  // the tyre in contact
      TwinSensitivities ts(run, std::make_unique<GglDae>(sys, 7.0), std::move(twins), true);
      local = ts.twins(0).reach.local;
      const int n = run.size();
      std::vector<double> zero(n, 0.0);
      r[whole].assign(n, 0.0);
      const double* s[1] = {zero.data()};
      double* out[1] = {r[whole].data()};
      ASSERT_EQ(ts.residual(0.3, y.data(), yp.data(), nullptr, s, s, out), 0);
    }
    double worst = 0, largest = 0;
    for (size_t k = 0; k < r[0].size(); ++k) {
      worst = std::max(worst, std::fabs(r[0][k] - r[1][k]));
      largest = std::max(largest, std::fabs(r[1][k]));
    }
    std::printf("  F_p of the %s (%s): largest %.3g, reached against whole %.2e\n", c.what,
                local ? "reached terms" : "whole residuals", largest, worst);
    EXPECT_EQ(local, c.local) << c.what;
    EXPECT_GT(largest, 1e-2) << c.what;
    EXPECT_LT(worst, 1e-8 * largest) << c.what;
  }
  // index1 gives no constraint terms: a centre of mass takes the whole residuals there.
  std::vector<std::unique_ptr<System>> systems;
  std::vector<ParameterTwins> twins(1);
  for (int side = 0; side < 2; ++side) {
    Model m = base;
    m.bodies[1].com[0] += side == 0 ? 1e-4 : -1e-4;
    systems.push_back(std::make_unique<System>(build_system(m)));
    (side == 0 ? twins[0].plus : twins[0].minus) =
        std::make_unique<Index1Dae>(*systems.back(), 5.0, BaumgarteParameters{10.0, 20.0});
  }
  twins[0].delta = 1e-4;
  Index1Dae i1(sys, 5.0, BaumgarteParameters{10.0, 20.0});
  const TwinSensitivities ts(i1, std::make_unique<Index1Dae>(sys, 5.0, BaumgarteParameters{10.0, 20.0}),
                             std::move(twins), true);
  EXPECT_FALSE(ts.twins(0).reach.local);
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
  std::vector<double> y, yp;
  testing::dae_vectors(st, n, false, y, yp);
  const double cj = 37.0, t = 0.3;
  for (auto& m : dae.state().modes) m = 1;
  for (auto& m : exact.state().modes) m = 1;
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

TEST(Formulations, PenaltyResidualAndNewtonMatrix) {
  // F3 = s [index-1 rows - lambda / p], p = penalty * largest mass; the Newton matrix (with
  // d(gamma)/dq by differences, as in the index-1 test) against central differences, and its
  // lambda block exactly -s/p I.
  const System sys = build_system(testing::all_types_model());
  const double scale = 7.0, penalty = 1e3;
  const BaumgarteParameters bg{3.0, 5.0};
  Index1Dae plain(sys, scale, bg, true), pen(sys, scale, bg, true, penalty);
  double m_ref = 1e-3;
  for (const auto& b : sys.bodies) m_ref = std::max(m_ref, b.mass);
  EXPECT_DOUBLE_EQ(pen.inverse_penalty(), 1.0 / (penalty * m_ref));
  EXPECT_EQ(plain.inverse_penalty(), 0.0);
  const State st = random_state(sys, 5);
  const int n = pen.size(), nq = sys.nq(), nc = sys.num_constraint_rows();
  std::vector<double> y, yp;
  testing::dae_vectors(st, n, false, y, yp);
  const double cj = 37.0, t = 0.3;
  for (auto& m : pen.state().modes) m = 1;
  for (auto& m : plain.state().modes) m = 1;
  std::vector<double> rp(n), rn(n);
  pen.residual(t, y.data(), yp.data(), rp.data());
  plain.residual(t, y.data(), yp.data(), rn.data());
  for (int i = 0; i < 2 * nq; ++i) EXPECT_EQ(rp[i], rn[i]);
  for (int i = 0; i < nc; ++i)
    EXPECT_NEAR(rp[2 * nq + i], rn[2 * nq + i] - scale * st.lambda[i] / (penalty * m_ref),
                1e-12 * (1 + std::fabs(rn[2 * nq + i])));
  const Eigen::MatrixXd an = analytic_matrix(pen, t, cj, y, yp), fd = fd_matrix(pen, t, cj, y, yp);
  const double worst = compare(pen, an, fd, 1e-5, "penalty");
  const Eigen::MatrixXd block = an.block(2 * nq, 2 * nq, nc, nc);
  EXPECT_NEAR((block + scale / (penalty * m_ref) * Eigen::MatrixXd::Identity(nc, nc)).cwiseAbs().maxCoeff(), 0.0,
              1e-15);
  // Without penalty the pattern has no lambda-lambda entries.
  EXPECT_EQ(plain.jacobian_pattern().nnz() + nc, pen.jacobian_pattern().nnz());
  std::printf("  penalty Newton matrix (%d x %d): worst relative error %.2e\n", n, n, worst);
}

// --- b. Compound pendulum ------------------------------------------------------------------------

// A formulation that also records, per third of the run, the largest |Phi| and |Phi_q v + Phi_t|
// of the integrator's accepted steps.
template <class Dae>
struct Recording : Dae {
  using Dae::Dae;
  double t_end = 1;
  double phi[3] = {0, 0, 0}, phi_dot[3] = {0, 0, 0};
  void after_step(double t, const double* y) override {
    const double p = this->state().statistics.max_position_violation, v = this->state().statistics.max_velocity_violation;
    this->state().statistics.max_position_violation = this->state().statistics.max_velocity_violation = 0;
    Dae::after_step(t, y);
    const int k = std::min(2, static_cast<int>(3 * t / t_end));
    phi[k] = std::max(phi[k], this->state().statistics.max_position_violation);
    phi_dot[k] = std::max(phi_dot[k], this->state().statistics.max_velocity_violation);
    this->state().statistics.max_position_violation = std::max(p, this->state().statistics.max_position_violation);
    this->state().statistics.max_velocity_violation = std::max(v, this->state().statistics.max_velocity_violation);
  }
};

// Pendulum: m = 2 kg, centre of mass d = 0.5 m below the pivot, I_xx = 0.05 kg m^2 about the
// centre of mass, released at rest from 1 rad about the x axis.
constexpr double kMass = 2.0, kD = 0.5, kIxx = 0.05, kTheta0 = 1.0, kG = 9.81;
double exact_period() {
  const double i_pivot = kIxx + kMass * kD * kD;
  return 4.0 * std::sqrt(i_pivot / (kMass * kG * kD)) * elliptic_k(std::sin(kTheta0 / 2));
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
  o.t1 = 5.0 * period + 0.1;  // 5 periods, about 8 s
  o.output_step = 1e-3;
  // Reference: index 3 at rtol 1e-12 with a tight Newton test (period error 3.5e-10, theta
  // within 3e-8 rad of GGL at rtol 1e-13).
  IdaOptions oref = o;
  oref.rtol = 1e-12;
  oref.atol = 1e-14;
  oref.nonlinear_convergence = 0.001;
  Index3Dae ref_dae(sys, 2.0 / (1e-3 * 1e-3));
  const RunResult ref = integrate_model(ref_dae, oref);
  ASSERT_TRUE(ref.stats.ok) << ref.stats.message;
  EXPECT_LT(std::fabs(measured_period(ref) - period) / period, 1e-8);

  o.rtol = 1e-8;
  o.atol = 1e-10;
  Index3Dae i3(sys, 2.0 / (1e-3 * 1e-3));
  GglDae ggl(sys);
  Index1Dae i1(sys);
  const RunResult r3 = integrate_model(i3, o), rg = integrate_model(ggl, o), r1 = integrate_model(i1, o);
  ASSERT_TRUE(r3.stats.ok) << r3.stats.message;
  ASSERT_TRUE(rg.stats.ok) << rg.stats.message;
  ASSERT_TRUE(r1.stats.ok) << r1.stats.message;
  ASSERT_EQ(rg.t.size(), ref.t.size());
  ASSERT_EQ(r1.t.size(), ref.t.size());
  // What rtol promises: a local error per step below rtol |y| + atol in every error-tested
  // component, here q and v. The global error is that local error carried along the ~3000
  // steps; for this pendulum it is measured at 30-75 rtol in theta over 5 periods (rtol 1e-6 ..
  // 1e-10) and below 3 rtol in the period. Bounds: theta within 200 rtol of the reference at
  // every sample, period within 10 rtol of the elliptic-integral value.
  // Index 3 controls q only: its velocities, hence its phase, are not error-controlled, and it
  // misses both bounds by far at the same rtol (period error ~500 rtol); printed, not checked.
  const double theta_bound = 200 * o.rtol, period_bound = 10 * o.rtol;
  struct {
    const char* name;
    const RunResult* r;
    bool checked;
  } runs[] = {{"index3", &r3, false}, {"index2-ggl", &rg, true}, {"index1", &r1, true}};
  for (const auto& [name, r, checked] : runs) {
    const double rel = (measured_period(*r) - period) / period;
    const double dtheta = max_diff(r->x, ref.x);
    std::printf("  %-10s rtol %.0e: %5ld steps %6ld residuals: period rel. error %9.2e (bound %.0e), "
                "max |theta - theta_ref| %.2e rad (bound %.0e), max |Phi| %.2e\n",
                name, o.rtol, r->stats.steps, r->stats.residual_evals, rel, period_bound, dtheta,
                theta_bound, r->max_position_violation);
    if (!checked) continue;
    EXPECT_LT(std::fabs(rel), period_bound) << name;
    EXPECT_LT(dtheta, theta_bound) << name;
  }
}

// --- c. Constraint drift ----------------------------------------------------------------------

TEST(Formulations, ConstraintDrift) {
  const System sys = build_system(testing::pendulum(kMass, kD, kIxx, kTheta0));
  IdaOptions o;
  o.t1 = 30.0;
  o.output_step = 0;
  o.rtol = 1e-6;
  o.atol = 1e-8;
  double qmax = 0;
  for (double x : sys.q0) qmax = std::max(qmax, std::fabs(x));
  const double tol = o.rtol * std::max(1.0, qmax) + o.atol;

  // GGL enforces Phi = 0 and Phi' = 0 at every step: what is left is the Newton iteration's
  // leftover, of the size of the Newton test (weighted corrections under 0.33 of rtol|q| + atol
  // in RMS norm); measured 0.25 to 0.55 tol over builds. Bound: 2 tol.
  Recording<GglDae> ggl(sys);
  ggl.t_end = o.t1;
  const RunResult rg = integrate_model(ggl, o);
  ASSERT_TRUE(rg.stats.ok) << rg.stats.message;
  std::printf("  GGL over %.0f s at rtol %.0e: max |Phi| %.2e (tolerance %.1e), max |Phi'| %.2e, "
              "max | |p| - 1 | %.2e\n",
              o.t1, o.rtol, rg.max_position_violation, tol, ggl.state().statistics.max_velocity_violation, rg.max_norm_drift);
  EXPECT_LT(rg.max_position_violation, 2 * tol);
  EXPECT_LT(ggl.state().statistics.max_velocity_violation, 10 * tol);

  // Index 1: the constraints are integrated, not enforced: Phi and Phi' are driven by each
  // step's local error. With Baumgarte (default alpha = beta = 20/s) they settle at about the
  // tolerance; without (alpha = beta = 0) Phi grows with time.
  Recording<Index1Dae> stab(sys);
  Recording<Index1Dae> plain(sys, 1.0, BaumgarteParameters{0.0, 0.0});
  stab.t_end = plain.t_end = o.t1;
  const RunResult rs = integrate_model(stab, o), rp = integrate_model(plain, o);
  ASSERT_TRUE(rs.stats.ok) << rs.stats.message;
  ASSERT_TRUE(rp.stats.ok) << rp.stats.message;
  for (const auto* d : {&stab, &plain})
    std::printf("  index1 alpha = beta = %2.0f/s: max |Phi| per 10 s %.2e %.2e %.2e, max |Phi'| "
                "per 10 s %.2e %.2e %.2e\n",
                d->baumgarte().alpha, d->phi[0], d->phi[1], d->phi[2], d->phi_dot[0],
                d->phi_dot[1], d->phi_dot[2]);
  // Bounded: every third at the tolerance's level (measured up to 1.5 tol).
  for (int k = 0; k < 3; ++k) EXPECT_LT(stab.phi[k], 5 * tol) << "third " << k;
  // Unstabilized: grows from third to third, to well above the stabilized level.
  EXPECT_GT(plain.phi[1], plain.phi[0]);
  EXPECT_GT(plain.phi[2], plain.phi[1]);
  EXPECT_GT(plain.phi[2], 100 * tol);
}

// --- d. Events ----------------------------------------------------------------------------------

// A wheel on a vertical slider, dropped from 0.2 m above ground contact: it bounces on the tyre
// spring (no damping), so contact and lift-off alternate as events.
constexpr double kWheelMass = 10.0, kTyreStiffness = 1e5, kRadius = 0.3, kDrop = 0.2;
Model bouncing_wheel() {
  Model m;
  m.name = "bouncing_wheel";
  m.bodies.push_back(testing::make_body("wheel", kWheelMass, Vec3::Zero(), Vec3(0.3, 0.5, 0.3)));
  m.joints.push_back(testing::make_joint("slider", kGround, "wheel", Vec3::Zero(), "T3 ", {"z"}));
  testing::add_coordinate(m, "z", kRadius + kDrop);
  ForceSpec w;
  w.name = "tyre";
  w.type = ForceSpec::Type::kWheelContact;
  w.body1 = "wheel";
  w.stiffness = kTyreStiffness;
  w.radius = kRadius;
  w.axis = Vec3(0, 1, 0);
  w.ground = TimeFunction::constant(0.0);
  m.forces.push_back(w);
  return m;
}

// Event times in closed form: free fall to contact, then half a harmonic oscillation about the
// static deflection m g / K (omega = sqrt(K/m)) until lift-off, then a ballistic flight back up
// and down with the same speed; and so on.
std::vector<double> bouncing_wheel_events(double t_end) {
  const double w = std::sqrt(kTyreStiffness / kWheelMass), x0 = kWheelMass * kG / kTyreStiffness;
  const double v0 = std::sqrt(2 * kG * kDrop), amp = std::sqrt(x0 * x0 + v0 * v0 / (w * w));
  const double contact = 2 * (kPi - std::acos(x0 / amp)) / w, flight = 2 * v0 / kG;
  std::vector<double> t{std::sqrt(2 * kDrop / kG)};
  while (true) {
    const double next = t.back() + (t.size() % 2 ? contact : flight);
    if (next > t_end) break;
    t.push_back(next);
  }
  return t;
}

TEST(Formulations, WheelContactEventsMatchClosedForm) {
  const System sys = build_system(bouncing_wheel());
  IdaOptions o;
  o.t1 = 1.5;
  o.output_step = 1e-2;
  o.rtol = 1e-9;
  o.atol = 1e-11;
  const std::vector<double> exact = bouncing_wheel_events(o.t1);
  ASSERT_EQ(exact.size(), 6u);
  Index3Dae i3(sys, 10.0 / (1e-3 * 1e-3));
  GglDae ggl(sys);
  Index1Dae i1(sys);
  const RunResult r3 = integrate_model(i3, o), rg = integrate_model(ggl, o), r1 = integrate_model(i1, o);
  ASSERT_TRUE(r3.stats.ok && rg.stats.ok && r1.stats.ok);
  // Measured at rtol 1e-9: GGL 5e-8 s, index 1 9e-8 s, index 3 2.5e-5 s (its velocities, and
  // so the flight times, are not error-controlled). Bound for GGL and index 1: 1e-6 s.
  struct {
    const char* name;
    const RunResult* r;
    bool checked;
  } runs[] = {{"index3", &r3, false}, {"index2-ggl", &rg, true}, {"index1", &r1, true}};
  for (const auto& [name, r, checked] : runs) {
    double worst = 0;
    for (size_t k = 0; k < std::min(exact.size(), r->stats.event_times.size()); ++k)
      worst = std::max(worst, std::fabs(r->stats.event_times[k] - exact[k]));
    std::printf("  %-10s %zu events (exact %zu), %4ld steps, max |t_event - exact| %.2e s\n", name,
                r->stats.event_times.size(), exact.size(), r->stats.steps, worst);
    EXPECT_EQ(r->stats.restarts, static_cast<long>(exact.size())) << name;
    if (!checked) continue;
    ASSERT_EQ(r->stats.event_times.size(), exact.size()) << name;
    EXPECT_LT(worst, 1e-6) << name;
  }
}

// --- e. A body without inertia ------------------------------------------------------------------

// A four-bar whose coupler is a point mass (no inertia tensor): only the loop decides the
// coupler's Euler parameters. Index 3 keeps what rtol promises on its crank angle, the
// mechanism's one degree of freedom. (Taking such slaved coordinates out of the error test was
// measured and not kept: docs/formulation.md, "Error control".) Ground 2.5 m (not the parallelogram of testing::four_bar, whose change points are singular):
// no link turns fully, the rocker swings through no singular configuration.
Model point_mass_coupler_four_bar() {
  Model m = testing::four_bar(0.4);
  m.joints[2].anchor = Vec3(2.5, 0, 0);
  m.gravity = Vec3(0, -9.81, 0);  // in the plane of motion
  m.bodies[1].inertia.setZero();
  return m;
}

// Assembled, with the planar loop's redundant equations removed.
System assembled(const Model& m) {
  System sys = build_system(m);
  std::vector<double> q = sys.q0;
  AugmentedSolver(sys).positions(q.data(), 0.0, 1e-13, 50);
  sys = without_redundant_constraints(sys, find_redundant_constraints(sys, q.data(), 0.0));
  sys.q0 = q;
  return sys;
}

TEST(Formulations, PointMassCouplerKeepsThePromise) {
  const System sys = assembled(point_mass_coupler_four_bar());
  IdaOptions o;
  o.t1 = 3.0;
  o.output_step = 1e-3;
  const ModelScales scales = model_scales(sys, sys.q0.data(), o.t0, o.t1);
  auto run = [&](const char* name, double rtol, auto&& dae) {
    IdaOptions oo = o;
    oo.rtol = rtol;
    oo.atol = default_position_atol(scales, rtol);
    dae.set_absolute_tolerances(absolute_tolerances(scales, oo.atol));
    const RunResult r = integrate_model(dae, oo);
    EXPECT_TRUE(r.stats.ok) << name << ": " << r.stats.message;
    return r;
  };
  // Reference: index 2 (GGL) at rtol 1e-12, shown converged by GGL at 1e-11.
  GglDae ggl_ref(sys), ggl_check(sys), ggl(sys);
  Index3Dae i3(sys, 1.0, true);
  const RunResult ref = run("reference", 1e-12, ggl_ref), chk = run("check", 1e-11, ggl_check);
  ASSERT_EQ(chk.x.size(), ref.x.size());
  double scale = 0;
  for (double x : ref.x) scale = std::max(scale, std::fabs(x));
  EXPECT_LT(max_diff(chk.x, ref.x), 1e-8 * scale);
  // Index 3 keeps the promise; GGL, which misses it on every case (docs/work-precision.md), is
  // printed (measured: 266 rtol).
  const double rtol = 1e-6;
  const RunResult r3 = run("index3", rtol, i3), rg = run("index2-ggl", rtol, ggl);
  for (const auto* r : {&r3, &rg}) {
    ASSERT_EQ(r->x.size(), ref.x.size());
    const double err = max_diff(r->x, ref.x) / scale;
    std::printf("  %s rtol %.0e: %ld steps, crank angle error %.2e of its scale (%.2f rtol)\n",
                r == &r3 ? "index3" : "index2-ggl", rtol, r->stats.steps, err, err / rtol);
    if (r == &r3) {
      EXPECT_LT(err, 10 * rtol);
    }
  }
}

}  // namespace
}  // namespace mbdae
