// Every analytic derivative against central finite differences: constraint gradients and
// Hessians, applied-force Jacobians, and the full index-3 Newton matrix dF/dy + cj dF/dy'.
#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include "formulation/constraints.h"
#include "formulation/forces.h"
#include "formulation/index3_dae.h"
#include "formulation/mechanics.h"
#include "formulation/system.h"
#include "formulation/tests/test_models.h"

namespace mbdae {
namespace {

using testing::add_coordinate;
using testing::make_body;
using testing::make_joint;

using testing::all_types_model;

using testing::random_state;
using testing::RandomState;

TEST(JacobianFd, ConstraintGradientsAndHessians) {
  const System sys = build_system(all_types_model());
  const RandomState st = random_state(sys, 1);
  // One count per Constraint::Type (kOrientation is the last).
  constexpr int kTypes = static_cast<int>(Constraint::Type::kOrientation) + 1;
  int checked[kTypes] = {};
  for (const Constraint& c : sys.constraints) {
    const LocalState s = gather(st.q.data(), c.bi, c.bj);
    Vec14 x = Vec14::Zero();
    x.head<3>() = s.ri;
    x.segment<4>(3) = s.pi;
    x.segment<3>(7) = s.rj;
    x.tail<4>() = s.pj;
    auto state_of = [&](const Vec14& y) {
      LocalState t;
      t.ri = y.head<3>();
      t.pi = y.segment<4>(3);
      t.rj = y.segment<3>(7);
      t.pj = y.tail<4>();
      return t;
    };
    Row14 rows[3];
    constraint_jacobian(c, s, rows);
    const double w[3] = {0.7, -1.3, 0.4};
    Mat14 h = Mat14::Zero();
    constraint_hessian(c, s, w, h);
    const double eps = 1e-6;
    for (int l = 0; l < 14; ++l) {
      if ((l < 7 && c.bi < 0) || (l >= 7 && c.bj < 0)) continue;
      Vec14 xp = x, xm = x;
      xp[l] += eps;
      xm[l] -= eps;
      double vp[3], vm[3];
      constraint_value(c, state_of(xp), 0.3, vp);
      constraint_value(c, state_of(xm), 0.3, vm);
      Row14 rp[3], rm[3];
      constraint_jacobian(c, state_of(xp), rp);
      constraint_jacobian(c, state_of(xm), rm);
      Row14 hw = Row14::Zero();
      for (int r = 0; r < c.rows(); ++r) {
        const double fd = (vp[r] - vm[r]) / (2 * eps);
        EXPECT_NEAR(rows[r](l), fd, 1e-6 * (1 + std::fabs(fd))) << c.label << " row " << r << " col " << l;
        hw += w[r] * (rp[r] - rm[r]) / (2 * eps);
      }
      for (int k = 0; k < 14; ++k) {
        if ((k < 7 && c.bi < 0) || (k >= 7 && c.bj < 0)) continue;
        EXPECT_NEAR(h(k, l), hw(k), 1e-6 * (1 + std::fabs(hw(k)))) << c.label << " hessian " << k << "," << l;
      }
    }
    checked[static_cast<int>(c.type)]++;
  }
  for (int t = 0; t < kTypes; ++t) EXPECT_GT(checked[t], 0) << "constraint type " << t << " not exercised";
}

// coordinate_slope is coordinate_jet without the Hessian: the same value and gradient, bit for
// bit, for every joint coordinate of the model (rotations about each axis, translations) at
// several states.
TEST(JacobianFd, CoordinateSlopeIsTheJetsValueAndGradient) {
  const System sys = build_system(all_types_model());
  int checked = 0, rotations = 0;
  for (int seed = 1; seed <= 4; ++seed) {
    const RandomState st = random_state(sys, seed);
    for (const JointCoordinate& jc : sys.coordinates) {
      if (jc.merged) continue;
      const LocalState s = gather(st.q.data(), jc.function.body_parent, jc.function.body_child);
      const ScalarJet jet = coordinate_jet(jc.function, s);
      const ScalarSlope slope = coordinate_slope(jc.function, s);
      EXPECT_EQ(std::memcmp(&jet.value, &slope.value, sizeof(double)), 0) << jc.name;
      EXPECT_EQ(std::memcmp(jet.grad.data(), slope.grad.data(), 14 * sizeof(double)), 0) << jc.name;
      ++checked;
      rotations += jc.function.rotation ? 1 : 0;
    }
  }
  EXPECT_GT(checked, 8);
  EXPECT_GT(rotations, 0);
  EXPECT_LT(rotations, checked);
}

// gamma = -d2Phi/dt2 along q(t) = q + v t (q'' = 0), by a central second difference in time.
TEST(JacobianFd, AccelerationRightSide) {
  const System sys = build_system(all_types_model());
  const RandomState st = random_state(sys, 4);
  const std::vector<int> off = constraint_offsets(sys);
  const int nc = off.back(), nq = sys.nq();
  std::vector<double> gamma(nc), phi_t(nc), pp(nc), p0(nc), pm(nc), qp(nq), qm(nq);
  const double t = 0.37, eps = 1e-4;
  constraint_rates(sys, off, st.q.data(), st.v.data(), t, phi_t.data(), gamma.data());
  for (int i = 0; i < nq; ++i) {
    qp[i] = st.q[i] + eps * st.v[i];
    qm[i] = st.q[i] - eps * st.v[i];
  }
  constraint_values(sys, off, qp.data(), t + eps, pp.data());
  constraint_values(sys, off, st.q.data(), t, p0.data());
  constraint_values(sys, off, qm.data(), t - eps, pm.data());
  for (size_t k = 0; k < sys.constraints.size(); ++k)
    for (int r = 0; r < sys.constraints[k].rows(); ++r) {
      const int i = off[k] + r;
      const double fd = -(pp[i] - 2 * p0[i] + pm[i]) / (eps * eps);
      EXPECT_NEAR(gamma[i], fd, 1e-5 * (1 + std::fabs(fd))) << sys.constraints[k].label;
    }
}

TEST(JacobianFd, ForceJacobians) {
  const System sys = build_system(all_types_model());
  const RandomState st = random_state(sys, 2);
  ASSERT_EQ(sys.forces.size(), 5u);
  for (const Force& f : sys.forces) {
    const testing::ForceCheck check =
        testing::check_force_jacobians(f, gather(st.q.data(), f.bi, f.bj), gather(st.v.data(), f.bi, f.bj));
    EXPECT_GT(check.force_norm, 0) << f.name;
    EXPECT_LT(check.worst, 1e-5) << check.where;
  }
}

TEST(JacobianFd, Index3NewtonMatrix) {
  const System sys = build_system(all_types_model());
  Index3Dae dae(sys, 7.0);
  const testing::NewtonCheck check = testing::check_newton_matrix(dae, random_state(sys, 3), false);
  EXPECT_LT(check.worst, 1e-6) << check.where;
  RecordProperty("worst_relative_error", testing::sci(check.worst));
}

}  // namespace
}  // namespace mbdae
