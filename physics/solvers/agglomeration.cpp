#include "physics/solvers/agglomeration.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <Eigen/Dense>

#include "physics/dg/block_rows.h"
#include "polydg/integrate/monomials.h"
#include "polydg/mesh/geometry.h"
#include "polydg/physics/dg/dg_basis.h"
#include "util/union_find.h"

namespace polydg {

namespace {

using SpMat = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

/// Lattice comparisons (extents, planes) are within this fraction of a cell length: far above
/// the round-off of slicing (ulps of the model's size per coordinate), far below any feature
/// a surface or a cut makes on purpose.
constexpr double kLatticeTolerance = 1e-6;

/// The share of elements that must each lie in one cell for a lattice to be used. Not all:
/// a sliver merged into its neighbour across a cell face makes one element of two cells, and
/// slicing merges many (about one element in ten of a sliced model spans two cells); with no
/// lattice few boxes share the one extent and origin found.
constexpr double kLatticeShare = 0.5;

/// Monomial combinations of a group whose Gram eigenvalue over its blocks' weights
/// (Agglomeration::spans) is below this fraction of the largest are not kept: on the blocks
/// they are under 1e-4 of the best-represented combination, which a coarse correction cannot
/// use and which would make the coarse matrix nearly singular. Where the blocks tell a
/// combination apart at all, on a sliced mesh, its eigenvalue is far larger; where they do
/// not (blocks on a line), it is round-off, about 1e-16 of the largest.
constexpr double kSpanTolerance = 1e-8;

/// Cells per axis at most (indices fit an int with room for the box arithmetic).
constexpr double kMaxLatticeCells = 1 << 24;

/// Smallest |cos| of the angle between the axis and the line joining two centres for a pair
/// to form along that axis (60 degrees).
constexpr double kMinAlignment = 0.5;

/// Groups the blocks into agglomerates: three rounds of greedy pairing of neighbours (blocks,
/// then pairs, then pairs of pairs), round k pairing along axis k, each group with its
/// unpaired neighbour best aligned with the axis (at least kMinAlignment; groups in order,
/// ties to the first neighbour). On a hex grid: 2 x 2 x 2 blocks. Groups are centred at the
/// mean of their blocks' centres. Returns each block's agglomerate; `count` their number.
std::vector<int> pairAlongAxes(const BlockRows<double>& rows,
                               const std::vector<Eigen::Vector3d>& centres, int& count) {
  const int nb = static_cast<int>(rows.start.size()) - 1;
  std::vector<int> group(static_cast<std::size_t>(nb));
  for (int b = 0; b < nb; ++b) group[static_cast<std::size_t>(b)] = b;
  std::vector<Eigen::Vector3d> centre = centres;
  std::vector<int> weight(static_cast<std::size_t>(nb), 1);
  int groups = nb;
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<std::vector<int>> adjacent(static_cast<std::size_t>(groups));
    for (int b = 0; b < nb; ++b)
      for (int k = rows.start[static_cast<std::size_t>(b)];
           k < rows.start[static_cast<std::size_t>(b) + 1]; ++k)
        if (const int f = rows.element[static_cast<std::size_t>(k)];
            group[static_cast<std::size_t>(f)] != group[static_cast<std::size_t>(b)])
          adjacent[static_cast<std::size_t>(group[static_cast<std::size_t>(b)])].push_back(
              group[static_cast<std::size_t>(f)]);
    std::vector<int> merged(static_cast<std::size_t>(groups), -1);
    std::vector<Eigen::Vector3d> nextCentre;
    std::vector<int> nextWeight;
    for (int g = 0; g < groups; ++g) {
      if (merged[static_cast<std::size_t>(g)] >= 0) continue;
      std::vector<int>& adj = adjacent[static_cast<std::size_t>(g)];
      std::sort(adj.begin(), adj.end());
      int best = -1;
      double bestAlignment = kMinAlignment;
      for (std::size_t k = 0; k < adj.size(); ++k) {
        const int h = adj[k];
        if ((k > 0 && adj[k - 1] == h) || merged[static_cast<std::size_t>(h)] >= 0) continue;
        const Eigen::Vector3d v =
            centre[static_cast<std::size_t>(h)] - centre[static_cast<std::size_t>(g)];
        const double length = v.norm();
        if (!(length > 0.0)) continue;
        const double alignment = std::abs(v[axis]) / length;
        if (alignment >= bestAlignment && (best < 0 || alignment > bestAlignment)) {
          best = h;
          bestAlignment = alignment;
        }
      }
      const int id = static_cast<int>(nextCentre.size());
      merged[static_cast<std::size_t>(g)] = id;
      Eigen::Vector3d sum =
          weight[static_cast<std::size_t>(g)] * centre[static_cast<std::size_t>(g)];
      int w = weight[static_cast<std::size_t>(g)];
      if (best >= 0) {
        merged[static_cast<std::size_t>(best)] = id;
        sum += weight[static_cast<std::size_t>(best)] * centre[static_cast<std::size_t>(best)];
        w += weight[static_cast<std::size_t>(best)];
      }
      nextCentre.push_back(sum / w);
      nextWeight.push_back(w);
    }
    for (int& g : group) g = merged[static_cast<std::size_t>(g)];
    centre = std::move(nextCentre);
    weight = std::move(nextWeight);
    groups = static_cast<int>(centre.size());
  }
  count = groups;
  return group;
}

/// floor(c / 2) per component.
Eigen::Vector3i halved(const Eigen::Vector3i& c) {
  Eigen::Vector3i h;
  for (int l = 0; l < 3; ++l) h[l] = c[l] >= 0 ? c[l] / 2 : -((1 - c[l]) / 2);
  return h;
}

/// Whether stored slot k of `rows` has a nonzero entry.
bool coupledSlot(const BlockRows<double>& rows, int k) {
  const std::size_t slot = static_cast<std::size_t>(k);
  const std::size_t count = rows.diagonal[slot] ? static_cast<std::size_t>(3 * rows.n * rows.n)
                                                : static_cast<std::size_t>(rows.bs * rows.bs);
  const double* v = rows.values.data() + rows.offset[slot];
  return std::any_of(v, v + count, [](double x) { return x != 0.0; });
}

/// Groups the blocks by 2 x 2 x 2 boxes of their cells, each box split into the connected
/// components of the blocks' coupling inside it, except that no group takes two blocks of
/// one cell; groups in the order of their first block. Returns each block's group; `boxes`
/// gets each group's box (the cells halved).
/// Two blocks of one cell are pieces that a cut (or the surface) separates in it, coupled by
/// no face; a component can still join them around the end of a finite cut inside the box,
/// and one polynomial on both sides then cannot open the slit, which becomes the V-cycle's
/// slowest mode, at every agglomeration level (a group of groups joins two groups of one box
/// the same way). Pairs of coupled blocks are joined in the order of their blocks, each
/// unless their sets share a cell (a set holds a few cells: up to 8, and merged slivers).
std::vector<int> groupByCells(const BlockRows<double>& rows,
                              const std::vector<Eigen::Vector3i>& cells,
                              std::vector<Eigen::Vector3i>& boxes) {
  const int nb = static_cast<int>(rows.start.size()) - 1;
  std::vector<Eigen::Vector3i> box(static_cast<std::size_t>(nb));
  for (std::size_t b = 0; b < box.size(); ++b) box[b] = halved(cells[b]);
  UnionFind components(static_cast<std::size_t>(nb));
  // The cells of each set, at its root.
  std::vector<std::vector<Eigen::Vector3i>> cellsOf(static_cast<std::size_t>(nb));
  for (std::size_t b = 0; b < cellsOf.size(); ++b) cellsOf[b].push_back(cells[b]);
  auto shareACell = [&](std::uint32_t r, std::uint32_t t) {
    for (const Eigen::Vector3i& c : cellsOf[r])
      if (std::find(cellsOf[t].begin(), cellsOf[t].end(), c) != cellsOf[t].end()) return true;
    return false;
  };
  for (int b = 0; b < nb; ++b)
    for (int k = rows.start[static_cast<std::size_t>(b)];
         k < rows.start[static_cast<std::size_t>(b) + 1]; ++k) {
      const int f = rows.element[static_cast<std::size_t>(k)];
      if (f >= b || box[static_cast<std::size_t>(f)] != box[static_cast<std::size_t>(b)] ||
          !coupledSlot(rows, k))
        continue;
      const std::uint32_t rf = components.find(static_cast<std::uint32_t>(f));
      const std::uint32_t rb = components.find(static_cast<std::uint32_t>(b));
      if (rf == rb || shareACell(rf, rb)) continue;
      components.unite(rf, rb);  // rb represents the union
      cellsOf[rb].insert(cellsOf[rb].end(), cellsOf[rf].begin(), cellsOf[rf].end());
      std::vector<Eigen::Vector3i>().swap(cellsOf[rf]);
    }
  std::vector<int> id(static_cast<std::size_t>(nb), -1), group(static_cast<std::size_t>(nb));
  boxes.clear();
  for (int b = 0; b < nb; ++b) {
    int& g = id[components.find(static_cast<std::uint32_t>(b))];
    if (g < 0) {
      g = static_cast<int>(boxes.size());
      boxes.push_back(box[static_cast<std::size_t>(b)]);
    }
    group[static_cast<std::size_t>(b)] = g;
  }
  return group;
}

/// Per coarse row block C: its coarse column blocks B <= C (in order met) and P_CB.
struct Panels {
  std::vector<int> columns;
  std::vector<double> panel;  // block k at (3 n)^2 k, column-major
};

/// The panels of P^T A P for NF functions per component of the blocks and N of the groups (a
/// fixed size: these products are the agglomeration levels' setup cost).
template <int NF, int N>
void galerkinPanels(const Agglomeration& fine, const BlockRows<double>& rows,
                    std::vector<Panels>& panels) {
  const int coarseBlocks = fine.groups();
  constexpr int bs = 3 * N, bs2 = bs * bs;
  constexpr std::size_t weights = NF * N;
  using Weights = Eigen::Matrix<double, NF, N>;
  using FineBlock = Eigen::Matrix<double, 3 * NF, 3 * NF>;
  using FineDiagonal = Eigen::Matrix<double, NF, NF>;
  using Block = Eigen::Matrix<double, bs, bs>;
  tbb::enumerable_thread_specific<std::vector<int>> slots(
      std::vector<int>(static_cast<std::size_t>(coarseBlocks), -1));
  tbb::parallel_for(0, coarseBlocks, [&](int cc) {
    std::vector<int>& slot = slots.local();
    Panels& row = panels[static_cast<std::size_t>(cc)];
    row.columns.reserve(8);
    row.panel.reserve(8 * bs2);
    for (int k = fine.childStart[static_cast<std::size_t>(cc)];
         k < fine.childStart[static_cast<std::size_t>(cc) + 1]; ++k) {
      const int e = fine.children[static_cast<std::size_t>(k)];
      const Eigen::Map<const Weights> we(fine.weights.data() +
                                         weights * static_cast<std::size_t>(e));
      for (int t = rows.start[static_cast<std::size_t>(e)];
           t < rows.start[static_cast<std::size_t>(e) + 1]; ++t) {
        const std::size_t sl = static_cast<std::size_t>(t);
        const int f = rows.element[sl];
        const int cb = fine.parent[static_cast<std::size_t>(f)];
        if (cb > cc) continue;  // upper triangle: mirrored later
        int s = slot[static_cast<std::size_t>(cb)];
        if (s < 0) {
          s = static_cast<int>(row.columns.size());
          slot[static_cast<std::size_t>(cb)] = s;
          row.columns.push_back(cb);
          row.panel.resize(row.panel.size() + bs2, 0.0);
        }
        const Eigen::Map<const Weights> wf(fine.weights.data() +
                                           weights * static_cast<std::size_t>(f));
        Eigen::Map<Block> target(row.panel.data() + static_cast<std::size_t>(s) * bs2);
        const double* values = rows.values.data() + rows.offset[sl];
        if (rows.diagonal[sl]) {
          for (int d = 0; d < 3; ++d)
            target.template block<N, N>(d * N, d * N).noalias() +=
                we.transpose() * (Eigen::Map<const FineDiagonal>(values + d * NF * NF) * wf);
          continue;
        }
        const Eigen::Map<const FineBlock> block(values);
        for (int dr = 0; dr < 3; ++dr)
          for (int dc = 0; dc < 3; ++dc)
            target.template block<N, N>(dr * N, dc * N).noalias() +=
                we.transpose() * (block.template block<NF, NF>(dr * NF, dc * NF) * wf);
      }
    }
    for (int c : row.columns) slot[static_cast<std::size_t>(c)] = -1;
  });
}

}  // namespace

BlockRows<double> galerkinBlocks(const Agglomeration& fine, const BlockRows<double>& rows) {
  if (rows.n != fine.blockFunctions)
    throw std::invalid_argument("galerkinBlocks: the rows' functions do not match the groups'");
  const int coarseBlocks = fine.groups();
  const int n = fine.functions, bs = 3 * n, bs2 = bs * bs;
  std::vector<Panels> panels(static_cast<std::size_t>(coarseBlocks));
  if (n == 4)
    galerkinPanels<4, 4>(fine, rows, panels);
  else if (fine.blockFunctions == 4)
    galerkinPanels<4, 10>(fine, rows, panels);
  else
    galerkinPanels<10, 10>(fine, rows, panels);
  // Each stored block (C, B) of coarse row block C: P_CB from C's panels for B <= C, P_BC^T
  // from B's panels for B > C. A block coupled between displacement components (every
  // diagonal block, and IP's off-diagonal ones) is stored whole, an uncoupled one (BZ's) as
  // its three diagonal n x n parts. Written straight from the panels: a CSR matrix (made
  // full by Eigen's selfadjointView) and the block rows converted from it cost as much
  // again as the panels, and the CSR matrix would set the setup's peak memory.
  struct Source {
    int block;  // B
    int slot;   // its slot in the panels of C (B <= C) or of B (B > C)
    bool coupled;
  };
  std::vector<std::vector<Source>> sources(static_cast<std::size_t>(coarseBlocks));
  std::vector<std::vector<std::uint8_t>> coupledSlots(static_cast<std::size_t>(coarseBlocks));
  tbb::parallel_for(0, coarseBlocks, [&](int cc) {
    const Panels& row = panels[static_cast<std::size_t>(cc)];
    std::vector<std::uint8_t>& coupled = coupledSlots[static_cast<std::size_t>(cc)];
    coupled.assign(row.columns.size(), 0);
    for (std::size_t s = 0; s < row.columns.size(); ++s) {
      const double* block = row.panel.data() + s * bs2;
      bool c = row.columns[s] == cc;
      for (int j = 0; j < bs && !c; ++j)
        for (int r = 0; r < bs; ++r)
          if (r / n != j / n && block[j * bs + r] != 0.0) c = true;
      coupled[s] = c ? 1 : 0;
    }
  });
  for (int cc = 0; cc < coarseBlocks; ++cc) {
    const Panels& row = panels[static_cast<std::size_t>(cc)];
    for (std::size_t s = 0; s < row.columns.size(); ++s) {
      const int cb = row.columns[s];
      const bool c = coupledSlots[static_cast<std::size_t>(cc)][s] != 0;
      sources[static_cast<std::size_t>(cc)].push_back({cb, static_cast<int>(s), c});
      if (cb != cc) sources[static_cast<std::size_t>(cb)].push_back({cc, static_cast<int>(s), c});
    }
  }
  BlockRows<double> coarse;
  coarse.n = n;
  coarse.bs = bs;
  coarse.start.assign(static_cast<std::size_t>(coarseBlocks) + 1, 0);
  tbb::parallel_for(0, coarseBlocks, [&](int cc) {
    std::vector<Source>& blocks = sources[static_cast<std::size_t>(cc)];
    std::sort(blocks.begin(), blocks.end(),
              [](const Source& a, const Source& b) { return a.block < b.block; });
    coarse.start[static_cast<std::size_t>(cc) + 1] = static_cast<int>(blocks.size());
  });
  for (std::size_t c = 1; c < coarse.start.size(); ++c) coarse.start[c] += coarse.start[c - 1];
  const std::size_t slots = static_cast<std::size_t>(coarse.start.back());
  coarse.element.resize(slots);
  coarse.diagonal.resize(slots);
  coarse.offset.assign(slots + 1, 0);
  for (int cc = 0; cc < coarseBlocks; ++cc) {
    std::size_t k = static_cast<std::size_t>(coarse.start[static_cast<std::size_t>(cc)]);
    for (const Source& b : sources[static_cast<std::size_t>(cc)]) {
      coarse.element[k] = b.block;
      coarse.diagonal[k] = b.coupled ? 0 : 1;
      coarse.offset[k + 1] =
          coarse.offset[k] + static_cast<std::size_t>(b.coupled ? bs2 : 3 * n * n);
      ++k;
    }
  }
  coarse.values.resize(coarse.offset.back());
  tbb::parallel_for(0, coarseBlocks, [&](int cc) {
    std::size_t k = static_cast<std::size_t>(coarse.start[static_cast<std::size_t>(cc)]);
    for (const Source& b : sources[static_cast<std::size_t>(cc)]) {
      const int owner = std::max(b.block, cc);  // the row block whose panel holds it
      const double* block = panels[static_cast<std::size_t>(owner)].panel.data() +
                            static_cast<std::size_t>(b.slot) * bs2;
      double* to = coarse.values.data() + coarse.offset[k++];
      // Entry (i, j) of block (C, B): P_CB(i, j) if B < C, P_BC(j, i) if B > C, and on the
      // diagonal block P_CC's upper triangle mirrored (sums in another order make P_CC
      // symmetric only to round-off; the matrix is exactly symmetric).
      auto entry = [&](int i, int j) {
        return b.block < cc   ? block[j * bs + i]
               : b.block > cc ? block[i * bs + j]
                              : block[std::min(i, j) * bs + std::max(i, j)];
      };
      if (b.coupled) {
        for (int j = 0; j < bs; ++j)
          for (int i = 0; i < bs; ++i) to[j * bs + i] = entry(i, j);
        continue;
      }
      for (int d = 0; d < 3; ++d)
        for (int j = 0; j < n; ++j)
          for (int i = 0; i < n; ++i) to[d * n * n + j * n + i] = entry(d * n + i, d * n + j);
    }
  });
  std::vector<Panels>().swap(panels);
  // Unknowns that prolong to nothing (zero columns of a group's span): decoupled, unit
  // diagonal.
  if (!fine.ranks.empty())
    for (int g = 0; g < coarseBlocks; ++g) {
      double* diagonalBlock = const_cast<double*>(coarse.diagonalBlock(g));
      for (int j = fine.ranks[static_cast<std::size_t>(g)]; j < n; ++j)
        for (int d = 0; d < 3; ++d) diagonalBlock[(d * n + j) * bs + d * n + j] = 1.0;
    }
  return coarse;
}

SpMat galerkinMatrix(const Agglomeration& fine, const BlockRows<double>& rows) {
  return galerkinBlocks(fine, rows).toSparse();
}

std::vector<Eigen::Vector3i> latticeCells(const std::vector<Eigen::AlignedBox3d>& boxes) {
  const std::size_t ne = boxes.size();
  if (ne == 0) return {};
  Eigen::Vector3d h, origin;
  for (int l = 0; l < 3; ++l) {
    // The most common extent: the largest run of sorted extents within the tolerance of its
    // first.
    std::vector<double> extents(ne);
    for (std::size_t e = 0; e < ne; ++e) extents[e] = boxes[e].sizes()[l];
    std::sort(extents.begin(), extents.end());
    std::size_t best = 0, bestCount = 0;
    for (std::size_t i = 0, j = 0; i < ne; i = j) {
      j = i + 1;
      while (j < ne && extents[j] <= extents[i] * (1.0 + kLatticeTolerance)) ++j;
      if (j - i > bestCount) {
        best = i;
        bestCount = j - i;
      }
    }
    h[l] = extents[best];
    if (!(h[l] > 0.0) || !std::isfinite(h[l])) return {};
    double lowest = boxes[0].min()[l], reference = 0.0;
    bool found = false;
    for (const Eigen::AlignedBox3d& box : boxes) {
      lowest = std::min(lowest, box.min()[l]);
      if (!found && std::abs(box.sizes()[l] - h[l]) <= kLatticeTolerance * h[l]) {
        reference = box.min()[l];
        found = true;
      }
    }
    const double below = std::ceil((reference - lowest) / h[l] - kLatticeTolerance);
    if (below > kMaxLatticeCells) return {};
    origin[l] = reference - below * h[l];
  }
  std::vector<Eigen::Vector3i> cells(ne);
  std::size_t inOneCell = 0;
  for (std::size_t e = 0; e < ne; ++e) {
    const Eigen::Vector3d lo = (boxes[e].min() - origin).cwiseQuotient(h);
    const Eigen::Vector3d hi = (boxes[e].max() - origin).cwiseQuotient(h);
    const Eigen::Vector3d centre = 0.5 * (lo + hi);
    if (!(centre.maxCoeff() < kMaxLatticeCells)) return {};
    bool one = true;
    for (int l = 0; l < 3; ++l) {
      const double cell = std::max(0.0, std::floor(centre[l]));
      cells[e][l] = static_cast<int>(cell);
      one = one && lo[l] >= cell - kLatticeTolerance && hi[l] <= cell + 1.0 + kLatticeTolerance;
    }
    if (one) ++inOneCell;
  }
  if (static_cast<double>(inOneCell) < kLatticeShare * static_cast<double>(ne)) return {};
  return cells;
}

ElementFrames elementFrames(const DgBasis& basis, const PolyMesh& mesh) {
  ElementFrames frames;
  const std::size_t ne = basis.numElements();
  frames.centres.resize(ne);
  frames.scales.resize(ne);
  frames.bases.resize(ne);
  const int n = numMonomials(std::min(basis.degree(), 2));
  std::vector<Eigen::AlignedBox3d> boxes(ne);
  tbb::parallel_for(std::size_t(0), ne, [&](std::size_t e) {
    const ElementId id(e);
    frames.centres[e] = basis.centre(id);
    frames.scales[e] = basis.scale(id);
    frames.bases[e] = basis.coefficients(id).topLeftCorner(n, n);
    boxes[e] = elementBounds(mesh, id);
  });
  frames.cells = latticeCells(boxes);
  return frames;
}

namespace {

/// The functions of the blocks being grouped: each block's centre c_b and scale h_b, its
/// functions per component that take part, and how they combine the block's scaled monomials
/// m_a = ((x - c_b) / h_b)^a: elements phi = T_b m (`triangular`, ElementFrames::bases), or
/// groups of a finer agglomeration F = S_b^T m (`spans`, Agglomeration::spans).
struct BlockFunctions {
  const std::vector<Eigen::Vector3d>& centres;
  const std::vector<double>& scales;
  const std::vector<Eigen::MatrixXd>* triangular = nullptr;
  const std::vector<double>* spans = nullptr;
  int functions = 4;
};

Agglomeration groupBlocks(const BlockRows<double>& rows, const BlockFunctions& blocks,
                          const std::vector<Eigen::Vector3i>& cells, int degree) {
  if (degree < 1 || degree > 2) throw std::invalid_argument("agglomerate: degree must be 1 or 2");
  const int nb = static_cast<int>(rows.start.size()) - 1;
  Agglomeration a;
  a.functions = numMonomials(degree);
  a.blockFunctions = blocks.functions;
  if (a.blockFunctions > a.functions)
    throw std::invalid_argument("agglomerate: the groups' degree is below their blocks'");
  int count = 0;
  if (!cells.empty() && cells.size() == static_cast<std::size_t>(nb)) {
    a.parent = groupByCells(rows, cells, a.cells);
    count = static_cast<int>(a.cells.size());
  } else {
    a.parent = pairAlongAxes(rows, blocks.centres, count);
  }
  a.childStart.assign(static_cast<std::size_t>(count) + 1, 0);
  for (int g : a.parent) ++a.childStart[static_cast<std::size_t>(g) + 1];
  for (std::size_t g = 0; g < static_cast<std::size_t>(count); ++g)
    a.childStart[g + 1] += a.childStart[g];
  a.children.resize(static_cast<std::size_t>(nb));
  std::vector<int> next(a.childStart.begin(), a.childStart.end() - 1);
  for (int b = 0; b < nb; ++b)
    a.children[static_cast<std::size_t>(
        next[static_cast<std::size_t>(a.parent[static_cast<std::size_t>(b)])]++)] = b;
  a.centres.assign(static_cast<std::size_t>(count), Eigen::Vector3d::Zero());
  a.scales.assign(static_cast<std::size_t>(count), 0.0);
  for (std::size_t g = 0; g < static_cast<std::size_t>(count); ++g) {
    const int first = a.childStart[g], last = a.childStart[g + 1];
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int k = first; k < last; ++k)
      sum += blocks.centres[static_cast<std::size_t>(a.children[static_cast<std::size_t>(k)])];
    a.centres[g] = sum / (last - first);
    for (int k = first; k < last; ++k) {
      const std::size_t b = static_cast<std::size_t>(a.children[static_cast<std::size_t>(k)]);
      a.scales[g] =
          std::max(a.scales[g], (blocks.centres[b] - a.centres[g]).norm() + blocks.scales[b]);
    }
  }
  const int n = a.functions, nf = a.blockFunctions;
  const std::size_t size = static_cast<std::size_t>(nf * n),
                    spanSize = static_cast<std::size_t>(n * n);
  a.weights.resize(size * static_cast<std::size_t>(nb));
  a.spans.resize(spanSize * static_cast<std::size_t>(count));
  a.ranks.assign(static_cast<std::size_t>(count), n);
  tbb::parallel_for(0, count, [&](int g) {
    const std::size_t gi = static_cast<std::size_t>(g);
    Eigen::MatrixXd gram = Eigen::MatrixXd::Zero(n, n);
    for (int k = a.childStart[gi]; k < a.childStart[gi + 1]; ++k) {
      const std::size_t i = static_cast<std::size_t>(a.children[static_cast<std::size_t>(k)]);
      // Column j: the group's monomial j, ((x - C) / H)^a, in the block's scaled monomials
      // ((x - c) / h)^b (x = c + h y: sigma = h / H, d = (c - C) / H), of degree <= the
      // block's: all of it, or its Taylor part at c.
      const Eigen::MatrixXd change =
          monomialShift(degree, blocks.scales[i] / a.scales[gi],
                        (blocks.centres[i] - a.centres[gi]) / a.scales[gi])
              .transpose()
              .topRows(nf);
      // In the block's functions: phi = T m, so T^T W = change (T lower triangular); F = S^T m
      // with orthonormal (or zero) columns, so W = S^T change.
      Eigen::Map<Eigen::MatrixXd> w(a.weights.data() + size * i, nf, n);
      if (blocks.triangular != nullptr)
        w = (*blocks.triangular)[i]
                .topLeftCorner(nf, nf)
                .transpose()
                .triangularView<Eigen::Upper>()
                .solve(change);
      else
        w = Eigen::Map<const Eigen::MatrixXd>(
                blocks.spans->data() + static_cast<std::size_t>(nf * nf) * i, nf, nf)
                .transpose() *
            change;
      gram.noalias() += w.transpose() * w;
    }
    Eigen::Map<Eigen::MatrixXd> span(a.spans.data() + spanSize * gi, n, n);
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(gram);
    const Eigen::VectorXd& lambda = eigen.eigenvalues();  // increasing
    int rank = 0;
    while (rank < n && lambda[n - 1 - rank] > kSpanTolerance * lambda[n - 1]) ++rank;
    if (rank == n) {
      span.setIdentity();
      return;
    }
    a.ranks[gi] = rank;
    span.setZero();
    span.leftCols(rank) = eigen.eigenvectors().rightCols(rank).rowwise().reverse();
    for (int k = a.childStart[gi]; k < a.childStart[gi + 1]; ++k) {
      const std::size_t i = static_cast<std::size_t>(a.children[static_cast<std::size_t>(k)]);
      Eigen::Map<Eigen::MatrixXd> w(a.weights.data() + size * i, nf, n);
      w = (w * span).eval();
    }
  });
  return a;
}

}  // namespace

Agglomeration agglomerate(const BlockRows<double>& rows,
                          const std::vector<Eigen::Vector3d>& centres,
                          const std::vector<double>& scales,
                          const std::vector<Eigen::MatrixXd>& bases,
                          const std::vector<Eigen::Vector3i>& cells, int degree) {
  BlockFunctions blocks{centres, scales};
  blocks.triangular = &bases;
  blocks.functions = numMonomials(std::clamp(degree, 1, 2));
  return groupBlocks(rows, blocks, cells, degree);
}

Agglomeration agglomerate(const BlockRows<double>& rows, const Agglomeration& finer, int degree) {
  BlockFunctions blocks{finer.centres, finer.scales};
  blocks.spans = &finer.spans;
  blocks.functions = finer.functions;
  return groupBlocks(rows, blocks, finer.cells, degree);
}

}  // namespace polydg
