#include "core/klu_linear_solver.h"

#include <nvector/nvector_serial.h>
#include <sunmatrix/sunmatrix_sparse.h>

#include <cstring>
#include <vector>

#include "core/klu_solver.h"
#include "core/sundials_compat.h"

namespace mbdae {
namespace {

// The sensitivities' right-hand sides announced by klu_linear_solver_expect_batch: `next` is the
// one IDAS's next solve should name; all were solved together at the first.
struct Batch {
  std::vector<double*> rhs;
  size_t next = 0;
};

struct Content {
  KluSolver klu;
  int last_flag = 0;
  Batch batch;
};
Content* content(SUNLinearSolver s) { return static_cast<Content*>(s->content); }

SUNLinearSolver_Type get_type(SUNLinearSolver) { return SUNLINEARSOLVER_DIRECT; }
SUNLinearSolver_ID get_id(SUNLinearSolver) { return SUNLINEARSOLVER_CUSTOM; }
int initialize(SUNLinearSolver) { return kLinSolSuccess; }

int setup(SUNLinearSolver s, SUNMatrix a) {
  Content* c = content(s);
  const bool ok = c->klu.factor(SUNSparseMatrix_Data(a));
  c->last_flag = ok ? 0 : 1;
  return ok ? kLinSolSuccess : SUNLS_LUFACT_FAIL;  // recoverable: IDA reduces the step
}

int solve(SUNLinearSolver s, SUNMatrix, N_Vector x, N_Vector b, sunrealtype) {
  Content* c = content(s);
  const sunindextype n = N_VGetLength(b);
  double* bd = N_VGetArrayPointer(b);
  Batch& batch = c->batch;
  bool ok = true;
  if (batch.next < batch.rhs.size() && bd == batch.rhs[batch.next]) {
    // One of the announced right-hand sides, in IDAS's order: the first solves them all.
    if (batch.next++ == 0) ok = c->klu.solve_many(batch.rhs.data(), static_cast<int>(batch.rhs.size()));
    std::memcpy(N_VGetArrayPointer(x), bd, n * sizeof(double));
  } else {
    batch.rhs.clear();  // any other solve ends the batch
    std::memcpy(N_VGetArrayPointer(x), bd, n * sizeof(double));
    ok = c->klu.solve(N_VGetArrayPointer(x));
  }
  c->last_flag = ok ? 0 : 1;
  return ok ? kLinSolSuccess : kLinSolFailUnrecoverable;
}

}  // namespace

SUNLinearSolver new_direct_linear_solver(SUNContext ctx, const DirectSolverOps& ops, void* content) {
  SUNLinearSolver s = SUNLinSolNewEmpty(ctx);
  s->ops->gettype = get_type;
  s->ops->getid = get_id;
  s->ops->initialize = initialize;
  s->ops->setup = ops.setup;
  s->ops->solve = ops.solve;
  s->ops->lastflag = ops.last_flag;
  s->ops->free = ops.free;
  s->content = content;
  return s;
}

SUNLinearSolver make_klu_linear_solver(const CscPattern& pattern, SUNContext ctx) {
  auto* c = new Content;
  c->klu.analyze(pattern);  // symbolic analysis once per pattern
  return new_direct_linear_solver(ctx, setup, solve, c);
}

void klu_linear_solver_expect_batch(SUNLinearSolver s, double* const* rhs, int count) {
  if (!s || s->ops->solve != solve) return;
  Batch& batch = content(s)->batch;
  batch.rhs.assign(rhs, rhs + (count > 1 ? count : 0));  // capacity kept: no allocation per step
  batch.next = 0;
}

int klu_linear_solver_fresh_factorizations(SUNLinearSolver s) {
  return content(s)->klu.full_factorizations();
}

}  // namespace mbdae
