// What travels across an edit of the mesh: DG fields and refinement levels. Fields: each element
// after it takes the polynomial of its first source before it, re-expressed in its own basis
// (physics/dg/dg_basis.h, transferMatrix): exact for a piece of one element, an extension for an
// element that merged pieces of several. Private to model/.
#pragma once

#include <cstddef>
#include <cstdint>
#include <unordered_set>
#include <vector>

#include <Eigen/Core>

#include "polydg/cut/cut.h"
#include "polydg/physics/dg/dg_basis.h"

namespace polydg {

struct TransferCounts {
  std::size_t exact = 0;     ///< elements from one source
  std::size_t extended = 0;  ///< elements from several (the first one's polynomial)
};

/// `fields` (LinearSystem's layout in `from`, 3 components) on the mesh after the edit, in
/// `to` (the same degree). `counts`, if given, receives how each element took them.
std::vector<Eigen::VectorXd> transferFields(const DgBasis& from,
                                            const std::vector<const Eigen::VectorXd*>& fields,
                                            const DgBasis& to, const ElementLineage& lineage,
                                            TransferCounts* counts = nullptr);

/// `fields` on the mesh after an edit that merged elements, by L2 projection: element e takes
/// sum over its sources s of Q_s^T u_s, Q_s re-expressing e's basis in s's (both orthonormal:
/// the mass matrices are identities). Polynomials of the degree survive exactly, and so do the
/// integrals of the fields against every polynomial of the degree (mass and momentum).
/// Throws std::invalid_argument unless both bases are orthonormal.
std::vector<Eigen::VectorXd> projectFields(const DgBasis& from,
                                           const std::vector<const Eigen::VectorXd*>& fields,
                                           const DgBasis& to, const ElementLineage& lineage);

/// Refinement levels across an edit: each element after it takes the highest level of its
/// sources, plus one if a source is in `refined` (split by the edit).
std::vector<int> levelsAfter(const std::vector<int>& levels, const ElementLineage& lineage,
                             std::size_t elements,
                             const std::unordered_set<std::uint32_t>& refined);

}  // namespace polydg
