// The smoother of the p-multigrid V-cycle (physics/solvers/p_multigrid.h), set up level by level:
// the inverses of its groups' diagonal blocks and the colouring that lets the groups of one
// colour be updated in parallel.
#pragma once

#include <vector>

#include "physics/solvers/multigrid_level.h"

namespace polydg::multigrid {

/// Inverts the diagonal blocks of `level`'s smoother groups, stored in the order the sweeps
/// visit the groups (colour by colour, once `level.colours` is set); false if one is not
/// positive definite.
bool invertGroups(Level& level);

/// The colouring of `level`'s smoother groups (two groups are neighbours if a stored block
/// couples one of each).
std::vector<std::vector<int>> colourGroups(const Level& level);

/// The blocks of `level` in the order its smoother visits them: colour by colour, group by
/// group.
std::vector<int> sweepOrder(const Level& level);

/// Every block of `level` a group of its own.
BlockGroups singleBlocks(int blocks);

}  // namespace polydg::multigrid
