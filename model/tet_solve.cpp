#include "model/tet_solve.h"

#include <algorithm>

#include "physics/fem/tet_static.h"
#include "polydg/mesh/geometry.h"
#include "polydg/model/names.h"
#include "polydg/util/error.h"
#include "util/stopwatch.h"

namespace polydg {

TetBoundary::TetBoundary(const TetMesh& mesh)
    : faces_(toPolyMesh(mesh)), diagonal_(meshBounds(faces_).diagonal().norm()) {}

std::vector<FaceId> TetBoundary::select(const FaceSelector& where) const {
  std::vector<FaceId> out;
  for (std::size_t f = 0; f < faces_.numFaces(); ++f)
    if (!faces_.face(FaceId(f)).back.valid() && selects(where, faces_, FaceId(f), diagonal_))
      out.push_back(FaceId(f));
  return out;
}

std::vector<std::uint32_t> TetBoundary::nodes(const std::vector<FaceId>& faces) const {
  std::vector<std::uint32_t> out;
  for (FaceId f : faces)
    for (VertexId v : faces_.face(f).vertices) out.push_back(static_cast<std::uint32_t>(v.index()));
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

Eigen::VectorXd TetBoundary::tractionLoad(const std::vector<FaceId>& faces,
                                          const Vec3& traction) const {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(3 * faces_.numVertices()));
  for (FaceId face : faces) {
    const double area = areaVector(faces_, face).norm();
    for (VertexId v : faces_.face(face).vertices)
      f.segment<3>(3 * static_cast<Eigen::Index>(v.index())) += traction * (area / 3.0);
  }
  return f;
}

TetSolveReport solveOnTets(const TetMesh& mesh, TetMethod method, const SolveOptions& options) {
  options.check();
  if (options.adapt || options.estimate || options.exactDisplacement)
    throw InvalidOption("method", std::string("adaptivity, the error estimate and an exact "
                                              "solution are for the DG methods, not ") +
                                      toString(method));
  const Stopwatch assemble;
  TetSolveReport r;
  r.method = method;
  r.nodes = mesh.numVertices();
  r.tets = mesh.numTets();
  r.dofs = 3 * r.nodes;
  const TetDiscretization discretization(mesh, method);

  const TetBoundary boundary(mesh);
  TetStaticProblem problem;
  problem.material = options.material;
  problem.bodyForce = options.material.density * options.gravity;
  problem.prescribed = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(r.dofs));
  problem.nodalForces = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(r.dofs));
  if (options.bodyForce)
    problem.nodalForces += discretization.bodyForceFieldLoad(options.bodyForce);
  std::vector<char> held(r.nodes, 0);
  auto hold = [&](const FaceSelector& where, const VectorField& value) {
    for (std::uint32_t v : boundary.nodes(boundary.select(where))) {
      held[v] = 1;
      problem.prescribed.segment<3>(3 * v) = value ? value(mesh.vertices[v]) : Vec3::Zero();
    }
  };
  for (const FaceSelector& clamp : options.clamps) hold(clamp, {});
  for (const DirichletCondition& d : options.displacements) hold(d.where, d.displacement);
  for (const TractionLoad& t : options.tractions)
    problem.nodalForces += boundary.tractionLoad(boundary.select(t.where), t.traction);
  for (std::size_t v = 0; v < r.nodes; ++v)
    if (held[v]) problem.clamped.push_back(static_cast<std::uint32_t>(v));
  r.heldNodes = problem.clamped.size();
  if (problem.clamped.empty())
    throw InputError(
        "no boundary face of the tet mesh lies where the clamps and displacements "
        "select: nothing holds the body; check the regions");
  r.assembleSeconds = assemble.seconds();

  const Stopwatch solve;
  SolverOptions solver;
  solver.kind = options.solver;
  TetStaticSolution s = solveTetStatic(discretization, problem, solver);
  r.solveSeconds = solve.seconds();
  r.solver = s.solve;
  r.energy = s.strainEnergy;
  for (std::size_t v = 0; v < r.nodes; ++v)
    r.maxDisplacement = std::max(r.maxDisplacement, s.displacement.segment<3>(3 * v).norm());
  r.displacement = std::move(s.displacement);
  return r;
}

}  // namespace polydg
