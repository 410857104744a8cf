#include "physics/dg/local_integrators.h"

#include <cmath>

#include "physics/dg/polynomial_tables.h"

namespace polydg {

namespace {

/// The degree-P kernels. Fixed-size matrices: N = numMonomials(P) functions per component,
/// N1 = numMonomials(P - 1) lifting functions. Products are lazyProduct(): coefficient-based
/// and unrolled for these small fixed sizes, where Eigen's default GEMM path (packing, for
/// sizes past its threshold of 20) spent a third of the assembly time.
template <int P>
struct Kernel {
  using Tab = detail::PolyTables<P>;
  static constexpr int N = Tab::N;
  static constexpr int N1 = Tab::N1;
  static constexpr int N2 = Tab::N2;
  using Mat = Eigen::Matrix<double, N, N>;
  using Mat1 = Eigen::Matrix<double, N1, N>;
  using Mat11 = Eigen::Matrix<double, N1, N1>;

  /// int m_a m_b from moments about the monomials' centre, divided by h^(|a|+|b|).
  static Mat gram(std::span<const double> moments, double h) {
    double scaled[N2];
    double hp[2 * P + 1];
    hp[0] = 1.0;
    for (int k = 1; k <= 2 * P; ++k) hp[k] = hp[k - 1] / h;
    for (int g = 0; g < N2; ++g) scaled[g] = moments[g] * hp[kMonomialTable[g].degree()];
    Mat m;
    for (int a = 0; a < N; ++a)
      for (int b = 0; b < N; ++b) m(a, b) = scaled[Tab::sum[a][b]];
    return m;
  }

  /// R with d/dx_k (t m)(x) = (R m)(x) * h for monomials m scaled by h: R(i, pred(a)) +=
  /// power_k(a) t(i, a).
  static Mat derive(const Mat& t, int k) {
    Mat r = Mat::Zero();
    for (int a = 0; a < N; ++a) {
      const int b = Tab::pred[k][a];
      if (b >= 0) r.col(b) += Tab::power[k][a] * t.col(a);
    }
    return r;
  }

  /// S with m_a((x - c)/h) = sum_b S(a, b) y^b for x = r + hF y: the binomial expansion of
  /// (sigma y + d)^a, sigma = hF / h, d = (r - c) / h.
  static Mat shift(double sigma, const Vec3& d) {
    if constexpr (P == 1) {  // (sigma y_k + d_k)^1: the products below, without their ones
      static_assert(monomialIndex(1, 0, 0) == 1 && monomialIndex(0, 1, 0) == 2 &&
                    monomialIndex(0, 0, 1) == 3);
      Mat s = Mat::Zero();
      s(0, 0) = 1.0;
      for (int k = 0; k < 3; ++k) {
        s(1 + k, 0) = d[k];
        s(1 + k, 1 + k) = sigma;
      }
      return s;
    }
    double sp[P + 1], dp[3][P + 1];
    sp[0] = 1.0;
    for (int k = 0; k < 3; ++k) dp[k][0] = 1.0;
    for (int m = 1; m <= P; ++m) {
      sp[m] = sp[m - 1] * sigma;
      for (int k = 0; k < 3; ++k) dp[k][m] = dp[k][m - 1] * d[k];
    }
    Mat s = Mat::Zero();
    for (int a = 0; a < N; ++a)
      for (int b = 0; b < N; ++b) {
        double v = 1.0;
        for (int k = 0; k < 3 && v != 0.0; ++k) {
          const int pa = Tab::power[k][a], pb = Tab::power[k][b];
          if (pb > pa)
            v = 0.0;
          else
            v *= Tab::binomial[pa][pb] * sp[pb] * dp[k][pa - pb];
        }
        s(a, b) = v;
      }
    return s;
  }

  static Mat coefficients(const DgBasis& basis, ElementId e) { return Mat(basis.coefficients(e)); }

  // --- elements ------------------------------------------------------------------------
  static void stiffness(const DgBasis& basis, const MomentCache& moments, ElementId e, double mu,
                        double lambda, Eigen::MatrixXd& out) {
    const double h = basis.scale(e);
    const Mat g = gram(moments.element(e), h);
    const Mat t = coefficients(basis, e);
    Mat r[3];
    for (int k = 0; k < 3; ++k) r[k] = derive(t, k) / h;
    Mat rg[3];
    for (int k = 0; k < 3; ++k) rg[k] = r[k].lazyProduct(g);
    Mat gd[3][3];  // gd[k][l](i, j) = int d_k phi_i d_l phi_j
    for (int k = 0; k < 3; ++k)
      for (int l = k; l < 3; ++l) {
        gd[k][l] = rg[k].lazyProduct(r[l].transpose());
        if (l != k) gd[l][k] = gd[k][l].transpose();
      }
    const Mat lap = gd[0][0] + gd[1][1] + gd[2][2];
    out.resize(3 * N, 3 * N);
    for (int d = 0; d < 3; ++d)
      for (int c = 0; c < 3; ++c) {
        Mat b = mu * gd[c][d] + lambda * gd[d][c];
        if (c == d) b += mu * lap;
        out.template block<N, N>(d * N, c * N) = b;
      }
  }

  static void mass(const DgBasis& basis, const MomentCache& moments, ElementId e,
                   Eigen::MatrixXd& out) {
    const Mat t = coefficients(basis, e);
    out = t * gram(moments.element(e), basis.scale(e)) * t.transpose();
  }

  // --- faces ---------------------------------------------------------------------------
  /// One element's functions expressed in the face's scaled monomials y^b.
  struct Side {
    Mat p;     ///< phi_i = sum_b p(i, b) y^b
    Mat q[3];  ///< d phi_i / dx_k = sum_b q[k](i, b) y^b
    Mat1 psi;  ///< lifting functions psi_q = sum_b psi(q, b) y^b
  };

  struct FaceFrame {
    Vec3 origin;
    double h = 1.0;
    Mat gram;  ///< int_F y^a y^b
  };

  static FaceFrame frame(const PolyMesh& mesh, const MomentCache& moments, FaceId f) {
    FaceFrame fr;
    fr.origin = faceReferencePoint(mesh, f);
    fr.h = 0.5 * faceBounds(mesh, f).diagonal().norm();
    fr.gram = gram(moments.face(f), fr.h);
    return fr;
  }

  /// Which parts of a Side to compute: BZ needs the values only, the penalty bound the
  /// lifting functions only (the derivatives were a third of BZ's assembly time).
  enum Parts { kValues = 1, kDerivatives = 2, kLifting = 4, kAll = 7 };

  static Side side(const DgBasis& basis, const FaceFrame& fr, ElementId e, int parts = kAll) {
    const double h = basis.scale(e);
    const Mat s = shift(fr.h / h, (fr.origin - basis.centre(e)) / h);
    const Mat t = coefficients(basis, e);
    Side sd;
    if (parts & kValues) sd.p = t.lazyProduct(s);
    if constexpr (P == 1) {
      // The gradients and the lifting functions are constants, and the constant's row of the
      // shift is (1, 0, 0, 0): the products below would only copy them.
      if (parts & kDerivatives)
        for (int k = 0; k < 3; ++k) sd.q[k] = derive(t, k) / h;
      if (parts & kLifting) {
        sd.psi.setZero();
        sd.psi(0, 0) = basis.liftingCoefficients(e)(0, 0);
      }
    } else {
      if (parts & kDerivatives)
        for (int k = 0; k < 3; ++k) sd.q[k] = (derive(t, k) / h).lazyProduct(s);
      if (parts & kLifting) {
        const Mat11 o(basis.liftingCoefficients(e));
        sd.psi = o.lazyProduct(s.template topRows<N1>());
      }
    }
    return sd;
  }

  /// The coefficients of the IP strain and lifting terms of a block (faceRows()).
  struct StrainWeights {
    Vec3 n;        ///< out of self
    double w, sb;  ///< the average's weight; +1 self's columns, -1 the other's
    double mu, lambda;
    double lift;         ///< the lifting term's weight over o_E^2 (degree 1)
    double trial, test;  ///< 1 or 0: the consistency, the symmetry terms
  };

  /// Degree 1's strain and lifting terms of the block of self (sk, ck = G p_K^T) against B
  /// (b, cb). The gradients g are constant and the lifting space is the constants, so each term
  /// is an outer product of a_i = int_F phi^K_i or g^K_i with g^B_j or b_j = int_F phi^B_j: the
  /// block (d, c) is a r^T + u b^T, what the matrix products of faceRows() give at any degree.
  static void addOuterProductTerms(const Side& sk, const Side& b, const Mat& ck, const Mat& cb,
                                   const StrainWeights& x, Eigen::MatrixXd& out) {
    using Vec = Eigen::Matrix<double, N, 1>;
    const Vec a = ck.row(0).transpose(), bj = cb.row(0).transpose();
    Vec gK[3], gB[3];
    for (int k = 0; k < 3; ++k) {
      gK[k] = sk.q[k].col(0);
      gB[k] = b.q[k].col(0);
    }
    const Vec3& n = x.n;
    const Vec gnK = n.x() * gK[0] + n.y() * gK[1] + n.z() * gK[2];
    const Vec gnB = n.x() * gB[0] + n.y() * gB[1] + n.z() * gB[2];
    const double w = x.w, sb = x.sb, mu = x.mu, lambda = x.lambda, ct = x.trial, cv = x.test;
    for (int d = 0; d < 3; ++d)
      for (int c = 0; c < 3; ++c) {
        Vec r = (-ct * w * mu * n[c]) * gB[d] + (-ct * w * lambda * n[d]) * gB[c] +
                (lambda * w * w * sb * n[d] * n[c] * x.lift) * bj;
        Vec u = (-cv * w * sb * mu * n[d]) * gK[c] + (-cv * w * sb * lambda * n[c]) * gK[d];
        if (c == d) {
          r += (-ct * w * mu) * gnB;
          u += (-cv * w * sb * mu) * gnK;
        }
        out.template block<N, N>(d * N, c * N) += a * r.transpose() + u * bj.transpose();
      }
  }

  static void faceRows(const PolyMesh& mesh, const DgBasis& basis, const MomentCache& moments,
                       const FaceView& view, const FormCoefficients& form,
                       Eigen::MatrixXd& selfBlock, Eigen::MatrixXd& otherBlock, bool withOther,
                       int terms, bool genericAtDegreeOne = false) {
    const bool trialStrain = terms & kTrialStrainTerms, testStrain = terms & kTestStrainTerms,
               jump = terms & kJumpTerms, otherLift = terms & kOtherLiftingTerms;
    const bool interior = view.kind == FaceKind::Interior;
    const FaceFrame fr = frame(mesh, moments, view.face);
    const Vec3 n =
        view.selfIsFront ? moments.faceNormal(view.face) : Vec3(-moments.faceNormal(view.face));
    const ElementId other = interior ? view.other : ElementId();
    const double etaF = facePenalty(form, moments, view.face, view.self, other);
    // The face mean's extra penalty over |F|.
    const double etaMean =
        faceMeanPenalty(form, moments, view.face, view.self, other) / moments.area(view.face);
    const double w = interior ? 0.5 : 1.0;
    const double mu = form.mu, lambda = form.lambda;
    const bool ip = form.method == Method::IP;

    const int parts = ip ? kAll : kValues;
    const Side sk = side(basis, fr, view.self, parts);
    Side sl;
    if (interior) sl = side(basis, fr, view.other, parts);
    const Mat ck = fr.gram.lazyProduct(sk.p.transpose());
    Mat cl;
    if (interior) cl = fr.gram.lazyProduct(sl.p.transpose());
    const double cK = view.selfCoupledFaces, cL = view.otherCoupledFaces;
    const bool structured = P == 1 && !genericAtDegreeOne;
    Mat ak;
    if (ip && !structured) ak = sk.p.lazyProduct(fr.gram);
    // Lifting face matrices psi_E against phi_X: mpsi[E][X] = psi_E G phi_X^T (N1 x N).
    Mat1 mkk = Mat1::Zero(), mkl = Mat1::Zero(), mlk = Mat1::Zero(), mll = Mat1::Zero();
    if (ip && !structured) {
      mkk = sk.psi.lazyProduct(ck);
      if (interior) {
        mkl = sk.psi.lazyProduct(cl);
        mlk = sl.psi.lazyProduct(ck);
        mll = sl.psi.lazyProduct(cl);
      }
    }

    auto block = [&](const Side& b, const Mat& cb, double sb, const Mat1* liftK, const Mat1* liftL,
                     Eigen::MatrixXd& out) {
      out.setZero(3 * N, 3 * N);
      if (jump) {
        Mat m = sk.p.lazyProduct(cb);
        // The face mean's extra penalty: int_F phi^K_i int_F phi^B_j (cb's row 0 holds
        // int_F y^0 phi^B_j).
        if (etaMean != 0.0) m += (etaMean / etaF) * (sk.p.lazyProduct(fr.gram.col(0))) * cb.row(0);
        for (int d = 0; d < 3; ++d) out.template block<N, N>(d * N, d * N) += (mu * etaF * sb) * m;
      }
      if (!ip) return;
      if (structured) {
        double lift = 0.0;  // psi_E = o_E: (psi_E phi_K)^T (psi_E phi_B) = o_E^2 a b^T
        if (testStrain) lift += cK * sk.psi(0, 0) * sk.psi(0, 0);
        if (liftL && otherLift) lift += cL * sl.psi(0, 0) * sl.psi(0, 0);
        const StrainWeights weights{
            n, w, sb, mu, lambda, lift, trialStrain ? 1.0 : 0.0, testStrain ? 1.0 : 0.0};
        addOuterProductTerms(sk, b, ck, cb, weights, out);
        return;
      }
      Mat wk[3], vk[3];  // wk: int phi^K_i d_k phi^B_j; vk: int d_k phi^K_i phi^B_j
      for (int k = 0; k < 3; ++k) {
        wk[k] = ak.lazyProduct(b.q[k].transpose());
        vk[k] = sk.q[k].lazyProduct(cb);
      }
      const Mat wn = n.x() * wk[0] + n.y() * wk[1] + n.z() * wk[2];
      const Mat vn = n.x() * vk[0] + n.y() * vk[1] + n.z() * vk[2];
      // Lifting: sum_E c_E (psi_E phi_K)^T (psi_E phi_B).
      // Groups (see FaceTerms): the consistency terms hold the strain of the trial function
      // (of element B), the symmetry terms that of the test function (of self); the lifting
      // terms complete the square of each element's lambda terms and go with that element.
      Mat lift = Mat::Zero();
      if (testStrain) lift += cK * liftK[0].transpose().lazyProduct(liftK[1]);
      if (liftL && otherLift) lift += cL * liftL[0].transpose().lazyProduct(liftL[1]);
      const double ct = trialStrain ? 1.0 : 0.0, cv = testStrain ? 1.0 : 0.0;
      for (int d = 0; d < 3; ++d)
        for (int c = 0; c < 3; ++c) {
          Mat blk = (-ct * w * mu * n[c]) * wk[d] + (-ct * w * lambda * n[d]) * wk[c] +
                    (-cv * w * sb * mu * n[d]) * vk[c] + (-cv * w * sb * lambda * n[c]) * vk[d] +
                    (lambda * w * w * sb * n[d] * n[c]) * lift;
          if (c == d) blk += (-ct * w * mu) * wn + (-cv * w * sb * mu) * vn;
          out.template block<N, N>(d * N, c * N) += blk;
        }
    };

    const Mat1 kk[2] = {mkk, mkk};
    if (interior) {
      const Mat1 llk[2] = {mlk, mlk};
      block(sk, ck, 1.0, kk, llk, selfBlock);
      if (withOther) {
        const Mat1 kl[2] = {mkk, mkl};
        const Mat1 ll[2] = {mlk, mll};
        block(sl, cl, -1.0, kl, ll, otherBlock);
      } else {
        otherBlock.resize(0, 0);
      }
    } else {
      block(sk, ck, 1.0, kk, nullptr, selfBlock);
      otherBlock.resize(0, 0);
    }
  }

  static Eigen::MatrixXd liftingGram(const DgBasis& basis, const MomentCache& moments,
                                     const PolyMesh& mesh, FaceId f, ElementId e) {
    const FaceFrame fr = frame(mesh, moments, f);
    const Side s = side(basis, fr, e, kLifting);
    const Mat1 pg = s.psi.lazyProduct(fr.gram);
    return Eigen::MatrixXd(pg.lazyProduct(s.psi.transpose()));
  }
};

}  // namespace

void elementStiffness(const DgBasis& basis, const MomentCache& moments, ElementId e, double mu,
                      double lambda, Eigen::MatrixXd& out) {
  detail::dispatchBasisDegree(
      basis.degree(), [&](auto p) { Kernel<p()>::stiffness(basis, moments, e, mu, lambda, out); });
}

void elementMass(const DgBasis& basis, const MomentCache& moments, ElementId e,
                 Eigen::MatrixXd& out) {
  detail::dispatchBasisDegree(basis.degree(),
                              [&](auto p) { Kernel<p()>::mass(basis, moments, e, out); });
}

double facePenalty(const FormCoefficients& form, const MomentCache& moments, FaceId f,
                   ElementId self, ElementId other) {
  auto eta = [&](ElementId e) { return form.elementEta ? (*form.elementEta)[e] : form.eta; };
  auto area = [&](ElementId e) {
    return form.elementFaceArea ? (*form.elementFaceArea)[e] : moments.area(f);
  };
  double sum = eta(self) * area(self) / moments.volume(self);
  if (other.valid()) sum += eta(other) * area(other) / moments.volume(other);
  const bool factored = form.method == Method::BZ && !form.bzFactorOnMean;
  return sum * (factored ? form.bzFactor : 1.0);
}

double faceMeanPenalty(const FormCoefficients& form, const MomentCache& moments, FaceId f,
                       ElementId self, ElementId other) {
  if (form.method != Method::BZ || !form.bzFactorOnMean) return 0.0;
  return (form.bzFactor - 1.0) * facePenalty(form, moments, f, self, other);
}

void faceRows(const PolyMesh& mesh, const DgBasis& basis, const MomentCache& moments,
              const FaceView& view, const FormCoefficients& form, Eigen::MatrixXd& selfBlock,
              Eigen::MatrixXd& otherBlock, bool withOther, int terms) {
  detail::dispatchBasisDegree(basis.degree(), [&](auto p) {
    Kernel<p()>::faceRows(mesh, basis, moments, view, form, selfBlock, otherBlock, withOther,
                          terms);
  });
}

namespace detail {

void faceRowsByMatrixProducts(const PolyMesh& mesh, const DgBasis& basis,
                              const MomentCache& moments, const FaceView& view,
                              const FormCoefficients& form, Eigen::MatrixXd& selfBlock,
                              Eigen::MatrixXd& otherBlock, bool withOther, int terms) {
  dispatchBasisDegree(basis.degree(), [&](auto p) {
    Kernel<p()>::faceRows(mesh, basis, moments, view, form, selfBlock, otherBlock, withOther, terms,
                          true);
  });
}

}  // namespace detail

Eigen::MatrixXd liftingFaceGram(const DgBasis& basis, const MomentCache& moments,
                                const PolyMesh& mesh, FaceId f, ElementId e) {
  return detail::dispatchBasisDegree(
      basis.degree(), [&](auto p) { return Kernel<p()>::liftingGram(basis, moments, mesh, f, e); });
}

}  // namespace polydg
