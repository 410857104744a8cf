#include "physics/dynamics/dynamics.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <Eigen/Cholesky>
#include <Eigen/SVD>

#include "integrate/quadrature.h"
#include "physics/dg/assembly.h"
#include "physics/dg/local_integrators.h"
#include "physics/dg/polynomial_tables.h"
#include "physics/solvers/agglomeration.h"
#include "polydg/physics/dg/post_process.h"
#include "util/stopwatch.h"

namespace polydg {

namespace {

using SpMat = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;
using RowMap =
    Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>;
using ColMap = Eigen::Map<const Eigen::MatrixXd>;

constexpr double kNewmarkBeta = 0.25, kNewmarkGamma = 0.5;
/// Solves per step of the automatic corrections of the second-order integrators with corotation
/// (the modified Newton iteration gains 1-2 digits per solve on B7's spinning cube).
constexpr int kMaxAutomaticSolves = 12;
/// Adaptive preconditioner: block-Jacobi CG until a solve needs more than this many iterations,
/// then the p-multigrid. On B10's beam at 87k DOFs, p = 1, dt = 0.01: block-Jacobi 45
/// iterations at 2.3 ms, the p-multigrid 14 at 15 ms (a V-cycle is several products).
constexpr int kBlockJacobiLimit = 80;

/// out += s (R (x) I_N) B (R (x) I_N)^T for a 3N x 3N column-major block B, into the
/// column-major out: N x N blocks, B'_dc = sum_ab R(d, a) B_ab R(c, b).
template <int N>
void addWarped(const Eigen::Matrix3d& r, const double* b, double s, double* out) {
  constexpr int BS = 3 * N;
  const Eigen::Map<const Eigen::Matrix<double, BS, BS>> in(b);
  Eigen::Map<Eigen::Matrix<double, BS, BS>> o(out);
  Eigen::Matrix<double, BS, BS> t;  // (R (x) I) B
  for (int d = 0; d < 3; ++d)
    for (int c = 0; c < 3; ++c)
      t.template block<N, N>(d * N, c * N).noalias() =
          r(d, 0) * in.template block<N, N>(0, c * N) +
          r(d, 1) * in.template block<N, N>(N, c * N) +
          r(d, 2) * in.template block<N, N>(2 * N, c * N);
  for (int d = 0; d < 3; ++d)
    for (int c = 0; c < 3; ++c)
      o.template block<N, N>(d * N, c * N) += (s * r(c, 0)) * t.template block<N, N>(d * N, 0) +
                                              (s * r(c, 1)) * t.template block<N, N>(d * N, N) +
                                              (s * r(c, 2)) * t.template block<N, N>(d * N, 2 * N);
}

}  // namespace

Eigen::Matrix3d polarRotation(const Eigen::Matrix3d& f) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(f, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d u = svd.matrixU();
  const Eigen::Matrix3d v = svd.matrixV();
  if ((u * v.transpose()).determinant() < 0.0) u.col(2) = -u.col(2);  // smallest singular value
  return u * v.transpose();
}

/// One block of an element's rows: against element `other`, read from `block` of the split
/// matrices (diagonal: the element's own; else a coupling block, transposed when stored by
/// the other element).
struct RowSlot {
  std::uint32_t other = 0;
  std::size_t block = 0;  ///< diagonal: the element; coupling: the coupling block's index
  bool diagonal = false;
  bool transposed = false;
};

struct DynamicSolver::Impl {
  const PolyMesh* mesh = nullptr;
  const MomentCache* moments = nullptr;
  DynamicsOptions options;
  std::unique_ptr<DgBasis> basis;
  FaceRoles roles;
  ElementPenalties penalties;
  FormCoefficients form;
  SplitLocalMatrices parts;
  int n = 0, bs = 0;
  std::size_t ne = 0;
  std::vector<std::size_t> rowStart;
  std::vector<RowSlot> slots;
  std::vector<double> mass;       ///< rho int phi_i phi_j, n x n per element
  std::vector<double> massOne;    ///< rho int phi_i, n per element
  std::vector<double> gradients;  ///< (1/|K|) int d_k phi_i at k * n + i, 3n per element
  std::vector<Eigen::LLT<Eigen::MatrixXd>> massInverse;
  Eigen::VectorXd x0;  ///< coefficients of x - o
  Vec3 origin = Vec3::Zero();
  double totalMass = 0.0;
  Eigen::VectorXd gravityForce;
  std::vector<Eigen::VectorXd> tractionForces;
  std::vector<std::size_t> clampFaces, tractionFaces;
  ElementFrames frames;
  LocalMatrices system;
  SpMat matrix;
  SpMat contactMatrix;  ///< matrix plus the step's contact terms
  ContactModel* contact = nullptr;
  LinearSolver solver;
  bool assembled = false;
  int baselineIterations = -1, lastIterations = 0;
  double t = 0.0;
  Eigen::VectorXd u, v, a;
  SolverOptions activeSolver;       ///< options.solver with the preconditioner in use
  Eigen::VectorXd previousUnknown;  ///< the step's unknown one step back (warm start)
  bool hasGuessHistory = false;
  bool solverReady = false;        ///< factorized, or preconditioner built, for `matrix`
  bool switchToMultigrid = false;  ///< from the next step on
  /// BDF2: the state one step back, once there is one.
  Eigen::VectorXd uPrevious, vPrevious;
  bool hasPrevious = false;
  double lastCK = 0.0;

  // --- setup ---------------------------------------------------------------------------
  void setup(const PolyMesh& m, const MomentCache& mc, const DynamicLoads& loads,
             const DynamicsOptions& o) {
    mesh = &m;
    moments = &mc;
    options = o;
    options.material.check();
    if (!(o.dt > 0.0) || !std::isfinite(o.dt))
      throw std::invalid_argument("the time step must be positive");
    if (!(o.massDamping >= 0.0) || !(o.stiffnessDamping >= 0.0))
      throw std::invalid_argument("damping coefficients must not be negative");
    const int p = o.discretization.basis.degree;
    if (mc.degree() < 2 * p)
      throw std::invalid_argument("DynamicSolver: the moments must be of degree >= 2p");
    basis = std::make_unique<DgBasis>(m, mc, o.discretization.basis);
    n = basis->size();
    bs = 3 * n;
    ne = m.numElements();

    LoadCase lc;
    for (const FaceSelector& c : loads.clamps) lc.dirichlet.push_back({c, {}});
    for (const TimedTraction& tr : loads.tractions) lc.tractions.push_back({tr.where, tr.traction});
    roles = classifyFaces(m, lc);
    clampFaces.assign(loads.clamps.size(), 0);
    tractionFaces.assign(loads.tractions.size(), 0);
    for (std::size_t f = 0; f < m.numFaces(); ++f) {
      const FaceId id(f);
      if (roles.dirichlet[id] >= 0) ++clampFaces[static_cast<std::size_t>(roles.dirichlet[id])];
      if (roles.traction[id] >= 0) ++tractionFaces[static_cast<std::size_t>(roles.traction[id])];
    }
    double threshold = 0.0;
    form = formCoefficients(m, *basis, mc, roles, options.material, o.discretization, penalties,
                            threshold);
    parts = splitLocalMatrices(m, *basis, mc, roles, form);
    buildSlots();
    elementTerms();

    const int quadrature =
        o.discretization.quadratureDegree >= 0 ? o.discretization.quadratureDegree : 2 * p + 2;
    LoadCase gravity = lc;
    for (auto& tr : gravity.tractions) tr.traction = Vec3::Zero();
    gravity.gravity = loads.gravity;
    gravityForce = assembleLoad(m, *basis, mc, roles, form, options.material, gravity, quadrature);
    for (std::size_t k = 0; k < loads.tractions.size(); ++k) {
      LoadCase one = gravity;
      one.gravity = Vec3::Zero();
      one.tractions[k].traction = loads.tractions[k].traction;
      tractionForces.push_back(
          assembleLoad(m, *basis, mc, roles, form, options.material, one, quadrature));
    }
    until.clear();
    for (const TimedTraction& tr : loads.tractions) until.push_back(tr.until);

    system = parts.jumps;  // layout; values are written per step
    frames = elementFrames(*basis, m);
    activeSolver = options.solver;
    if (options.adaptivePreconditioner) activeSolver.preconditioner = CgPreconditioner::BlockJacobi;
    solver = LinearSolver(activeSolver);
    solverReady = false;
    u = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(ne) * bs);
    v = u;
    a = u;
  }
  std::vector<double> until;

  void buildSlots() {
    const LocalMatrices& l = parts.jumps;
    rowStart.assign(ne + 1, 0);
    slots.clear();
    for (std::size_t i = 0; i < ne; ++i) {
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
        slots.push_back(s);
      }
      rowStart[i + 1] = slots.size();
    }
  }

  void elementTerms() {
    const double rho = options.material.density;
    mass.assign(ne * n * n, 0.0);
    massOne.assign(ne * n, 0.0);
    gradients.assign(ne * 3 * n, 0.0);
    massInverse.assign(ne, Eigen::LLT<Eigen::MatrixXd>());
    x0.resize(static_cast<Eigen::Index>(ne) * bs);
    // o: the undeformed centre of mass (bounded coordinates far from the world's origin).
    Vec3 first = Vec3::Zero();
    double volume = 0.0;
    for (std::size_t i = 0; i < ne; ++i) {
      volume += moments->volume(ElementId(i));
      first += moments->volume(ElementId(i)) * moments->centroid(ElementId(i));
    }
    origin = volume > 0.0 ? Vec3(first / volume) : Vec3::Zero();
    totalMass = rho * volume;
    tbb::parallel_for(std::size_t(0), ne, [&](std::size_t i) {
      const ElementId e(i);
      Eigen::MatrixXd me;
      elementMass(*basis, *moments, e, me);
      me *= rho;
      Eigen::Map<Eigen::MatrixXd>(mass.data() + i * n * n, n, n) = me;
      massInverse[i].compute(me);
      const Eigen::VectorXd one = affineCoefficients(*basis, e, 1.0, Vec3::Zero(), origin);
      Eigen::Map<Eigen::VectorXd>(massOne.data() + i * n, n) = me * one;
      for (int d = 0; d < 3; ++d)
        x0.segment(static_cast<Eigen::Index>(i) * bs + d * n, n) =
            affineCoefficients(*basis, e, 0.0, Vec3::Unit(d), origin);
      // Mean gradients: (1/|K|) int d_k phi_i = (1/|K|) sum_a T(i, a) int d_k m_a.
      const auto t = basis->coefficients(e);
      const auto em = moments->element(e);
      const double h = basis->scale(e), vol = moments->volume(e);
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
            gradients[i * 3 * n + k * n + fn] += t(fn, aIdx) * integral / vol;
        }
    });
  }

  // --- per step ------------------------------------------------------------------------
  /// Element i's mean deformation gradient I + (1/|K|) int_K grad u for the displacement `disp`.
  Eigen::Matrix3d deformationGradient(std::size_t i, const Eigen::VectorXd& disp) const {
    Eigen::Matrix3d f = Eigen::Matrix3d::Identity();
    const double* g = gradients.data() + i * 3 * n;
    const double* ue = disp.data() + i * bs;
    for (int d = 0; d < 3; ++d)
      for (int k = 0; k < 3; ++k) {
        double sum = 0.0;
        for (int fn = 0; fn < n; ++fn) sum += g[k * n + fn] * ue[d * n + fn];
        f(d, k) += sum;
      }
    return f;
  }

  std::vector<Eigen::Matrix3d> rotationsOf(const Eigen::VectorXd& disp) const {
    std::vector<Eigen::Matrix3d> r(ne, Eigen::Matrix3d::Identity());
    if (!options.corotational) return r;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, ne, 256),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                        for (std::size_t i = range.begin(); i != range.end(); ++i)
                          r[i] = polarRotation(deformationGradient(i, disp));
                      });
    return r;
  }

  /// The rotations and the elastic force (with its energy) of the current displacement, kept
  /// until it changes: the report's state() after a step and the next step share them.
  struct ForceAtU {
    std::vector<Eigen::Matrix3d> r;
    Eigen::VectorXd f;
    double energy = 0.0;
    double rotationSeconds = 0.0, forceSeconds = 0.0;
  };
  mutable std::optional<ForceAtU> current;
  const ForceAtU& forceAtU() const {
    if (!current) {
      ForceAtU c;
      const Stopwatch tr;
      c.r = rotationsOf(u);
      c.rotationSeconds = tr.seconds();
      const Stopwatch tf;
      c.f = elasticForce(c.r, u, &c.energy);
      c.forceSeconds = tf.seconds();
      current = std::move(c);
    }
    return *current;
  }

  /// The parts of the block of row element i in `slot`: pointers, layouts and the element
  /// whose rotation warps it (-1: none).
  struct Part {
    const double* b;
    bool columnMajor;  ///< else row-major (read transposed: the other layout)
    std::int64_t source;
  };
  int partsOf(std::size_t i, const RowSlot& s, Part out[3]) const {
    const std::size_t bb = static_cast<std::size_t>(bs) * bs;
    if (s.diagonal) {
      out[0] = {parts.rowStrain.diagonal.data() + i * bb, true, static_cast<std::int64_t>(i)};
      out[1] = {parts.jumps.diagonal.data() + i * bb, true, -1};
      return 2;
    }
    const std::size_t off = s.block * bb;
    const auto self = static_cast<std::int64_t>(i), other = static_cast<std::int64_t>(s.other);
    if (!s.transposed) {  // row-major, stored by i
      out[0] = {parts.rowStrain.coupling.data() + off, false, self};
      out[1] = {parts.columnStrain.coupling.data() + off, false, other};
      out[2] = {parts.jumps.coupling.data() + off, false, -1};
    } else {  // stored by `other` as its rows: read transposed
      out[0] = {parts.rowStrain.coupling.data() + off, true, other};
      out[1] = {parts.columnStrain.coupling.data() + off, true, self};
      out[2] = {parts.jumps.coupling.data() + off, true, -1};
    }
    return 3;
  }

  /// out = sum over blocks of R_S B (R_S^T x_C - z_C) (z null: 0), and if `energy`, the form's
  /// energy 1/2 sum (R_S^T x_A - z_A) . B (R_S^T x_C - z_C).
  void warpedProduct(const std::vector<Eigen::Matrix3d>& r, const Eigen::VectorXd& x,
                     const Eigen::VectorXd* z, Eigen::VectorXd& out, double* energy) const {
    detail::dispatchBasisDegree(
        basis->degree(), [&](auto p) { warpedProductOf<numMonomials(p())>(r, x, z, out, energy); });
  }

  /// warpedProduct() for n = N functions per component (fixed-size kernels).
  template <int N>
  void warpedProductOf(const std::vector<Eigen::Matrix3d>& r, const Eigen::VectorXd& x,
                       const Eigen::VectorXd* z, Eigen::VectorXd& out, double* energy) const {
    constexpr int BS = 3 * N;
    using Vec = Eigen::Matrix<double, BS, 1>;
    using Components = Eigen::Matrix<double, N, 3>;  // column d: component d
    using Block = Eigen::Matrix<double, BS, BS>;
    using RowBlock = Eigen::Matrix<double, BS, BS, Eigen::RowMajor>;
    out.setZero(x.size());
    const bool bz = parts.jumps.componentDiagonalCoupling;
    const std::size_t bb = static_cast<std::size_t>(BS) * BS;
    const double e = tbb::parallel_deterministic_reduce(
        tbb::blocked_range<std::size_t>(0, ne, 64), 0.0,
        [&](const tbb::blocked_range<std::size_t>& range, double sum) {
          Vec w, y, wa, v;
          for (std::size_t i = range.begin(); i != range.end(); ++i) {
            Eigen::Map<Vec> oa(out.data() + i * BS);
            // The vector a side of a block reads: R^T x - z (positions against the undeformed
            // state: the strain side and interior jumps) or R^T (x - z) (the displacement: the
            // jump against a Dirichlet face's fixed outside). (R (x) I)^T acts on the
            // components as V R.
            auto side = [&](const Eigen::Matrix3d* rot, std::size_t el, bool difference, Vec& o) {
              v = Eigen::Map<const Vec>(x.data() + el * BS);
              if (z && difference) v -= Eigen::Map<const Vec>(z->data() + el * BS);
              if (rot)
                Eigen::Map<Components>(o.data()).noalias() =
                    Eigen::Map<const Components>(v.data()) * (*rot);
              else
                o = v;
              if (z && !difference) o -= Eigen::Map<const Vec>(z->data() + el * BS);
            };
            // Row i's block B against column element `col`, warped with element `source`'s
            // rotation (-1: not warped); B column-major or row-major.
            auto apply = [&](const double* b, bool columnMajor, std::int64_t source,
                             std::size_t col, bool rowDifference = false,
                             bool columnDifference = false) {
              const bool warp = source >= 0 && options.corotational;
              const Eigen::Matrix3d* rot = warp ? &r[static_cast<std::size_t>(source)] : nullptr;
              side(rot, col, columnDifference, w);
              if (columnMajor)
                y.noalias() = Eigen::Map<const Block>(b) * w;
              else
                y.noalias() = Eigen::Map<const RowBlock>(b) * w;
              if (rot)
                Eigen::Map<Components>(oa.data()).noalias() +=
                    Eigen::Map<const Components>(y.data()) * rot->transpose();
              else
                oa += y;
              if (energy) {
                side(rot, i, rowDifference, wa);
                sum += 0.5 * wa.dot(y);
              }
            };
            if (!bz) {  // the Dirichlet faces' strain terms
              const auto self = static_cast<std::int64_t>(i);
              apply(parts.dirichletTrial.data() + i * bb, true, self, i, true, false);
              apply(parts.dirichletTest.data() + i * bb, true, self, i, false, true);
            }
            std::size_t neighbour = 0;
            for (std::size_t k = rowStart[i]; k < rowStart[i + 1]; ++k) {
              const RowSlot& s = slots[k];
              if (!s.diagonal && !bz)  // the neighbour's lifting terms in i's diagonal block
                apply(parts.neighbourLifting.data() + (parts.neighbourStart[i] + neighbour++) * bb,
                      true, s.other, i);
              Part ps[3];
              const int np = partsOf(i, s, ps);
              for (int q = 0; q < np; ++q) {
                if (ps[q].source >= 0 && !s.diagonal && bz) continue;  // BZ: no coupling strain
                apply(ps[q].b, ps[q].columnMajor, ps[q].source, s.other);
              }
            }
          }
          return sum;
        },
        std::plus<double>());
    if (energy) *energy = e;
  }

  /// The system matrix cM M + cK K_w with the rotations `r`, into `system` and `matrix`.
  void assembleSystem(const std::vector<Eigen::Matrix3d>& r, double cM, double cK) {
    detail::dispatchBasisDegree(basis->degree(),
                                [&](auto p) { assembleSystemOf<numMonomials(p())>(r, cM, cK); });
    if (!assembled) {
      SpMat k = assembleStiffness(system);
      matrix.swap(k);
    } else {
      refillStiffness(system, matrix);
    }
  }

  template <int N>
  void assembleSystemOf(const std::vector<Eigen::Matrix3d>& r, double cM, double cK) {
    const std::size_t bb = static_cast<std::size_t>(bs) * bs;
    const bool bz = parts.jumps.componentDiagonalCoupling;
    const bool warp = options.corotational;
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, ne, 32),
        [&](const tbb::blocked_range<std::size_t>& range) {
          for (std::size_t i = range.begin(); i != range.end(); ++i) {
            double* d = system.diagonal.data() + i * bb;
            const double* js = parts.jumps.diagonal.data() + i * bb;
            const double* ss = parts.rowStrain.diagonal.data() + i * bb;
            for (std::size_t k = 0; k < bb; ++k) d[k] = cK * js[k];
            if (warp)
              addWarped<N>(r[i], ss, cK, d);
            else
              for (std::size_t k = 0; k < bb; ++k) d[k] += cK * ss[k];
            if (!bz) {
              for (const std::vector<double>* dir : {&parts.dirichletTrial, &parts.dirichletTest}) {
                if (warp)
                  addWarped<N>(r[i], dir->data() + i * bb, cK, d);
                else
                  for (std::size_t q = 0; q < bb; ++q) d[q] += cK * (*dir)[i * bb + q];
              }
              const std::size_t first = parts.neighbourStart[i];
              std::size_t k = 0;
              for (std::uint32_t f : parts.jumps.neighbours[i]) {
                if (f == i) continue;
                const double* nl = parts.neighbourLifting.data() + (first + k++) * bb;
                if (warp)
                  addWarped<N>(r[f], nl, cK, d);
                else
                  for (std::size_t q = 0; q < bb; ++q) d[q] += cK * nl[q];
              }
            }
            const double* me = mass.data() + i * n * n;
            for (int c = 0; c < 3; ++c)
              for (int fi = 0; fi < n; ++fi)
                for (int fj = 0; fj < n; ++fj)
                  d[static_cast<std::size_t>(c * n + fj) * bs + c * n + fi] += cM * me[fj * n + fi];
            const auto& nb = parts.jumps.neighbours[i];
            const auto firstGreater =
                std::upper_bound(nb.begin(), nb.end(), static_cast<std::uint32_t>(i));
            std::size_t slot = parts.jumps.couplingStart[i];
            for (auto it = firstGreater; it != nb.end(); ++it, ++slot) {
              // Coupling blocks are row-major: as column-major they are the transposed block,
              // (R1 B R2^T)^T = R2 B^T R1^T.
              double* c = system.coupling.data() + slot * bb;
              const double* jc = parts.jumps.coupling.data() + slot * bb;
              for (std::size_t k = 0; k < bb; ++k) c[k] = cK * jc[k];
              if (bz) continue;
              const double* rc = parts.rowStrain.coupling.data() + slot * bb;
              const double* oc = parts.columnStrain.coupling.data() + slot * bb;
              if (warp) {
                const Eigen::Matrix3d& rf = r[*it];
                // Read each row-major block column-major (its transpose) and write the
                // transpose of the warped block: R_f B^T R_f^T etc. with the roles swapped.
                addWarped<N>(r[i], rc, cK, c);
                addWarped<N>(rf, oc, cK, c);
              } else {
                for (std::size_t k = 0; k < bb; ++k) c[k] += cK * (rc[k] + oc[k]);
              }
            }
          }
        });
  }

  void massProduct(const Eigen::VectorXd& x, Eigen::VectorXd& out) const {
    out.resize(x.size());
    tbb::parallel_for(std::size_t(0), ne, [&](std::size_t i) {
      const ColMap me(mass.data() + i * n * n, n, n);
      for (int d = 0; d < 3; ++d) {
        const Eigen::Index base = static_cast<Eigen::Index>(i * bs + d * n);
        out.segment(base, n).noalias() = me * x.segment(base, n);
      }
    });
  }

  Eigen::VectorXd external(double time) const {
    Eigen::VectorXd f = gravityForce;
    for (std::size_t k = 0; k < tractionForces.size(); ++k)
      if (time <= until[k] * (1.0 + 1e-12) + 1e-12 * options.dt) f += tractionForces[k];
    return f;
  }

  /// f(disp) with the rotations `r` (and the form's energy if `energy`).
  Eigen::VectorXd elasticForce(const std::vector<Eigen::Matrix3d>& r, const Eigen::VectorXd& disp,
                               double* energy) const {
    const Eigen::VectorXd x = x0 + disp;
    Eigen::VectorXd f;
    warpedProduct(r, x, &x0, f, energy);
    return f;
  }

  /// Newmark: A from M A = F - D V - f(U).
  void equilibriumAcceleration() {
    const std::vector<Eigen::Matrix3d>& r = forceAtU().r;
    Eigen::VectorXd rhs = external(t) - forceAtU().f;
    if (options.massDamping > 0.0 || options.stiffnessDamping > 0.0) {
      Eigen::VectorXd mv, kv;
      massProduct(v, mv);
      warpedProduct(r, v, nullptr, kv, nullptr);
      rhs -= options.massDamping * mv + options.stiffnessDamping * kv;
    }
    tbb::parallel_for(std::size_t(0), ne, [&](std::size_t i) {
      for (int d = 0; d < 3; ++d) {
        const Eigen::Index base = static_cast<Eigen::Index>(i * bs + d * n);
        a.segment(base, n) = massInverse[i].solve(rhs.segment(base, n));
      }
    });
  }

  /// The state the solution x of a step's system gives: U_{n+1} (and V, A through `vOut`,
  /// `aOut` if not null).
  Eigen::VectorXd advance(const Eigen::VectorXd& x, bool bdf2, double c, Eigen::VectorXd* vOut,
                          Eigen::VectorXd* aOut) const {
    const double dt = options.dt;
    switch (options.integrator) {
      case TimeIntegrator::Newmark:
        if (vOut) *vOut = v + dt * ((1.0 - kNewmarkGamma) * a + kNewmarkGamma * x);
        if (aOut) *aOut = x;
        return u + dt * v + dt * dt * ((0.5 - kNewmarkBeta) * a + kNewmarkBeta * x);
      case TimeIntegrator::Bdf2:
        if (vOut) *vOut = x;
        return bdf2 ? Eigen::VectorXd((4.0 * u - uPrevious) / 3.0 + c * x)
                    : Eigen::VectorXd(u + dt * x);
      case TimeIntegrator::BackwardEuler: break;
    }
    if (vOut) *vOut = x;
    return u + dt * x;
  }

  StepReport step() {
    StepReport rep;
    const double dt = options.dt, alpha = options.massDamping, beta = options.stiffnessDamping;
    const bool newmark = options.integrator == TimeIntegrator::Newmark;
    // The rotations and f(U_n): computed here, unless state() already did after the last step;
    // counted in this step's phases either way.
    const ForceAtU& at = forceAtU();
    const std::vector<Eigen::Matrix3d>& r = at.r;
    rep.rotationSeconds = at.rotationSeconds;
    rep.assemblySeconds = at.forceSeconds;

    const Stopwatch t1;
    // BDF2 needs one step behind it; its first step is backward Euler.
    const bool bdf2 = options.integrator == TimeIntegrator::Bdf2 && hasPrevious;
    const double c = bdf2 ? 2.0 * dt / 3.0 : dt;
    const double cM = newmark ? 1.0 + kNewmarkGamma * dt * alpha : 1.0 + c * alpha;
    const double cK =
        newmark ? kNewmarkGamma * dt * beta + kNewmarkBeta * dt * dt : c * beta + c * c;
    // A new matrix with new rotations, and when BDF2's coefficients replace its first step's.
    const bool newMatrix = !assembled || options.corotational || cK != lastCK;
    lastCK = cK;
    if (newMatrix) assembleSystem(r, cM, cK);
    const double t1Time = t + dt;
    // The right-hand side without the elastic force: it enters as g = f(U_n), or, in the
    // corrections of a corotated step, as f(U^k) - K_w (U^k - U_n).
    Eigen::VectorXd base, mv;
    double forceScale = 0.0;  // the elastic force's factor in the right-hand side
    if (bdf2) {
      Eigen::VectorXd kd;
      warpedProduct(r, (u - uPrevious) / 3.0, nullptr, kd, nullptr);
      massProduct((4.0 * v - vPrevious) / 3.0, mv);
      base = mv + c * (external(t1Time) - kd);
      forceScale = c;
    } else if (!newmark) {
      massProduct(v, mv);
      base = mv + dt * external(t1Time);
      forceScale = dt;
    } else {
      const Eigen::VectorXd w1 = v + (1.0 - kNewmarkGamma) * dt * a;
      const Eigen::VectorXd w2 = beta * w1 + dt * v + (0.5 - kNewmarkBeta) * dt * dt * a;
      Eigen::VectorXd kw;
      warpedProduct(r, w2, nullptr, kw, nullptr);
      base = external(t1Time) - kw;
      if (alpha > 0.0) {
        massProduct(w1, mv);
        base -= alpha * mv;
      }
      forceScale = 1.0;
    }
    rep.assemblySeconds += t1.seconds();

    // Contact (physics/contact/contact.h): K_c and the friction damping C_t enter like K and D.
    // With U_{n+1} = U0 + cU x and V_{n+1} = V0 + cV x (advance() of x = 0 gives U0, V0), the
    // contact force f_c - K_c (U_{n+1} - U_n) - C_t V_{n+1} adds forceScale (cU K_c + cV C_t)
    // to the matrix and forceScale (f_c - K_c (U0 - U_n) - C_t V0) to the right-hand side.
    ContactLinearization contactTerms;
    Eigen::VectorXd u0, v0;
    double cU = 0.0, cV = 0.0;
    if (contact) {
      const Stopwatch tq;
      contactTerms = contact->linearize(u, v, t1Time, dt);
      const Eigen::VectorXd zero = Eigen::VectorXd::Zero(u.size());
      u0 = advance(zero, bdf2, c, &v0, nullptr);
      cU = newmark ? kNewmarkBeta * dt * dt : c;
      cV = newmark ? kNewmarkGamma * dt : 1.0;
      rep.assemblySeconds += tq.seconds();
    }
    auto contactRhs = [&]() {
      Eigen::VectorXd add = contactTerms.force - contactTerms.stiffness * (u0 - u);
      if (contactTerms.damping.nonZeros() > 0) add -= contactTerms.damping * v0;
      return Eigen::VectorXd(forceScale * add);
    };

    const Stopwatch t2;
    if (switchToMultigrid) {  // block-Jacobi took too many iterations: the p-multigrid pays
      activeSolver.preconditioner = CgPreconditioner::PMultigrid;
      solver = LinearSolver(activeSolver);
      solverReady = false;
      switchToMultigrid = false;
    }
    // The solver for the matrix without contact terms: factorized, or updated.
    auto prepare = [&]() {
      if (!solverReady) {
        const bool direct = chooseSolver(matrix, activeSolver) == SolverKind::Cholesky;
        if (!solver.compute(matrix, bs, direct ? nullptr : &frames) && direct)
          throw std::runtime_error(
              "the time step's system matrix is not positive definite (a corotated element "
              "turned inside out?)");
        rep.refactorized = direct;
        rep.preconditionerRebuilt = !direct;
        assembled = true;
        solverReady = true;
        baselineIterations = -1;
      } else if (newMatrix) {
        const bool direct = solver.kind() == SolverKind::Cholesky;
        const bool refresh =
            !direct && baselineIterations >= 0 &&
            lastIterations > options.refreshRatio * std::max(baselineIterations, 1);
        if (!solver.update(matrix, refresh, &frames) && direct)
          throw std::runtime_error(
              "the time step's system matrix is not positive definite (a corotated element "
              "turned inside out?)");
        rep.refactorized = direct;
        rep.preconditionerRebuilt = refresh;
        if (refresh) baselineIterations = -1;
      }
    };
    // With contacts: the matrix plus the contact terms, another pattern: factorized (or its
    // preconditioner built) anew; the next step without contacts starts over as well.
    auto prepareWithContact = [&]() {
      contactMatrix = matrix + (forceScale * cU) * contactTerms.stiffness;
      if (contactTerms.damping.nonZeros() > 0)
        contactMatrix += (forceScale * cV) * contactTerms.damping;
      const bool direct = chooseSolver(contactMatrix, activeSolver) == SolverKind::Cholesky;
      if (!solver.compute(contactMatrix, bs, direct ? nullptr : &frames) && direct)
        throw std::runtime_error(
            "the time step's system matrix with contacts is not positive definite");
      rep.refactorized = direct;
      rep.preconditionerRebuilt = !direct;
      assembled = true;
      solverReady = false;
      baselineIterations = -1;
    };
    auto solve = [&](const Eigen::VectorXd& b, const Eigen::VectorXd& guess) {
      LinearSolveReport lr;
      Eigen::VectorXd x = solver.solve(b, lr, &guess);
      if (!lr.success)
        throw std::runtime_error("the time step's solve failed (CG did not converge, residual " +
                                 std::to_string(lr.residual) + ")");
      rep.iterations += lr.iterations;
      rep.residual = lr.residual;
      return x;
    };
    // Warm start: the unknown (Newmark: A, else V) extrapolated linearly from the last two
    // steps (the last step's alone after a start or a cut).
    const Eigen::VectorXd& last = newmark ? a : v;
    const Eigen::VectorXd firstGuess =
        hasGuessHistory ? Eigen::VectorXd(2.0 * last - previousUnknown) : last;
    const int maxSolves = corrections();
    const int maxPasses = contact ? contact->options().maxPasses : 1;
    const Eigen::VectorXd base0 = std::move(base);
    rep.solves = 0;
    double notSolving = 0.0;  // rotations and forces of the corrections, contact updates
    Eigen::VectorXd x;
    for (int pass = 1;; ++pass) {
      rep.contacts = contactTerms.contacts;
      rep.contactPasses = pass;
      base = contactTerms.empty() ? base0 : Eigen::VectorXd(base0 + contactRhs());
      Eigen::VectorXd rhs = base - forceScale * at.f;
      if (contactTerms.empty())
        prepare();
      else
        prepareWithContact();
      x = solve(rhs, pass == 1 ? firstGuess : x);
      ++rep.solves;
      // Corotation: correct the once-linearized force (modified Newton with the step's matrix):
      // f(U_{n+1}) ~ f(U^k) + K_w (U_{n+1} - U^k), U^k the last solution's state.
      for (int k = 1; k < maxSolves; ++k) {
        const Stopwatch tc;
        const Eigen::VectorXd uk = advance(x, bdf2, c, nullptr, nullptr);
        const std::vector<Eigen::Matrix3d> rk = rotationsOf(uk);
        const double rotating = tc.seconds();
        rep.rotationSeconds += rotating;
        notSolving += rotating;
        const Stopwatch tf;
        Eigen::VectorXd kd;
        const Eigen::VectorXd fk = elasticForce(rk, uk, nullptr);
        warpedProduct(r, uk - u, nullptr, kd, nullptr);
        rhs = base - forceScale * (fk - kd);
        const double forcing = tf.seconds();
        rep.assemblySeconds += forcing;
        notSolving += forcing;
        Eigen::VectorXd next = solve(rhs, x);
        ++rep.solves;
        const double change = (next - x).norm(), size = next.norm();
        x = std::move(next);
        rep.correction = size > 0.0 ? change / size : change;
        if (options.corotationSolves <= 0 && rep.correction <= options.correctionTolerance) break;
      }
      // The active set: contacts that would pull leave, points that ended inside join.
      if (!contact || pass >= maxPasses) break;
      const Stopwatch tq;
      const bool changed = contact->adjust(advance(x, bdf2, c, nullptr, nullptr));
      if (changed) contactTerms = contact->relinearize();
      const double adjusting = tq.seconds();
      rep.assemblySeconds += adjusting;
      notSolving += adjusting;
      if (!changed) break;
    }
    previousUnknown = last;
    hasGuessHistory = true;
    rep.solveSeconds = t2.seconds() - notSolving;
    if (contact) rep.contactQuerySeconds = contact->takeQuerySeconds();
    lastIterations = rep.iterations;
    if (baselineIterations < 0) baselineIterations = rep.iterations;
    rep.preconditioner = activeSolver.preconditioner;
    if (solver.kind() == SolverKind::ConjugateGradient && options.adaptivePreconditioner &&
        activeSolver.preconditioner == CgPreconditioner::BlockJacobi &&
        rep.iterations > kBlockJacobiLimit * rep.solves)
      switchToMultigrid = true;

    Eigen::VectorXd vNew, aNew;
    Eigen::VectorXd uNew = advance(x, bdf2, c, &vNew, newmark ? &aNew : nullptr);
    if (options.integrator == TimeIntegrator::Bdf2) {
      uPrevious = std::move(u);
      vPrevious = std::move(v);
      hasPrevious = true;
    }
    u = std::move(uNew);
    current.reset();  // r, and `at`, belong to the old displacement
    v = std::move(vNew);
    if (newmark) a = std::move(aNew);
    t = t1Time;
    rep.t = t;
    return rep;
  }

  /// The most solves per step (see DynamicsOptions::corotationSolves).
  int corrections() const {
    if (!options.corotational) return 1;
    if (options.corotationSolves > 0) return options.corotationSolves;
    return options.integrator == TimeIntegrator::BackwardEuler ? 1 : kMaxAutomaticSolves;
  }

  BodyState bodyState() const {
    BodyState s;
    s.elastic = forceAtU().energy;
    s.gravity = -gravityForce.dot(u);
    for (std::size_t k = 0; k < tractionForces.size(); ++k)
      if (t <= until[k] * (1.0 + 1e-12) + 1e-12 * options.dt)
        s.tractionPotential -= tractionForces[k].dot(u);
    const Eigen::VectorXd q = x0 + u;  // x - o + u
    Eigen::VectorXd mv;
    massProduct(v, mv);
    s.kinetic = 0.5 * v.dot(mv);
    Vec3 first = Vec3::Zero();
    for (std::size_t i = 0; i < ne; ++i) {
      const Eigen::Map<const Eigen::VectorXd> one(massOne.data() + i * n, n);
      for (int d = 0; d < 3; ++d) {
        const Eigen::Index base = static_cast<Eigen::Index>(i * bs + d * n);
        s.momentum[d] += one.dot(v.segment(base, n));
        first[d] += one.dot(q.segment(base, n));
      }
      // int rho q_a v_b = Q_a . (M V_b)
      Eigen::Matrix3d qv;
      for (int aa = 0; aa < 3; ++aa)
        for (int b = 0; b < 3; ++b)
          qv(aa, b) = q.segment(static_cast<Eigen::Index>(i * bs + aa * n), n)
                          .dot(mv.segment(static_cast<Eigen::Index>(i * bs + b * n), n));
      s.angularMomentum += Vec3(qv(1, 2) - qv(2, 1), qv(2, 0) - qv(0, 2), qv(0, 1) - qv(1, 0));
    }
    s.centreOfMass = origin + (totalMass > 0.0 ? Vec3(first / totalMass) : Vec3::Zero());
    return s;
  }

  double deformedVolume() const {
    const int p = basis->degree();
    return tbb::parallel_deterministic_reduce(
        tbb::blocked_range<std::size_t>(0, ne, 64), 0.0,
        [&](const tbb::blocked_range<std::size_t>& range, double sum) {
          for (std::size_t i = range.begin(); i != range.end(); ++i) {
            const ElementId e(i);
            if (p == 1) {  // constant gradient
              sum += deformationGradient(i, u).determinant() * moments->volume(e);
              continue;
            }
            for (const QuadraturePoint& qp : elementQuadrature(*mesh, e, 3 * (p - 1)))
              sum += qp.weight *
                     (Eigen::Matrix3d::Identity() + displacementGradientAt(*basis, u, e, qp.point))
                         .determinant();
          }
          return sum;
        },
        std::plus<double>());
  }
};

DynamicSolver::DynamicSolver(const PolyMesh& mesh, const MomentCache& moments,
                             const DynamicLoads& loads, const DynamicsOptions& options)
    : impl_(std::make_unique<Impl>()) {
  impl_->setup(mesh, moments, loads, options);
  if (options.integrator == TimeIntegrator::Newmark) impl_->equilibriumAcceleration();
}
DynamicSolver::~DynamicSolver() = default;
DynamicSolver::DynamicSolver(DynamicSolver&&) noexcept = default;
DynamicSolver& DynamicSolver::operator=(DynamicSolver&&) noexcept = default;

const DgBasis& DynamicSolver::basis() const { return *impl_->basis; }
SolverKind DynamicSolver::solverKind() const { return impl_->solver.kind(); }
const DynamicsOptions& DynamicSolver::options() const { return impl_->options; }
std::size_t DynamicSolver::dofs() const { return static_cast<std::size_t>(impl_->u.size()); }
double DynamicSolver::time() const { return impl_->t; }
const Eigen::VectorXd& DynamicSolver::displacement() const { return impl_->u; }
const Eigen::VectorXd& DynamicSolver::velocity() const { return impl_->v; }
const std::vector<std::size_t>& DynamicSolver::clampFaces() const { return impl_->clampFaces; }
const std::vector<std::size_t>& DynamicSolver::tractionFaces() const {
  return impl_->tractionFaces;
}
const Vec3& DynamicSolver::referencePoint() const { return impl_->origin; }
double DynamicSolver::mass() const { return impl_->totalMass; }

void DynamicSolver::setState(double t, const Eigen::VectorXd& displacement,
                             const Eigen::VectorXd& velocity) {
  Impl& m = *impl_;
  if (displacement.size() != m.u.size() || velocity.size() != m.v.size())
    throw std::invalid_argument("DynamicSolver::setState: vectors of the wrong size");
  m.t = t;
  m.u = displacement;
  m.current.reset();
  m.v = velocity;
  m.hasPrevious = false;  // BDF2 starts again with a backward Euler step
  m.hasGuessHistory = false;
  if (m.options.integrator == TimeIntegrator::Newmark) m.equilibriumAcceleration();
}

StepReport DynamicSolver::step() { return impl_->step(); }
void DynamicSolver::setContact(ContactModel* contact) {
  impl_->contact = contact;
  impl_->solverReady = false;
}
BodyState DynamicSolver::state() const { return impl_->bodyState(); }

Eigen::VectorXd DynamicSolver::elasticForce() const { return impl_->forceAtU().f; }
Eigen::VectorXd DynamicSolver::externalForce(double t) const { return impl_->external(t); }
double DynamicSolver::deformedVolume() const { return impl_->deformedVolume(); }

Eigen::VectorXd DynamicSolver::affineField(const Eigen::Matrix3d& a, const Vec3& b,
                                           const Vec3& c) const {
  const Impl& m = *impl_;
  Eigen::VectorXd out(static_cast<Eigen::Index>(m.ne) * m.bs);
  tbb::parallel_for(std::size_t(0), m.ne, [&](std::size_t i) {
    for (int d = 0; d < 3; ++d)
      out.segment(static_cast<Eigen::Index>(i * m.bs + d * m.n), m.n) =
          affineCoefficients(*m.basis, ElementId(i), b[d], a.row(d).transpose(), c);
  });
  return out;
}

std::vector<double> DynamicSolver::vonMises() const {
  const Impl& m = *impl_;
  std::vector<double> out(m.ne);
  const double mu = m.options.material.mu(), lambda = m.options.material.lambda();
  tbb::parallel_for(std::size_t(0), m.ne, [&](std::size_t i) {
    const Eigen::Matrix3d f = m.deformationGradient(i, m.u);
    const Eigen::Matrix3d local =
        m.options.corotational ? Eigen::Matrix3d(polarRotation(f).transpose() * f) : f;
    const Eigen::Matrix3d eps = 0.5 * (local + local.transpose()) - Eigen::Matrix3d::Identity();
    const Eigen::Matrix3d sigma = 2 * mu * eps + lambda * eps.trace() * Eigen::Matrix3d::Identity();
    const Eigen::Matrix3d dev = sigma - sigma.trace() / 3.0 * Eigen::Matrix3d::Identity();
    out[i] = std::sqrt(1.5 * dev.squaredNorm());
  });
  return out;
}

std::vector<Eigen::Matrix3d> DynamicSolver::rotations() const { return impl_->forceAtU().r; }

}  // namespace polydg
