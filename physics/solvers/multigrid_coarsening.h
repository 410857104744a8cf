// The coarse matrices of the p-multigrid's degree levels (physics/solvers/p_multigrid.h): principal
// submatrices on the lower-degree functions, from a CSR matrix or from block rows; and the split
// of a degree-0 matrix by displacement component for the coarsest factorization.
#pragma once

#include <vector>

#include "physics/solvers/multigrid_level.h"

namespace polydg::multigrid {

/// The principal submatrix of `fine` (n functions per component) on the DOFs of the first
/// `nc` functions of each component, renumbered (e, d, i) -> e 3 nc + d nc + i.
SpMat restrictMatrix(const SpMat& fine, int n, int nc);

/// The principal submatrix of `fine` on the first `nc` functions of each component, as
/// restrictMatrix() gives it, from block rows.
SpMat restrictBlocks(const BlockRows<double>& fine, int nc);

/// The level-0 matrix `a` (unknown (e, d) at 3 e + d) split by displacement component, if
/// no entry couples two components: `parts` = S_0, S_1, S_2 (one unknown per element), or
/// just S_0 when the three are bitwise equal (a = I_3 (x) S_0). Returns false (parts empty)
/// if components are coupled. BZ's level 0 is always I_3 (x) S: its only terms, the penalty
/// mu eta_F [u].[v], treat the components alike. IP's lifting adds lambda n n^T per face,
/// which couples components unless every coupled face is axis-aligned (hex grids: then
/// uncoupled but different).
bool splitComponents(const SpMat& a, std::vector<SpMat>& parts);

}  // namespace polydg::multigrid
