// The constraint Jacobian's transpose with every row scaled to unit norm, as a CHOLMOD sparse
// matrix for SuiteSparseQR: (D Phi_q)^T, nq x nc, column j = row j of Phi_q / |row j| (a zero
// row gives an empty column). Row scaling makes the QR's rank decision and singular values
// independent of the equations' units (lengths, angles' cosines, Euler norms). Used by the
// redundancy analysis (formulation/redundancy.h) and the singular-configuration diagnosis
// (formulation/singularity.h).
#pragma once

#include <cholmod.h>

#include "formulation/system.h"

namespace mbdae {

// Allocated with cc (cholmod_l_*); the caller frees it with cholmod_l_free_sparse.
cholmod_sparse* normalized_constraint_jacobian_transpose(const System& sys, const double* q, cholmod_common* cc);

}  // namespace mbdae
