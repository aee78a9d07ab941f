// Sensitivities of a kinematic sample (every degree of freedom driven, so that Phi_q is square)
// by the implicit function theorem, without integrating them (docs/sensitivities.md):
//
//   Phi(q, t; p) = 0          =>  Phi_q s_q = -dPhi/dp
//   Phi_q v + Phi_t = 0       =>  Phi_q s_v = -[d(Phi_q v + Phi_t)/dq s_q + d(Phi_q v + Phi_t)/dp]
//
// at the sample's consistent (q, v). Phi_q is factorized once per sample (Eigen's SparseLU, its
// pattern analysed once); the right sides are central differences over the twin models'
// constraint values (at q, and at q +- d s_q with v), so each parameter costs two
// back-substitutions and a few constraint evaluations; the sensors' sensitivities are central
// differences of the twins' sensors at (q +- d s_q, v +- d s_v).
#pragma once

#include <Eigen/SparseLU>

#include <string>
#include <utility>
#include <vector>

#include "core/sparse_assembler.h"
#include "formulation/system.h"

namespace mbdae {

class KinematicSensitivities {
 public:
  // `twins[i]` are the models at p_i + d_i and p_i - d_i, `deltas[i]` that d_i.
  KinematicSensitivities(const System& run, std::vector<std::pair<const System*, const System*>> twins,
                         std::vector<double> deltas);
  // Whether the implicit function theorem applies: Phi_q square (no free degree of freedom).
  static bool applicable(const System& sys) { return sys.nq() == sys.num_constraint_rows(); }
  // out[i][k] = d(sensor k)/d(p_i), dq[i] = dq/dp_i at the sample (q, v, t). False, with
  // failure(), where Phi_q is singular.
  bool sensors(const std::vector<char>& modes, const CoordinateTurns* turns, const double* q, const double* v,
               double t, std::vector<std::vector<double>>& out, std::vector<std::vector<double>>& dq);
  const std::string& failure() const { return failure_; }

 private:
  bool factorize(const double* q);
  const System& run_;
  std::vector<std::pair<const System*, const System*>> twins_;
  std::vector<double> deltas_;
  std::vector<int> offsets_;
  SparseAssembler asm_;  // Phi_q's pattern, recorded once; its values assembled into phi_q_
  Eigen::SparseMatrix<double> phi_q_;
  Eigen::SparseLU<Eigen::SparseMatrix<double>> lu_;
  Eigen::VectorXd rhs_, sq_, sv_;
  std::vector<double> a_, b_, qt_, vt_, yp_, ym_;
  std::string failure_;
};

}  // namespace mbdae
