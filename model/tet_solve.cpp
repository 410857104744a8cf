#include "model/tet_solve.h"

#include <algorithm>

#include "physics/checks/linear_field.h"
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
  SolveOptions checked = options;
  checked.tetMethod = method;
  checked.check();
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
  r.nonzeros = s.nonzeros;
  for (std::size_t v = 0; v < r.nodes; ++v)
    r.maxDisplacement = std::max(r.maxDisplacement, s.displacement.segment<3>(3 * v).norm());
  r.displacement = std::move(s.displacement);
  return r;
}

Eigen::VectorXd tetCoefficients(const TetMesh& mesh, const Eigen::VectorXd& displacement,
                                const DgBasis& basis) {
  const auto bs = static_cast<Eigen::Index>(3 * basis.size());
  Eigen::VectorXd out(bs * static_cast<Eigen::Index>(mesh.numTets()));
  for (std::size_t t = 0; t < mesh.numTets(); ++t) {
    const auto& c = mesh.tets[t];
    // u(x) = u_0 + A (x - x_0) with A (x_k - x_0) = u_k - u_0 for the three other corners.
    Eigen::Matrix3d edges, du;
    for (int k = 0; k < 3; ++k) {
      edges.col(k) = mesh.vertices[c[k + 1]] - mesh.vertices[c[0]];
      du.col(k) = displacement.segment<3>(3 * c[k + 1]) - displacement.segment<3>(3 * c[0]);
    }
    LinearField field;
    field.a = du * edges.inverse();
    field.b = displacement.segment<3>(3 * c[0]);
    field.x0 = mesh.vertices[c[0]];
    linearFieldCoefficients(basis, ElementId(t), field,
                            std::span<double>(out.data() + static_cast<Eigen::Index>(t) * bs,
                                              static_cast<std::size_t>(bs)));
  }
  return out;
}

void fillSolveReport(const TetSolveReport& t, SolveReport& report) {
  StaticReport& s = report.solve;
  s.elements = t.tets;
  s.dofs = t.dofs;
  s.nonzeros = t.nonzeros;
  s.solver = t.solver;
  s.energy = t.energy;
  s.assembleSeconds = t.assembleSeconds;
  s.solveSeconds = t.solveSeconds;
  for (std::size_t n : report.clampFaces) s.dirichletFaces += n;
  for (std::size_t n : report.tractionFaces) s.tractionFaces += n;
  report.tets = SolveReport::TetCounts{t.nodes, t.tets, t.heldNodes};
}

}  // namespace polydg
