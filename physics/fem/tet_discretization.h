// Linear elasticity on 4-node tetrahedra, by linear FEM or by the face-based smoothed FEM
// (FS-FEM, Nguyen-Thoi et al. 2009, as Zhang et al. 2017 section 4.1 uses it), with the
// stiffness warped by rotations per element (C-FEM) or per smoothing domain (CS-FEM, Zhang et
// al. section 4.2): the integration domains, their strain-displacement data, and the matrices
// and loads assembled from them. Beside the DG code, sharing only Material and the solvers.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include <Eigen/Dense>
#include <Eigen/Sparse>

#include "polydg/mesh/tet_mesh.h"
#include "polydg/physics/dg/material.h"
#include "polydg/physics/fem/tet_method.h"

namespace polydg {

/// Where strain is constant and integrated: a tet (FEM), or the smoothing domain of a face
/// (FS-FEM), the union of the pyramids from the face to the centroids of its one or two tets.
struct StrainDomain {
  /// The nodes whose displacements the strain depends on: 4 (a tet, or a boundary face's
  /// domain) or 5 (an interior face's: the face's 3 and the two tets' opposite corners).
  std::array<std::uint32_t, 5> nodes{};
  int numNodes = 0;
  /// The tets it takes its volume from, and their shares of it (their volumes / 4 for FS-FEM,
  /// the whole volume for FEM).
  std::array<std::uint32_t, 2> tets{};
  std::array<double, 2> tetVolume{};
  int numTets = 0;
  double volume = 0.0;
  /// Row a: the (smoothed) gradient of node a's shape function, constant over the domain. For
  /// FS-FEM the volume-weighted mean of the tets' gradients (eq. 15 of Zhang et al.: the
  /// divergence theorem over the domain's boundary gives the same mean).
  Eigen::Matrix<double, 5, 3> gradients = Eigen::Matrix<double, 5, 3>::Zero();
};

/// The degrees of freedom are the nodes' displacements, node-major: dof 3 v + c.
class TetDiscretization {
 public:
  /// Throws std::invalid_argument for a tet with non-positive volume (readTetMesh checks files
  /// already).
  TetDiscretization(const TetMesh& mesh, TetMethod method);

  TetMethod method() const { return method_; }
  std::size_t numNodes() const { return numNodes_; }
  std::size_t numDofs() const { return 3 * numNodes_; }
  const std::vector<StrainDomain>& domains() const { return domains_; }
  const std::vector<double>& tetVolumes() const { return tetVolumes_; }

  /// The domain's stiffness, 3n x 3n for its n nodes (node-major): V (lambda g_a g_b^T +
  /// mu g_b g_a^T + mu g_a.g_b I) for the block of nodes a, b.
  Eigen::MatrixXd domainStiffness(const StrainDomain& d, const Material& material) const;
  /// K = sum over domains of their stiffness (symmetric, positive semi-definite, the six rigid
  /// motions in its kernel).
  Eigen::SparseMatrix<double> stiffness(const Material& material) const;
  /// The corotated stiffness sum R_d K_d R_d^T with one rotation per domain, and the force
  /// offset sum R_d K_d X_d (X: rest positions): the elastic force at positions x is
  /// offset - K_R x (Müller and Gross 2004; Zhang et al. eq. 23-25).
  void corotatedStiffness(const Material& material, const std::vector<Eigen::Matrix3d>& rotations,
                          Eigen::SparseMatrix<double>& k, Eigen::VectorXd& offset) const;
  /// Each tet's rotation: the polar rotation of its deformation gradient at positions x (rest
  /// positions + displacement), node-major.
  std::vector<Eigen::Matrix3d> tetRotations(const Eigen::VectorXd& x) const;
  /// Each domain's rotation from its tets': the tet's (FEM, a boundary face), or the two tets'
  /// rotations interpolated by spherical linear interpolation of their quaternions at the second
  /// tet's share of the volume (Zhang et al. section 4.2; the tets' rotations are taken in one
  /// global frame, so no projection is needed).
  std::vector<Eigen::Matrix3d> domainRotations(
      const std::vector<Eigen::Matrix3d>& tetRotations) const;

  /// Lumped mass per node: a quarter of each tet's mass.
  Eigen::VectorXd lumpedMass(double density) const;
  /// The nodal load of a constant body force (force per volume): a quarter of each tet's.
  Eigen::VectorXd bodyForceLoad(const Eigen::Vector3d& force) const;
  /// The consistent nodal load of a body force field f(x): int f N_a over each tet by a rule
  /// exact for quadratics (appendTetrahedronRule, integrate/quadrature.h).
  Eigen::VectorXd bodyForceFieldLoad(
      const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& force) const;
  /// Each tet's von Mises stress at positions x: of its own strain, sym(F) - I (linear), or
  /// sym(R^T F) - I with R the polar rotation of F (corotational). For FS-FEM this is the
  /// tet's strain, not its faces' smoothed ones: a picture of the stress, not the method's.
  std::vector<double> tetVonMises(const Eigen::VectorXd& x, const Material& material,
                                  bool corotational) const;
  /// The mesh's volume at positions x (node-major): the sum of its tets' signed volumes.
  double volume(const Eigen::VectorXd& x) const;
  /// The rest positions, node-major.
  const Eigen::VectorXd& restPositions() const { return rest_; }

 private:
  TetMethod method_;
  std::size_t numNodes_ = 0;
  std::vector<std::array<std::uint32_t, 4>> tets_;
  std::vector<double> tetVolumes_;
  std::vector<Eigen::Matrix<double, 4, 3>> tetGradients_;  ///< per tet, row a: node a's gradient
  std::vector<Eigen::Matrix3d> restEdgesInverse_;          ///< per tet, (X1-X0, X2-X0, X3-X0)^-1
  std::vector<StrainDomain> domains_;
  Eigen::VectorXd rest_;
};

}  // namespace polydg
