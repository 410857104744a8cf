#include "physics/dynamics/corotation.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <Eigen/SVD>

#include "physics/dg/block_rows.h"
#include "physics/dg/polynomial_tables.h"
#include "physics/dynamics/corotation_kernels.h"
#include "util/uninitialized.h"

namespace polydg {

Eigen::Matrix3d polarRotation(const Eigen::Matrix3d& f) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(f, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d u = svd.matrixU();
  const Eigen::Matrix3d v = svd.matrixV();
  if ((u * v.transpose()).determinant() < 0.0) u.col(2) = -u.col(2);  // smallest singular value
  return u * v.transpose();
}

CorotatedStiffness::CorotatedStiffness(const DgBasis& basis, const MomentCache& moments,
                                       SplitLocalMatrices parts, const Vec3& origin,
                                       bool corotational)
    : parts_(std::move(parts)),
      corotational_(corotational),
      degree_(basis.degree()),
      n_(basis.size()),
      bs_(3 * basis.size()),
      ne_(parts_.jumps.neighbours.size()) {
  buildSlots();
  elementTerms(basis, moments, origin);
  // Elements with a Dirichlet face: the others' Dirichlet blocks are zero, and assembling skips
  // warping them (2 of the 15 warps of an element with six neighbours).
  const std::size_t bb = static_cast<std::size_t>(bs_) * bs_;
  clamped_.assign(ne_, 0);
  for (const UninitializedVector<double>* dir : {&parts_.dirichletTrial, &parts_.dirichletTest})
    if (dir->size() == ne_ * bb)
      for (std::size_t i = 0; i < ne_; ++i)
        if (std::any_of(dir->begin() + static_cast<std::ptrdiff_t>(i * bb),
                        dir->begin() + static_cast<std::ptrdiff_t>((i + 1) * bb),
                        [](double v) { return v != 0.0; }))
          clamped_[i] = 1;
}

void CorotatedStiffness::buildSlots() {
  const LocalMatrices& l = parts_.jumps;
  rowStart_.assign(ne_ + 1, 0);
  slots_.clear();
  for (std::size_t i = 0; i < ne_; ++i) {
    const auto& b = l.neighbours[i];
    const auto firstGreater = std::upper_bound(b.begin(), b.end(), static_cast<std::uint32_t>(i));
    for (std::uint32_t f : b) {
      RowSlot s;
      s.other = f;
      if (f == i) {
        s.diagonal = true;
        s.block = i;
      } else if (f > i) {
        s.block =
            l.couplingStart[i] +
            static_cast<std::size_t>(std::lower_bound(firstGreater, b.end(), f) - firstGreater);
      } else {
        const auto& bf = l.neighbours[f];
        const auto fg = std::upper_bound(bf.begin(), bf.end(), f);
        s.block = l.couplingStart[f] +
                  static_cast<std::size_t>(
                      std::lower_bound(fg, bf.end(), static_cast<std::uint32_t>(i)) - fg);
        s.transposed = true;
      }
      slots_.push_back(s);
    }
    rowStart_[i + 1] = slots_.size();
  }
}

void CorotatedStiffness::elementTerms(const DgBasis& basis, const MomentCache& moments,
                                      const Vec3& origin) {
  const int n = n_;
  gradients_.assign(ne_ * 3 * static_cast<std::size_t>(n), 0.0);
  x0_.resize(static_cast<Eigen::Index>(ne_) * bs_);
  tbb::parallel_for(std::size_t(0), ne_, [&](std::size_t i) {
    const ElementId e(i);
    for (int d = 0; d < 3; ++d)
      x0_.segment(static_cast<Eigen::Index>(i) * bs_ + d * n, n) =
          affineCoefficients(basis, e, 0.0, Vec3::Unit(d), origin);
    // Mean gradients: (1/|K|) int d_k phi_i = (1/|K|) sum_a T(i, a) int d_k m_a.
    const auto t = basis.coefficients(e);
    const auto em = moments.element(e);
    const double h = basis.scale(e), vol = moments.volume(e);
    for (int k = 0; k < 3; ++k)
      for (int aIdx = 0; aIdx < n; ++aIdx) {
        const Exponents ex = monomialExponents(aIdx);
        int pw[3] = {ex.a, ex.b, ex.c};
        if (pw[k] == 0) continue;
        const double factor = pw[k] / h;
        --pw[k];
        const int b = monomialIndex(pw[0], pw[1], pw[2]);
        const double integral = factor * em[b] / std::pow(h, pw[0] + pw[1] + pw[2]);
        for (int fn = 0; fn < n; ++fn)
          gradients_[i * 3 * n + k * n + fn] += t(fn, aIdx) * integral / vol;
      }
  });
}

Eigen::Matrix3d CorotatedStiffness::deformationGradient(std::size_t i,
                                                        const Eigen::VectorXd& u) const {
  Eigen::Matrix3d f = Eigen::Matrix3d::Identity();
  const double* g = gradients_.data() + i * 3 * n_;
  const double* ue = u.data() + i * bs_;
  for (int d = 0; d < 3; ++d)
    for (int k = 0; k < 3; ++k) {
      double sum = 0.0;
      for (int fn = 0; fn < n_; ++fn) sum += g[k * n_ + fn] * ue[d * n_ + fn];
      f(d, k) += sum;
    }
  return f;
}

std::vector<Eigen::Matrix3d> CorotatedStiffness::rotations(const Eigen::VectorXd& u) const {
  std::vector<Eigen::Matrix3d> r(ne_, Eigen::Matrix3d::Identity());
  if (!corotational_) return r;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, ne_, 256),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i != range.end(); ++i)
                        r[i] = polarRotation(deformationGradient(i, u));
                    });
  return r;
}

int CorotatedStiffness::partsOf(std::size_t i, const RowSlot& s, Part out[3]) const {
  const std::size_t bb = static_cast<std::size_t>(bs_) * bs_;
  if (s.diagonal) {
    out[0] = {parts_.rowStrain.diagonal.data() + i * bb, true, static_cast<std::int64_t>(i)};
    out[1] = {parts_.jumps.diagonal.data() + i * bb, true, -1};
    return 2;
  }
  const std::size_t off = s.block * bb;
  const auto self = static_cast<std::int64_t>(i), other = static_cast<std::int64_t>(s.other);
  if (!s.transposed) {  // row-major, stored by i
    out[0] = {parts_.rowStrain.coupling.data() + off, false, self};
    out[1] = {parts_.columnStrain.coupling.data() + off, false, other};
    out[2] = {parts_.jumps.coupling.data() + off, false, -1};
  } else {  // stored by `other` as its rows: read transposed
    out[0] = {parts_.rowStrain.coupling.data() + off, true, other};
    out[1] = {parts_.columnStrain.coupling.data() + off, true, self};
    out[2] = {parts_.jumps.coupling.data() + off, true, -1};
  }
  return 3;
}

void CorotatedStiffness::product(const std::vector<Eigen::Matrix3d>& r, const Eigen::VectorXd& x,
                                 const Eigen::VectorXd* z, Eigen::VectorXd& out,
                                 double* energy) const {
  detail::dispatchBasisDegree(degree_,
                              [&](auto p) { productOf<numMonomials(p())>(r, x, z, out, energy); });
}

/// The terms of product(), block by block: R_S B (R_S^T x_C - z_C) added to a row's output,
/// and their energy.
template <int N>
class CorotatedStiffness::BlockTerms {
 public:
  static constexpr int BS = 3 * N;
  using Vec = Eigen::Matrix<double, BS, 1>;
  using Components = Eigen::Matrix<double, N, 3>;  // column d: component d

  BlockTerms(const std::vector<Eigen::Matrix3d>& r, const Eigen::VectorXd& x,
             const Eigen::VectorXd* z, bool corotational, bool energy)
      : r_(r), x_(x), z_(z), corotational_(corotational), energy_(energy) {}

  /// Adds to `out` (row element `row`'s 3n values) the block B against column element `col`,
  /// warped with element `source`'s rotation (-1: not warped), B column-major or row-major;
  /// returns the block's energy term (0 without energy).
  double add(std::size_t row, double* out, const double* b, bool columnMajor, std::int64_t source,
             std::size_t col, bool rowDifference = false, bool columnDifference = false) {
    const bool warp = source >= 0 && corotational_;
    const Eigen::Matrix3d* rot = warp ? &r_[static_cast<std::size_t>(source)] : nullptr;
    side(rot, col, columnDifference, w_);
    blockTimes(N, b, columnMajor, w_.data(), y_.data());
    Eigen::Map<Vec> o(out);
    if (rot)
      Eigen::Map<Components>(o.data()).noalias() +=
          Eigen::Map<const Components>(y_.data()) * rot->transpose();
    else
      o += y_;
    if (!energy_) return 0.0;
    side(rot, row, rowDifference, wa_);
    return 0.5 * wa_.dot(y_);
  }

 private:
  /// The vector a side of a block reads: R^T x - z (positions against the undeformed state:
  /// the strain side and interior jumps) or R^T (x - z) (the displacement: the jump against a
  /// Dirichlet face's fixed outside). (R (x) I)^T acts on the components as V R.
  void side(const Eigen::Matrix3d* rot, std::size_t el, bool difference, Vec& o) {
    v_ = Eigen::Map<const Vec>(x_.data() + el * BS);
    if (z_ && difference) v_ -= Eigen::Map<const Vec>(z_->data() + el * BS);
    if (rot)
      Eigen::Map<Components>(o.data()).noalias() = Eigen::Map<const Components>(v_.data()) * (*rot);
    else
      o = v_;
    if (z_ && !difference) o -= Eigen::Map<const Vec>(z_->data() + el * BS);
  }

  const std::vector<Eigen::Matrix3d>& r_;
  const Eigen::VectorXd& x_;
  const Eigen::VectorXd* z_;
  bool corotational_, energy_;
  Vec w_, y_, wa_, v_;
};

template <int N>
double CorotatedStiffness::rowTerms(BlockTerms<N>& terms, std::size_t i, double* out,
                                    double* transposedTerms) const {
  constexpr std::size_t bb = static_cast<std::size_t>(3 * N) * (3 * N);
  const bool bz = parts_.jumps.componentDiagonalCoupling;
  const auto self = static_cast<std::int64_t>(i);
  double sum = 0.0;
  if (!bz && clamped_[i]) {  // the Dirichlet faces' strain terms (zero elsewhere)
    sum += terms.add(i, out, parts_.dirichletTrial.data() + i * bb, true, self, i, true, false);
    sum += terms.add(i, out, parts_.dirichletTest.data() + i * bb, true, self, i, false, true);
  }
  std::size_t neighbour = 0;
  for (std::size_t k = rowStart_[i]; k < rowStart_[i + 1]; ++k) {
    const RowSlot& s = slots_[k];
    if (!s.diagonal && !bz)  // the neighbour's lifting terms in i's diagonal block
      sum += terms.add(
          i, out, parts_.neighbourLifting.data() + (parts_.neighbourStart[i] + neighbour++) * bb,
          true, s.other, i);
    if (s.transposed) continue;  // stored by s.other, whose task computes these terms
    Part ps[3];
    const int np = partsOf(i, s, ps);
    for (int q = 0; q < np; ++q) {
      if (ps[q].source >= 0 && !s.diagonal && bz) continue;  // BZ: no coupling strain
      sum += terms.add(i, out, ps[q].b, ps[q].columnMajor, ps[q].source, s.other);
    }
    if (s.diagonal) continue;
    // The same block read transposed, as row s.other's (partsOf() of its transposed slot),
    // while it is in cache: the terms of s.other's row, kept per coupling block.
    double* into = transposedTerms + s.block * static_cast<std::size_t>(3 * N);
    std::fill(into, into + 3 * N, 0.0);
    const auto other = static_cast<std::int64_t>(s.other);
    const std::int64_t sources[3] = {self, other, -1};
    for (int q = 0; q < np; ++q) {
      if (sources[q] >= 0 && bz) continue;
      sum += terms.add(s.other, into, ps[q].b, true, sources[q], i);
    }
  }
  return sum;
}

template <int N, class EachElement>
double CorotatedStiffness::sumRows(const std::vector<Eigen::Matrix3d>& r, const Eigen::VectorXd& x,
                                   const Eigen::VectorXd* z, bool energy, Eigen::VectorXd& out,
                                   const EachElement& eachElement) const {
  constexpr int BS = 3 * N;
  constexpr std::size_t bb = static_cast<std::size_t>(BS) * BS;
  out.setZero(x.size());
  // One vector per stored coupling block: the terms of the greater element's row, which the
  // task of the smaller one computes (each task writes its own row only).
  UninitializedVector<double> transposed(parts_.jumps.coupling.size() / bb * BS);
  const double e = tbb::parallel_deterministic_reduce(
      tbb::blocked_range<std::size_t>(0, ne_, 32), 0.0,
      [&](const tbb::blocked_range<std::size_t>& range, double sum) {
        BlockTerms<N> terms(r, x, z, corotational_, energy);
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
          eachElement(i);
          sum += rowTerms<N>(terms, i, out.data() + i * BS, transposed.data());
        }
        return sum;
      },
      std::plus<double>());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, ne_, 256),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i != range.end(); ++i) {
                        Eigen::Map<Eigen::Matrix<double, BS, 1>> o(out.data() + i * BS);
                        for (std::size_t k = rowStart_[i]; k < rowStart_[i + 1]; ++k)
                          if (slots_[k].transposed)
                            o += Eigen::Map<const Eigen::Matrix<double, BS, 1>>(
                                transposed.data() + slots_[k].block * BS);
                      }
                    });
  return e;
}

template <int N>
void CorotatedStiffness::productOf(const std::vector<Eigen::Matrix3d>& r, const Eigen::VectorXd& x,
                                   const Eigen::VectorXd* z, Eigen::VectorXd& out,
                                   double* energy) const {
  const double e = sumRows<N>(r, x, z, energy != nullptr, out, [](std::size_t) {});
  if (energy) *energy = e;
}

void CorotatedStiffness::forceAndAssemble(const std::vector<Eigen::Matrix3d>& r,
                                          const Eigen::VectorXd& u, Eigen::VectorXd& force,
                                          double& energy, const std::vector<double>& mass,
                                          double cM, double cK, BlockRows<double>& rows) const {
  detail::dispatchBasisDegree(degree_, [&](auto p) {
    constexpr int N = numMonomials(p());
    // Each element's blocks warped into its rows first: its force terms then read them from
    // cache. The force is product()'s, term for term and in its order.
    tbb::enumerable_thread_specific<std::vector<double>> buffers;
    const auto warp = [&](std::size_t i) {
      elementRows<N>(r, mass, cM, cK, i, buffers.local(), rows);
    };
    energy = sumRows<N>(r, Eigen::VectorXd(x0_ + u), &x0_, true, force, warp);
  });
}

void CorotatedStiffness::assemble(const std::vector<Eigen::Matrix3d>& r,
                                  const std::vector<double>& mass, double cM, double cK,
                                  LocalMatrices& system) const {
  const std::size_t bb = static_cast<std::size_t>(bs_) * bs_;
  // Element i's blocks straight into the arrays of `system`.
  detail::dispatchBasisDegree(degree_, [&](auto p) {
    constexpr int N = numMonomials(p());
    assembleOf([&](std::size_t i, std::vector<double>&) {
      elementBlocks<N>(r, mass, cM, cK, i, system.diagonal.data() + i * bb,
                       system.coupling.data() + parts_.jumps.couplingStart[i] * bb);
    });
  });
}

void CorotatedStiffness::assemble(const std::vector<Eigen::Matrix3d>& r,
                                  const std::vector<double>& mass, double cM, double cK,
                                  BlockRows<double>& rows) const {
  // One pass over the rows and no LocalMatrices.
  detail::dispatchBasisDegree(degree_, [&](auto p) {
    constexpr int N = numMonomials(p());
    assembleOf([&](std::size_t i, std::vector<double>& buffer) {
      elementRows<N>(r, mass, cM, cK, i, buffer, rows);
    });
  });
}

template <class Each>
void CorotatedStiffness::assembleOf(const Each& each) const {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, ne_, 32),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      std::vector<double> buffer;
                      for (std::size_t i = range.begin(); i != range.end(); ++i) each(i, buffer);
                    });
}

template <int N>
void CorotatedStiffness::elementRows(const std::vector<Eigen::Matrix3d>& r,
                                     const std::vector<double>& mass, double cM, double cK,
                                     std::size_t i, std::vector<double>& buffer,
                                     BlockRows<double>& rows) const {
  constexpr std::size_t bb = static_cast<std::size_t>(3 * N) * (3 * N);
  buffer.resize((1 + greaterNeighbours(parts_.jumps.neighbours, i)) * bb);
  elementBlocks<N>(r, mass, cM, cK, i, buffer.data(), buffer.data() + bb);
  writeElementRows(rows, parts_.jumps.neighbours, i, buffer.data(), buffer.data() + bb);
}

template <int N>
void CorotatedStiffness::elementBlocks(const std::vector<Eigen::Matrix3d>& r,
                                       const std::vector<double>& mass, double cM, double cK,
                                       std::size_t i, double* d, double* c) const {
  const int n = n_, bs = bs_;
  const std::size_t bb = static_cast<std::size_t>(bs) * bs;
  const bool bz = parts_.jumps.componentDiagonalCoupling;
  const bool warp = corotational_;
  const double* js = parts_.jumps.diagonal.data() + i * bb;
  const double* ss = parts_.rowStrain.diagonal.data() + i * bb;
  for (std::size_t k = 0; k < bb; ++k) d[k] = cK * js[k];
  if (warp)
    addWarpedBlock(N, r[i].data(), ss, cK, d);
  else
    for (std::size_t k = 0; k < bb; ++k) d[k] += cK * ss[k];
  if (!bz) {
    if (clamped_[i])
      for (const UninitializedVector<double>* dir :
           {&parts_.dirichletTrial, &parts_.dirichletTest}) {
        if (warp)
          addWarpedBlock(N, r[i].data(), dir->data() + i * bb, cK, d);
        else
          for (std::size_t q = 0; q < bb; ++q) d[q] += cK * (*dir)[i * bb + q];
      }
    const std::size_t first = parts_.neighbourStart[i];
    std::size_t k = 0;
    for (std::uint32_t f : parts_.jumps.neighbours[i]) {
      if (f == i) continue;
      const double* nl = parts_.neighbourLifting.data() + (first + k++) * bb;
      if (warp)
        addWarpedBlock(N, r[f].data(), nl, cK, d);
      else
        for (std::size_t q = 0; q < bb; ++q) d[q] += cK * nl[q];
    }
  }
  const double* me = mass.data() + i * n * n;
  for (int comp = 0; comp < 3; ++comp)
    for (int fi = 0; fi < n; ++fi)
      for (int fj = 0; fj < n; ++fj)
        d[static_cast<std::size_t>(comp * n + fj) * bs + comp * n + fi] += cM * me[fj * n + fi];
  const auto& nb = parts_.jumps.neighbours[i];
  const auto firstGreater = std::upper_bound(nb.begin(), nb.end(), static_cast<std::uint32_t>(i));
  std::size_t slot = parts_.jumps.couplingStart[i];
  for (auto it = firstGreater; it != nb.end(); ++it, ++slot, c += bb) {
    // Coupling blocks are row-major: as column-major they are the transposed block,
    // (R1 B R2^T)^T = R2 B^T R1^T.
    const double* jc = parts_.jumps.coupling.data() + slot * bb;
    for (std::size_t k = 0; k < bb; ++k) c[k] = cK * jc[k];
    if (bz) continue;
    const double* rc = parts_.rowStrain.coupling.data() + slot * bb;
    const double* oc = parts_.columnStrain.coupling.data() + slot * bb;
    if (warp) {
      // Read each row-major block column-major (its transpose) and write the transpose of the
      // warped block: R_f B^T R_f^T etc. with the roles swapped.
      addWarpedBlock(N, r[i].data(), rc, cK, c);
      addWarpedBlock(N, r[*it].data(), oc, cK, c);
    } else {
      for (std::size_t k = 0; k < bb; ++k) c[k] += cK * (rc[k] + oc[k]);
    }
  }
}

}  // namespace polydg
