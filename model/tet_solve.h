// A static solve on a tet mesh with the tet methods (linear FEM, FS-FEM; physics/fem/), taking
// the same options as the DG solve: material, clamps, prescribed displacements, tractions,
// gravity and body force. `polydg solve --method fem|fs-fem` runs it.
#pragma once

#include <Eigen/Dense>

#include "physics/fem/tet_discretization.h"
#include "polydg/model/model.h"
#include "polydg/physics/dg/dg_basis.h"

namespace polydg {

/// A tet mesh's boundary faces (as toPolyMesh's Surface faces) and what face selectors pick on
/// them: the nodes a region holds, the nodal forces of a traction.
class TetBoundary {
 public:
  explicit TetBoundary(const TetMesh& mesh);
  /// The boundary faces `where` selects.
  std::vector<FaceId> select(const FaceSelector& where) const;
  /// The corners of `faces`, each once, in increasing order.
  std::vector<std::uint32_t> nodes(const std::vector<FaceId>& faces) const;
  /// A traction's nodal forces (node-major): a third of each face's force on each corner.
  Eigen::VectorXd tractionLoad(const std::vector<FaceId>& faces, const Vec3& traction) const;
  const PolyMesh& mesh() const { return faces_; }

 private:
  PolyMesh faces_;
  double diagonal_ = 0.0;
};

struct TetSolveReport {
  TetMethod method = TetMethod::Fem;
  std::size_t nodes = 0, tets = 0, dofs = 0, heldNodes = 0, nonzeros = 0;
  Eigen::VectorXd displacement;  ///< node-major
  double maxDisplacement = 0.0;
  double energy = 0.0;  ///< strain energy u^T K u / 2
  LinearSolveReport solver;
  double assembleSeconds = 0.0, solveSeconds = 0.0;
};

/// Solves on `mesh`: a node is held by a clamp or a prescribed displacement when a selected
/// boundary face has it as a corner (a node two conditions hold takes the last one's value); a
/// traction adds a third of each selected face's force to each of its corners; gravity and the
/// body force are integrated over the tets. The DG discretization options (degree, penalty, the
/// estimate, adaptivity, an exact solution) do not apply and are refused if set away from their
/// defaults. Throws InvalidOption for bad options, InputError when nothing is held.
TetSolveReport solveOnTets(const TetMesh& mesh, TetMethod method, const SolveOptions& options);

/// The nodal displacement (node-major) of a tet solve as DG coefficients in `basis` (degree 1
/// or more, on toPolyMesh(mesh)'s elements or any PolyMesh whose element t is tet t): exact,
/// since the displacement is linear on each tet (linearFieldCoefficients).
Eigen::VectorXd tetCoefficients(const TetMesh& mesh, const Eigen::VectorXd& displacement,
                                const DgBasis& basis);

/// The figures of a tet solve in Model::solve()'s report: counts, solver, energy, times.
void fillSolveReport(const TetSolveReport& t, SolveReport& report);

}  // namespace polydg
