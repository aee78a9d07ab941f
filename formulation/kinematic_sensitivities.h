// Sensitivities of a kinematic sample (every degree of freedom driven, so that Phi_q is square)
// by the implicit function theorem, without integrating them (docs/sensitivities.md):
//
//   Phi(q, t; p) = 0          =>  Phi_q s_q = -dPhi/dp
//   Phi_q v + Phi_t = 0       =>  Phi_q s_v = -[(H v) s_q + d(Phi_q v + Phi_t)/dp]
//
// at the sample's consistent (q, v), (H v) s_q the rows' Hessians along s_q (exact: the
// constraint library's closed forms, else its row Hessians; Phi_t depends on t alone).
// Phi_q is factorized once per sample (KLU, its pattern analysed once), and the right sides of
// all parameters are solved together, positions then velocities (klu_solve_many: a pass over
// the factors per four parameters). dPhi/dp and d(Phi_q v + Phi_t)/dp are central differences of the twin models'
// constraints, over the constraints the parameter reaches (formulation/parameter_reach.h; all
// of them where it changes the model's structure). The sensors' sensitivities are central
// differences of the twins' sensors at (q +- d s_q, v +- d s_v).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "core/klu_solver.h"
#include "core/sparse_assembler.h"
#include "formulation/parameter_reach.h"
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
  void position_side(size_t i, const double* q, double t, double* rhs);
  void velocity_sides(const double* q, const double* v, double t);  // into sv_, from sq_
  const System& run_;
  std::vector<std::pair<const System*, const System*>> twins_;
  std::vector<double> deltas_;
  std::vector<ParameterReach> reach_;
  std::vector<int> offsets_;
  SparseAssembler asm_;  // Phi_q's pattern, recorded once; its values assembled into values_
  std::vector<double> values_;
  KluSolver klu_;
  // Per parameter: s_q and s_v (the right sides, solved in place), n values each.
  std::vector<double> sq_, sv_;
  std::vector<double*> sq_cols_, sv_cols_;
  std::vector<double> a_, b_, qt_, vt_, yp_, ym_;
  std::string failure_;
};

}  // namespace mbdae
