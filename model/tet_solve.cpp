#include "model/tet_solve.h"

#include "physics/fem/tet_static.h"
#include "polydg/mesh/geometry.h"
#include "polydg/util/error.h"
#include "util/stopwatch.h"

namespace polydg {

const char* toString(TetMethod method) { return method == TetMethod::Fem ? "fem" : "fs-fem"; }

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

  // Boundary faces as a PolyMesh's, for the face selectors.
  const PolyMesh faces = toPolyMesh(mesh);
  const double diagonal = meshBounds(faces).diagonal().norm();
  TetStaticProblem problem;
  problem.material = options.material;
  problem.bodyForce = options.material.density * options.gravity;
  problem.prescribed = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(r.dofs));
  problem.nodalForces = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(r.dofs));
  if (options.bodyForce)
    problem.nodalForces += discretization.bodyForceFieldLoad(options.bodyForce);
  std::vector<char> held(r.nodes, 0);
  auto hold = [&](const FaceSelector& where, const VectorField& value) {
    for (std::size_t f = 0; f < faces.numFaces(); ++f) {
      const Face& face = faces.face(FaceId(f));
      if (face.back.valid() || !selects(where, faces, FaceId(f), diagonal)) continue;
      for (VertexId v : face.vertices) {
        held[v.index()] = 1;
        problem.prescribed.segment<3>(3 * v.index()) =
            value ? value(faces.position(v)) : Vec3::Zero();
      }
    }
  };
  for (const FaceSelector& clamp : options.clamps) hold(clamp, {});
  for (const DirichletCondition& d : options.displacements) hold(d.where, d.displacement);
  for (const TractionLoad& t : options.tractions)
    for (std::size_t f = 0; f < faces.numFaces(); ++f) {
      const Face& face = faces.face(FaceId(f));
      if (face.back.valid() || !selects(t.where, faces, FaceId(f), diagonal)) continue;
      const double area = areaVector(faces, FaceId(f)).norm();
      for (VertexId v : face.vertices)
        problem.nodalForces.segment<3>(3 * v.index()) += t.traction * (area / 3.0);
    }
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
