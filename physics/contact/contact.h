// Collision response with penalty forces on embedded points (Kaufmann et al. 2008, section 9;
// Kaufmann 2013, section 4.6): points of an embedding (surface vertices, or the mesh's boundary
// nodes) against obstacles (physics/contact/obstacles.h), the force linearized into the implicit
// step.
//
// Penalty. A point c with the signed distance phi_c < 0 to an obstacle gets the force
//   f_c = k a_c (-phi_c) n_c
// (k the stiffness: pressure per unit penetration; a_c the point's share of the surface area;
// n_c the obstacle's outward normal), energy E_c = k a_c phi_c^2 / 2. Linearized about the
// point's position predicted for the step's end, q = x + u~_n + dt v~_n, with
// phi(y) ~ phi(q) + n . (y - q):
//   f_c(U) = -k a_c (phi(q) + n . (u~(U) - u~_q)) n = A u~(U) + b,  A = -k a_c n n^T,
// which eq. (20)'s update turns into K += W^T (k a_c n n^T) W and F += W^T b (u~ = W U, eq. 19).
// A contact whose linearized force would pull (the point leaves the obstacle within the step)
// is dropped and the step solved again; a point that ends a step inside an obstacle it was
// not in contact with joins, likewise (at most ContactOptions::maxPasses solves).
//
// Friction (optional): regularized Coulomb friction, a tangential force opposing the slip
// velocity relative to the obstacle with magnitude mu |f_c| above the slip speed v_s, and
// proportional to it below (viscous): damping c_t = mu |f_c| / max(|v_t|, v_s) on the tangential
// velocity, taken implicitly (D += W^T c_t (I - n n^T) W), so it only dissipates.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "physics/contact/obstacles.h"
#include "polydg/physics/contact/contact_measure.h"
#include "polydg/physics/contact/embedding.h"

namespace polydg {

struct ContactOptions {
  /// Penalty stiffness: pressure per unit penetration (force / length^3), > 0.
  double stiffness = 0.0;
  double friction = 0.0;   ///< Coulomb coefficient mu (0: frictionless)
  double slipSpeed = 0.0;  ///< v_s of the regularization, > 0 when friction is on
  int maxPasses = 3;       ///< solves per step for the active set
};

/// The contact terms of one step: the stiffness K_c, damping C_t and the force at U_n.
struct ContactLinearization {
  Eigen::SparseMatrix<double, Eigen::ColMajor, int> stiffness;  ///< W^T (k a n n^T) W
  Eigen::SparseMatrix<double, Eigen::ColMajor, int> damping;    ///< friction, or empty
  Eigen::VectorXd force;     ///< f(U_n) + C_t v_obstacle: contact forces at the step's start
  std::size_t contacts = 0;  ///< active points
  bool empty() const { return contacts == 0; }
};

/// The embedded points, their areas and the obstacles; linearizes the contact forces for a
/// step. Holds a reference to the embedding, which must outlive it (and may be updated in
/// place between steps: call refresh()).
class ContactModel {
 public:
  /// Throws std::invalid_argument for bad options or one area per point missing.
  ContactModel(const SurfaceEmbedding& points, std::vector<double> areas,
               std::vector<Obstacle> obstacles, const ContactOptions& options);

  /// After the embedding changed (a cut): rebuilds the sample matrix.
  void refresh();

  /// The active contacts for a step from state (u, v) to time tNext with step dt (predicted
  /// positions, see above), and their linearization. Times the queries (querySeconds()).
  ContactLinearization linearize(const Eigen::VectorXd& u, const Eigen::VectorXd& v, double tNext,
                                 double dt);
  /// After a solve giving uNew: drops active contacts whose linearized force pulls and adds
  /// points that penetrate uNew but were not active; true if the active set changed (then
  /// call relinearize()).
  bool adjust(const Eigen::VectorXd& uNew);
  /// The linearization of the current active set (after adjust()).
  ContactLinearization relinearize();

  /// Contacts, deepest penetration and penalty energy at displacement u, time t.
  ContactMeasure measure(const Eigen::VectorXd& u, double t);

  const ContactOptions& options() const { return options_; }
  std::size_t numPoints() const { return embedding_->numPoints(); }
  /// Wall seconds spent in obstacle queries (and point positions) since the last call.
  double takeQuerySeconds();
  /// The points the last linearize(), adjust() or measure() looked at: those the clearances
  /// did not rule out.
  std::size_t candidateCount() const { return candidates_.size(); }
  /// How often the clearances were measured (a product with W over every point each time).
  std::size_t clearanceMeasurements() const { return clearanceMeasurements_; }

 private:
  struct Active {
    std::uint32_t point = 0;
    std::uint32_t obstacle = 0;
    double distance = 0.0;  ///< phi at the linearization point q
    Vec3 normal = Vec3::Zero();
    Vec3 position = Vec3::Zero();  ///< q
    Vec3 slip = Vec3::Zero();      ///< tangential velocity relative to the obstacle at start
    Vec3 start = Vec3::Zero();     ///< u~_n, its displacement at the step's start
  };
  /// Deepest obstacle at each of the given positions (distance >= 0 where none).
  void queryAll(const std::vector<Vec3>& positions, double t, std::vector<ObstacleQuery>& out,
                std::vector<std::uint32_t>& which);
  ContactLinearization build() const;
  /// The points that may be inside an obstacle at coefficients u and time t, ascending: all
  /// but those whose clearance, less how far they and the obstacles can have moved since it
  /// was measured, stays positive. Measures the clearances again (a product with W over every
  /// point) when they rule out fewer than three quarters of the points.
  const std::vector<std::uint32_t>& candidates(const Eigen::VectorXd& u, double t);
  /// The translation t of the split of `change` (coefficients) into T(t) + D (t: the midpoint
  /// of the elements' mean displacements' range, per component), and |D|_inf.
  std::pair<Vec3, double> translationAndRest(const Eigen::VectorXd& change) const;
  /// The displacements of `points` at coefficients u into `out`: kept from the last call with
  /// the same u (a step's last solve, the measure of its end state and the next step's start
  /// all ask for the same points at the same U), computed on both cores for the others.
  void displacementsAt(const std::vector<std::uint32_t>& points, const Eigen::VectorXd& u,
                       std::vector<Vec3>& out);
  /// The same points displaced: their positions at u.
  std::vector<Vec3> positionsAt(const std::vector<std::uint32_t>& points, const Eigen::VectorXd& u);
  /// The points of the active contacts, in their order.
  std::vector<std::uint32_t> activePoints() const;
  void measureClearances(const Eigen::VectorXd& u, double t);

  const SurfaceEmbedding* embedding_;
  std::vector<double> areas_;
  std::vector<Obstacle> obstacles_;
  ContactOptions options_;
  std::vector<Active> active_;
  std::vector<char> isActive_;         ///< adjust()'s scratch: 1 for the points it keeps
  Eigen::VectorXd startCoefficients_;  ///< U_n of the last linearize()
  // Culling (W's product over every point was most of a step's collision handling): each
  // point's clearance, a lower bound of its signed distance to every obstacle (the exact
  // distance to a half-space, the distance to a surface obstacle's box, 0 inside that box) at
  // coefficients clearanceU_ and time clearanceT_. U' - U is split into a uniform translation
  // T(t) and the rest D (translationAndRest()); point p then moves at most
  // |translationGain_[p]| |t| + rowScale_[p] |D|_inf (W_p T(t) = translationGain_[p] t, about t
  // as W reproduces constants; rowScale_ is sqrt 3 times the weights' absolute sum) and the
  // obstacles at most maxObstacleSpeed_ |t' - t|, both distances 1-Lipschitz: a clearance
  // larger than that (plus pad_, against rounding) rules contact out. Without the translation
  // a falling body's every point was a candidate a step or two after each measurement.
  std::vector<double> rowScale_, translationGain_, clearance_;
  Eigen::VectorXd clearanceU_;
  double clearanceT_ = 0.0, maxObstacleSpeed_ = 0.0, pad_ = 0.0;
  std::vector<std::uint32_t> candidates_;
  std::size_t measuredCandidates_ = 0;  ///< candidates right after the clearances were measured
  std::size_t clearanceMeasurements_ = 0;
  // displacementsAt()'s memory: point p's displacement at knownU_ where known_[p] == knownStamp_.
  Eigen::VectorXd knownU_;
  std::vector<Vec3> knownDisplacement_;
  std::vector<std::uint32_t> known_;
  std::uint32_t knownStamp_ = 0;
  double tNext_ = 0.0, querySeconds_ = 0.0;
  std::size_t dofs_ = 0;
};

}  // namespace polydg
