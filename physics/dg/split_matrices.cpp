// The layout of the split local matrices (assembly.h): made for a mesh, and updated in place
// after an edit of it so that only the rows the edit changed are computed again.
#include <algorithm>
#include <numeric>

#include "physics/dg/assembly.h"

namespace polydg {

namespace {

/// Room for the blocks an edit's update appends: the arrays are reserved a quarter larger
/// (address space only until written), so that updates rarely move them.
constexpr std::size_t kSpareQuarters = 5;

template <class T>
void reserveSpare(UninitializedVector<T>& v, std::size_t size) {
  v.reserve(size / 4 * kSpareQuarters + 1);
  v.resize(size);
}

/// Every element's blocks in element order: coupling blocks (greaterNeighbours()) and
/// lifting blocks (neighbours but itself).
void layOut(SplitLocalMatrices& split, std::vector<std::vector<std::uint32_t>> neighbours, int n,
            bool bz) {
  const std::size_t ne = neighbours.size();
  const int bs = 3 * n;
  const std::size_t bb = static_cast<std::size_t>(bs) * static_cast<std::size_t>(bs);
  std::vector<std::size_t> couplingStart(ne + 1, 0);
  split.neighbourStart.assign(ne + 1, 0);
  for (std::size_t i = 0; i < ne; ++i) {
    couplingStart[i + 1] = couplingStart[i] + greaterNeighbours(neighbours, i);
    split.neighbourStart[i + 1] = split.neighbourStart[i] + neighbours[i].size() - 1;
  }
  for (LocalMatrices* local : {&split.rowStrain, &split.columnStrain, &split.jumps}) {
    local->functions = n;
    local->blockSize = bs;
    local->componentDiagonalCoupling = bz;
    local->neighbours = neighbours;
    local->couplingStart = couplingStart;
    reserveSpare(local->diagonal, ne * bb);
    reserveSpare(local->coupling, couplingStart[ne] * bb);
  }
  reserveSpare(split.neighbourLifting, split.neighbourStart[ne] * bb);
  reserveSpare(split.dirichletTrial, ne * bb);
  reserveSpare(split.dirichletTest, ne * bb);
}

}  // namespace

SplitLocalMatrices splitLocalMatrices(const PolyMesh& mesh, const DgBasis& basis,
                                      const MomentCache& moments, const FaceRoles& roles,
                                      const FormCoefficients& form) {
  SplitLocalMatrices split;
  layOut(split, coupledNeighbours(mesh, roles), basis.size(), form.method == Method::BZ);
  std::vector<std::uint32_t> all(mesh.numElements());
  std::iota(all.begin(), all.end(), 0u);
  writeSplitRows(split, mesh, basis, moments, roles, form, all);
  return split;
}

std::size_t updateSplitLocalMatrices(SplitLocalMatrices& split, const PolyMesh& mesh,
                                     const DgBasis& basis, const MomentCache& moments,
                                     const FaceRoles& roles, const FormCoefficients& form,
                                     const std::vector<char>& fresh) {
  const std::size_t ne = mesh.numElements(), before = split.jumps.neighbours.size();
  std::vector<std::vector<std::uint32_t>> neighbours = coupledNeighbours(mesh, roles);
  std::vector<std::uint32_t> redo;
  std::size_t couplingsUsed = 0, couplingsStored = split.jumps.couplingStart[before];
  std::size_t liftingUsed = 0, liftingStored = split.neighbourStart[before];
  for (std::size_t i = 0; i < ne; ++i) {
    const auto& b = neighbours[i];
    bool again = i >= before || fresh[i] || b != split.jumps.neighbours[i];
    for (std::size_t k = 0; k < b.size() && !again; ++k) again = fresh[b[k]] != 0;
    couplingsUsed += greaterNeighbours(neighbours, i);
    liftingUsed += b.size() - 1;
    if (!again) continue;
    redo.push_back(static_cast<std::uint32_t>(i));
    couplingsStored += greaterNeighbours(neighbours, i);
    liftingStored += b.size() - 1;
  }
  if (couplingsStored > 2 * couplingsUsed || liftingStored > 2 * liftingUsed) {
    split = splitLocalMatrices(mesh, basis, moments, roles, form);
    return ne;
  }
  const int bs = split.jumps.blockSize;
  const std::size_t bb = static_cast<std::size_t>(bs) * static_cast<std::size_t>(bs);
  // The recomputed elements' blocks after those stored.
  std::vector<std::size_t> couplingStart = split.jumps.couplingStart;
  couplingStart.resize(ne + 1);
  split.neighbourStart.resize(ne + 1);
  std::size_t coupling = split.jumps.couplingStart[before], lifting = split.neighbourStart[before];
  for (std::uint32_t i : redo) {
    couplingStart[i] = coupling;
    coupling += greaterNeighbours(neighbours, i);
    split.neighbourStart[i] = lifting;
    lifting += neighbours[i].size() - 1;
  }
  couplingStart[ne] = coupling;
  split.neighbourStart[ne] = lifting;
  for (LocalMatrices* local : {&split.rowStrain, &split.columnStrain, &split.jumps}) {
    local->neighbours = neighbours;
    local->couplingStart = couplingStart;
    local->diagonal.resize(ne * bb);
    local->coupling.resize(coupling * bb);
  }
  split.neighbourLifting.resize(lifting * bb);
  split.dirichletTrial.resize(ne * bb);
  split.dirichletTest.resize(ne * bb);
  writeSplitRows(split, mesh, basis, moments, roles, form, redo);
  return redo.size();
}

}  // namespace polydg
