// The p-multigrid smoother's setup (physics/solvers/multigrid_smoother.h): group blocks gathered
// and inverted, greedy colouring of the groups.
#include "physics/solvers/multigrid_smoother.h"

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <numeric>
#include <span>

#include <tbb/parallel_for.h>
#include <Eigen/Dense>

namespace polydg::multigrid {

namespace {

/// D^-1 of one symmetric positive definite block D (column-major, BS x BS) into `inverse`;
/// false if D is not positive definite. Fixed sizes, which Eigen's LLT inverts several times
/// faster than dynamic ones.
template <int BS>
bool invertBlock(const double* block, double* inverse) {
  using Mat = Eigen::Matrix<double, BS, BS>;
  const Eigen::LLT<Mat> llt{Eigen::Map<const Mat>(block)};
  if (llt.info() != Eigen::Success) return false;
  Eigen::Map<Mat> out(inverse);
  out = llt.solve(Mat::Identity());
  return true;
}

bool invertBlock(int bs, const double* block, double* inverse) {
  switch (bs) {
    case 3: return invertBlock<3>(block, inverse);
    case 12: return invertBlock<12>(block, inverse);
    case 30: return invertBlock<30>(block, inverse);
    case 60: return invertBlock<60>(block, inverse);
    default: {
      const Eigen::LLT<Eigen::MatrixXd> llt{Eigen::Map<const Eigen::MatrixXd>(block, bs, bs)};
      if (llt.info() != Eigen::Success) return false;
      Eigen::Map<Eigen::MatrixXd> out(inverse, bs, bs);
      out = llt.solve(Eigen::MatrixXd::Identity(bs, bs));
      return true;
    }
  }
}

/// Writes the diagonal block of `level`'s smoother group g into `block` ((m bs) x (m bs),
/// column-major, zeroed by the caller), from the matrix as the smoother reads it.
void groupBlock(const Level& level, int g, double* block) {
  const int bs = level.bs;
  const std::span<const int> group = level.smootherGroups.of(g);
  const int m = static_cast<int>(group.size()), size = m * bs;
  const int* members = group.data();
  // The position of block f in the group, or -1.
  auto local = [&](int f) {
    const int* it = std::lower_bound(members, members + m, f);
    return it != members + m && *it == f ? static_cast<int>(it - members) : -1;
  };
  auto copyRows = [&](const auto& rows) {
    for (int i = 0; i < m; ++i)
      for (int k = rows.start[static_cast<std::size_t>(members[i])];
           k < rows.start[static_cast<std::size_t>(members[i]) + 1]; ++k)
        if (const int j = local(rows.element[static_cast<std::size_t>(k)]); j >= 0)
          rows.copySlot(static_cast<std::size_t>(k),
                        block + static_cast<std::ptrdiff_t>(j) * bs * size + i * bs, size);
  };
  if (level.rows) {
    copyRows(*level.rows);
  } else if (level.useBlocks) {  // invert the block as the smoother sees it (single precision)
    copyRows(level.blocks);
  } else {
    // Column c of block i is row c of it (symmetric storage).
    for (int i = 0; i < m; ++i)
      for (int c = 0; c < bs; ++c)
        for (SpMat::InnerIterator it(*level.matrix, static_cast<Eigen::Index>(members[i]) * bs + c);
             it; ++it)
          if (const int j = local(static_cast<int>(it.row() / bs)); j >= 0)
            block[static_cast<std::ptrdiff_t>(i * bs + c) * size + j * bs + it.row() % bs] =
                it.value();
  }
}

/// Greedy colouring of `ne` elements, in order, each taking the first colour none of its
/// neighbours has: forEachNeighbour(e, visit) calls visit(f) for each neighbour f of e. The
/// elements of each colour, in increasing order.
template <class ForEachNeighbour>
std::vector<std::vector<int>> colourGreedily(int ne, ForEachNeighbour&& forEachNeighbour) {
  std::vector<int> colour(static_cast<std::size_t>(ne), -1);
  std::vector<int> seenBy;  // seenBy[c] == e: colour c is taken by a neighbour of e
  std::vector<std::vector<int>> classes;
  for (int e = 0; e < ne; ++e) {
    forEachNeighbour(e, [&](int f) {
      const int c = colour[static_cast<std::size_t>(f)];
      if (c >= 0) seenBy[static_cast<std::size_t>(c)] = e;
    });
    int c = 0;
    while (c < static_cast<int>(seenBy.size()) && seenBy[static_cast<std::size_t>(c)] == e) ++c;
    if (c == static_cast<int>(seenBy.size())) {
      seenBy.push_back(-1);
      classes.emplace_back();
    }
    colour[static_cast<std::size_t>(e)] = c;
    classes[static_cast<std::size_t>(c)].push_back(e);
  }
  return classes;
}

/// Calls visit(f) for each block f that shares a stored block with block e of `level` (e
/// itself included), from the matrix as the smoother reads it.
template <class Visit>
void forEachNeighbour(const Level& level, int e, Visit&& visit) {
  auto fromRows = [&](const auto& rows) {
    for (int k = rows.start[static_cast<std::size_t>(e)];
         k < rows.start[static_cast<std::size_t>(e) + 1]; ++k)
      visit(rows.element[static_cast<std::size_t>(k)]);
  };
  if (level.rows) return fromRows(*level.rows);
  if (level.useBlocks) return fromRows(level.blocks);
  // Column e bs holds a row of every neighbour block (BZ blocks included: component 0).
  for (SpMat::InnerIterator it(*level.matrix, static_cast<Eigen::Index>(e) * level.bs); it; ++it)
    visit(static_cast<int>(it.row() / level.bs));
}

}  // namespace

bool invertGroups(Level& level) {
  const int bs = level.bs;
  const BlockGroups& groups = level.smootherGroups;
  const int ng = groups.groups();
  level.inverseOffset.assign(static_cast<std::size_t>(ng), 0);
  std::size_t next = 0;
  const auto place = [&](int g) {
    level.inverseOffset[static_cast<std::size_t>(g)] = next;
    next += static_cast<std::size_t>(groups.size(g) * bs) *
            static_cast<std::size_t>(groups.size(g) * bs);
  };
  if (level.colours.empty())
    for (int g = 0; g < ng; ++g) place(g);
  else
    for (const std::vector<int>& colour : level.colours)
      for (int g : colour) place(g);
  level.inverses.resize(next);
  std::atomic<bool> ok{true};
  tbb::parallel_for(0, ng, [&](int g) {
    const int size = groups.size(g) * bs;
    double* inverse = level.inverses.data() + level.inverseOffset[static_cast<std::size_t>(g)];
    if (size == bs) {
      double block[kMaxBlock * kMaxBlock];
      std::fill(block, block + bs * bs, 0.0);
      groupBlock(level, g, block);
      if (!invertBlock(bs, block, inverse)) ok = false;
      return;
    }
    Eigen::MatrixXd block = Eigen::MatrixXd::Zero(size, size);
    groupBlock(level, g, block.data());
    if (!invertBlock(size, block.data(), inverse)) ok = false;
  });
  return ok;
}

std::vector<std::vector<int>> colourGroups(const Level& level) {
  const BlockGroups& groups = level.smootherGroups;
  std::vector<int> groupOf(groups.members.size());
  for (int g = 0; g < groups.groups(); ++g)
    for (int e : groups.of(g)) groupOf[static_cast<std::size_t>(e)] = g;
  return colourGreedily(groups.groups(), [&](int g, auto&& visit) {
    for (int e : groups.of(g))
      forEachNeighbour(level, e, [&](int f) { visit(groupOf[static_cast<std::size_t>(f)]); });
  });
}

std::vector<int> sweepOrder(const Level& level) {
  std::vector<int> order;
  order.reserve(static_cast<std::size_t>(level.blockCount()));
  for (const std::vector<int>& colour : level.colours)
    for (int g : colour)
      for (int e : level.smootherGroups.of(g)) order.push_back(e);
  return order;
}

BlockGroups singleBlocks(int blocks) {
  BlockGroups groups;
  groups.start.resize(static_cast<std::size_t>(blocks) + 1);
  groups.members.resize(static_cast<std::size_t>(blocks));
  std::iota(groups.start.begin(), groups.start.end(), 0);
  std::iota(groups.members.begin(), groups.members.end(), 0);
  return groups;
}

}  // namespace polydg::multigrid
