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
  bool velocities(const double* q, double t, double* v);
  PositionSolveResult positions(double* q, double t, double tol = 1e-13, int max_iter = 100,
                                double regularization = 0.0);
  // 1-norm condition estimate of [I Phi_q^T; Phi_q 0] at q: large near a singular configuration
  // (a lost or gained degree of freedom), about the ratio of extreme singular values of Phi_q.
  double constraint_condition(const double* q);

 private:
  void assemble(const double* q, bool with_mass, double regularization = 0.0);
  // A value pass of assemble() into values_ (checked against the recorded pattern).
  void assemble_values(const double* q, bool with_mass, double regularization = 0.0);
  void check_overflow(const double* x, int n, double t, const char* what, const char* cause) const;
  const System& sys_;
  std::vector<int> offsets_;
  int nq_, nc_;
  SparseAssembler asm_;
  KluSolver klu_;
  std::vector<double> values_, rhs_, work_, work2_, trial_;
};

}  // namespace mbdae
