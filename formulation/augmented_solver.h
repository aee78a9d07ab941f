// Solves with the augmented matrix  [ D  Phi_q^T ; Phi_q  0 ],  D = M(q) or a diagonal weight,
// on one sparse pattern (one KLU symbolic analysis, numeric refactorizations after that):
//  - accelerations:   M a + Phi_q^T lambda = Q,  Phi_q a = gamma      (consistent a and lambda)
//  - velocities:      min |v - v0|  subject to  Phi_q v = -Phi_t       (velocity projection)
//  - positions:       min |q - q0|  subject to  Phi(q, t) = 0          (Gauss-Newton with line search:
//                     assembly from a guess, and projection of interpolated output)
#pragma once

#include <string>
#include <vector>

#include "core/klu_solver.h"
#include "core/sparse_assembler.h"
#include "formulation/body_point.h"
#include "formulation/mechanics.h"
#include "formulation/system.h"

namespace mbdae {

struct PositionSolveResult {
  bool converged = false;
  int iterations = 0;
  double residual = 0;  // max |Phi|
  std::string worst;    // labels of the most violated constraints when not converged
};

class AugmentedSolver {
 public:
  explicit AugmentedSolver(const System& sys);
  // a (nq) and lambda (nc) at state (q, v, t). False if the matrix is singular; throws
  // SolveError (status "overflow") if the mass matrix, the forces or the result are not finite.
  bool accelerations(const std::vector<char>& modes, const double* q, const double* v, double t,
                     double* a, double* lambda);
  // The accelerations of an output sample, without a factorization where one of a nearby state
  // suffices: iterative refinement x += K0^-1 (b - K x) on the last factorized acceleration
  // matrix K0 (a KluSolver of its own, so that output samples do not change the factorizations
  // the integration's own solves see; K x matrix-free, from the constraint rows: K is not
  // assembled), from x extrapolated through the last output samples (a
  // polynomial in t, its degree chosen from the samples: choose_extrapolation_order), accepted
  // when the estimated error of a and of lambda is below `tolerance` times their max norms (for
  // a, or 1e3 eps of the applied forces' |Q| / m, their rounding); else the direct solve of accelerations(). Samples come in increasing
  // t; a call of accelerations() (a restart, possibly over a discontinuity) starts the
  // extrapolation afresh. docs/performance.md has the measurements.
  bool output_accelerations(const std::vector<char>& modes, const double* q, const double* v,
                            double t, double* a, double tolerance);
  static constexpr int kMaxRefinements = 4;
  // The analysis of that factorization's pattern, outside the step loop (MultibodyDae's
  // consistent_state); until then output_accelerations is accelerations().
  void prepare_output_accelerations();
  struct RefinementStats {  // how output samples were solved (tests, benchmarks)
    long refined = 0, direct = 0, corrections = 0;
  } refinement;
  int extrapolation_points() const { return points_; }  // samples the next extrapolation uses
  // For the sensitivities of an output sample (formulation/twin_sensitivities.cpp): r = b - K x
  // of the acceleration system at (q, v, t) for a given x = [a; lambda]; the last output sample's
  // [a; lambda] if it was at t (else null); and dx with K dx = g, K that sample's matrix (q its
  // positions), on its factorization: one solve where K0 was factored at that sample, else
  // refined as that sample was from the guess in dx (false where the refinement does not
  // converge).
  void acceleration_system_residual(const std::vector<char>& modes, const double* q, const double* v, double t,
                                    const double* x, double* r);
  const double* last_output(double t) const;
  bool output_derivative(const double* q, double t, const double* g, double* dx, double tolerance);
  bool velocities(const double* q, double t, double* v);
  PositionSolveResult positions(double* q, double t, double tol = 1e-13, int max_iter = 100,
                                double regularization = 0.0);
  // 1-norm condition estimate of [I Phi_q^T; Phi_q 0] at q: large near a singular configuration
  // (a lost or gained degree of freedom), about the ratio of extreme singular values of Phi_q.
  double constraint_condition(const double* q);
  // The run's whole turns of rotation coordinates, for the loads (null: nearest the initial values).
  const CoordinateTurns* turns = nullptr;

 private:
  void assemble(const double* q, bool with_mass, double regularization = 0.0);
  // A value pass of assemble() into values_ (checked against the recorded pattern).
  void assemble_values(const double* q, bool with_mass, double regularization = 0.0);
  bool solve_accelerations(KluSolver& klu, const std::vector<char>& modes, const double* q,
                           const double* v, double t);
  void assemble_acceleration_system(const std::vector<char>& modes, const double* q,
                                    const double* v, double t);
  void extrapolation_weights(double t, int points, double* w) const;
  void predict_accelerations(double t, int points, double* x) const;
  void choose_extrapolation_order(double t);
  void acceleration_right_side(const std::vector<char>& modes, const double* q, const double* v, double t);
  void acceleration_residual(const double* q, const double* b, const double* x, double* r) const;
  bool refine_accelerations(const double* q, double t, double tolerance);
  // `what` names x in an overflow's message.
  bool refine(const double* q, const double* b, double* x, double t, double tolerance, const char* what);
  void remember_output(double t);
  void check_overflow(const double* x, int n, double t, const char* what, const char* cause) const;
  const System& sys_;
  std::vector<int> offsets_;
  int nq_, nc_;
  SparseAssembler asm_;
  KluSolver klu_;
  std::vector<double> values_, rhs_, work_, work2_, trial_;
  std::vector<Row14> rows_;    // the constraint Jacobian's rows at an output sample's q
  ConstraintRowsPattern phi_;  // their structural entries (the products with Phi_q)
  KluSolver klu_output_;  // output samples' acceleration matrix K0
  bool output_prepared_ = false;
  bool last_output_direct_ = false;  // the last output sample factored K0 at its own state
  // The last output solutions [a; lambda] and their times (history_[0] the newest), and how many
  // of them the next extrapolation goes through.
  static constexpr int kHistory = 8;
  int history_size_ = 0;
  int points_ = 3;
  static constexpr int kChoiceInterval = 4;  // samples between two choices of points_
  int samples_since_choice_ = 0;
  double history_t_[kHistory] = {};
  std::vector<double> history_[kHistory];
  std::vector<double> scratch_;  // the three candidate extrapolations
};

}  // namespace mbdae
