// Refinement of the model and adaptive static solves (paper section 10, "Dynamic Adaptivity";
// thesis 4.7): Model::refine() splits elements with their new faces coupled and carries the
// last solution to the children exactly; an adaptive solve repeats solve, measure, mark,
// refine until its goal is met.
#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <unordered_set>

#include "field_transfer.h"
#include "model_state.h"
#include "physics/solvers/error_estimator.h"
#include "physics/solvers/static_solver.h"
#include "polydg/mesh/geometry.h"
#include "polydg/model/model.h"
#include "polydg/util/error.h"
#include "util/stopwatch.h"

namespace polydg {

namespace {

/// The planes that split element e: its bounding box's mid-planes (Octants), or the plane
/// through its centroid across `direction` (Halves).
std::vector<Plane> splitPlanes(const PolyMesh& mesh, const MomentCache& moments, ElementId e,
                               RefineSplit split, const Vec3& direction) {
  if (split == RefineSplit::Octants) {
    const Vec3 c = elementBounds(mesh, e).center();
    return {Plane::make(Vec3::UnitX(), c.x()), Plane::make(Vec3::UnitY(), c.y()),
            Plane::make(Vec3::UnitZ(), c.z())};
  }
  return {Plane::make(direction, direction.dot(moments.centroid(e)))};
}

/// Error: the fewest elements holding `bulk` of the squared estimate (none, with the reason
/// in r.stop, once the target is met).
std::vector<ElementId> markByError(const SolveReport& report, const AdaptOptions& a,
                                   AdaptRound& r) {
  const ErrorEstimate& estimate = *report.estimate;
  r.estimate = estimate.total;
  r.energyNorm = report.energyNorm;
  if (a.targetError && estimate.total <= *a.targetError * report.energyNorm) {
    r.stop = "the estimate is below the target error";
    return {};
  }
  std::vector<ElementId> marked = markBulk(estimate.indicators, a.bulk);
  if (marked.empty()) r.stop = "the estimate is zero";
  return marked;
}

}  // namespace

RefineReport Model::refine(const RefineRequest& request) {
  State& s = *state_;
  s.requireUsable();
  const double fraction = request.sliverFraction.value_or(s.provenance.sliverFraction);
  checkEditOptions(fraction, request.checkDegree);
  const std::size_t ne = mesh().numElements();
  std::unordered_set<std::uint32_t> listed;
  for (ElementId e : request.elements) {
    if (!e.valid() || e.index() >= ne)
      throw InputError("element " + std::to_string(e.value) + " is not in the mesh (it has " +
                       std::to_string(ne) + " elements)");
    if (!listed.insert(e.value).second)
      throw InputError("element " + std::to_string(e.value) +
                       " is listed twice; list each element to refine once");
  }
  const Solution* u = solution();
  if (!request.planes.empty() && request.planes.size() != request.elements.size())
    throw InputError("give the planes of every element to refine, or none");
  for (const std::vector<Plane>& planes : request.planes)
    if (planes.empty() || planes.size() > 3)
      throw InputError("an element is split by 1 to 3 planes");
  if (request.split == RefineSplit::Halves && request.planes.empty()) {
    if (request.directions.empty() && !u)
      throw InputError(
          "splitting in halves needs a direction per element or a solution to take the "
          "principal stress directions from; solve first");
    if (!request.directions.empty() && request.directions.size() != request.elements.size())
      throw InputError("give one direction per element to split in halves (" +
                       std::to_string(request.elements.size()) + " elements, " +
                       std::to_string(request.directions.size()) + " directions)");
    for (const Vec3& d : request.directions)
      if (!d.allFinite() || d.norm() == 0.0)
        throw InputError("a splitting direction must be three finite numbers, not all zero");
  }
  const MomentCache& moments = this->moments(2);
  std::vector<ElementRefinement> split;
  split.reserve(request.elements.size());
  for (std::size_t i = 0; i < request.elements.size(); ++i) {
    const ElementId e = request.elements[i];
    const Vec3 direction = request.split == RefineSplit::Octants || !request.planes.empty()
                               ? Vec3::UnitX()
                           : request.directions.empty() ? u->fields.principalDirection[e]
                                                        : request.directions[i];
    split.push_back({e, request.planes.empty()
                            ? splitPlanes(mesh(), moments, e, request.split, direction)
                            : request.planes[i]});
  }
  // The solution before the edit (the edit drops it) and its basis, a copy independent of the
  // mesh.
  std::optional<Solution> before;
  if (u) before = std::move(s.solution);

  RefineOptions options;
  options.sliverFraction = fraction;
  options.checks = request.checks;
  options.checkDegree = request.checkDegree;
  RefineReport report;
  report.operation = s.edit().refine(split, options);
  s.finishEdit(report.operation, request.checks);
  if (before && report.operation.check.passed) {
    const int p = before->basis->degree();
    const MomentCache& after = this->moments(2 * p);
    auto basis = std::make_unique<DgBasis>(mesh(), after, BasisOptions{p, before->basis->kind()});
    TransferCounts counts;
    std::vector<Eigen::VectorXd> moved = transferFields(*before->basis, {&before->coefficients},
                                                        *basis, report.operation.lineage, &counts);
    report.solutionExact = counts.exact;
    report.solutionExtended = counts.extended;
    s.adoptSolution(std::move(basis), std::move(moved[0]), before->material, after);
  }
  return report;
}

CoarsenReport Model::coarsen(const CoarsenRequest& request) {
  State& s = *state_;
  s.requireUsable();
  checkEditOptions(0.0, request.checkDegree);
  const std::size_t ne = mesh().numElements();
  std::unordered_set<std::uint32_t> listed;
  for (const std::vector<ElementId>& group : request.groups) {
    if (group.size() < 2) throw InputError("a group to coarsen needs two elements or more");
    for (ElementId e : group) {
      if (!e.valid() || e.index() >= ne)
        throw InputError("element " + std::to_string(e.value) + " is not in the mesh (it has " +
                         std::to_string(ne) + " elements)");
      if (!listed.insert(e.value).second)
        throw InputError("element " + std::to_string(e.value) +
                         " is listed twice; each element joins one group");
    }
  }
  std::optional<Solution> before;
  if (s.solution) before = std::move(s.solution);
  CoarsenReport report;
  report.operation = s.edit().coarsen(request.groups, request.checks, request.checkDegree);
  s.finishEdit(report.operation, request.checks);
  if (before && report.operation.check.passed && before->basis->kind() == BasisKind::Orthonormal) {
    const int p = before->basis->degree();
    const MomentCache& after = this->moments(2 * p);
    auto basis = std::make_unique<DgBasis>(mesh(), after, BasisOptions{p, BasisKind::Orthonormal});
    std::vector<Eigen::VectorXd> moved =
        projectFields(*before->basis, {&before->coefficients}, *basis, report.operation.lineage);
    for (std::size_t e = 0; e < mesh().numElements(); ++e)
      report.solutionProjected += report.operation.lineage.sources(ElementId(e)).size() > 1;
    s.adoptSolution(std::move(basis), std::move(moved[0]), before->material, after);
  }
  return report;
}

SolveReport solveAdaptively(Model& model, const SolveOptions& options) {
  const AdaptOptions& a = *options.adapt;
  if (a.maxRounds < 0 || a.maxRounds > 20)
    throw InputError("the number of refinement rounds must be between 0 and 20");
  if (!(a.bulk > 0.0 && a.bulk <= 1.0)) throw InputError("the bulk fraction must be in (0, 1]");
  if (!(a.stressFraction > 0.0 && a.stressFraction <= 1.0))
    throw InputError("the stress fraction must be in (0, 1]");
  if (a.targetError && !(*a.targetError > 0.0 && std::isfinite(*a.targetError)))
    throw InputError("the target error must be a positive number");
  if (a.maxDofs && *a.maxDofs == 0) throw InputError("the DOF budget must be positive");
  if (a.maxLevel < 1 || a.maxLevel > 8)
    throw InputError("the largest refinement level must be between 1 and 8");
  SolveOptions once = options;
  once.adapt.reset();
  once.estimate = a.criterion == AdaptCriterion::Error;
  std::vector<AdaptRound> rounds;
  double stressThreshold = 0.0;
  // How often each element's ancestors in the first mesh were split (Stress).
  std::vector<int> level(model.mesh().numElements(), 0);
  for (int round = 0;; ++round) {
    AdaptRound r;
    const Stopwatch solveWatch;
    SolveReport report = model.solve(once);
    r.solveSeconds = solveWatch.seconds();
    r.elements = model.mesh().numElements();
    r.dofs = report.solve.dofs;
    if (report.error) r.l2Error = report.error->l2;
    if (report.energyError) r.energyError = report.energyError->total();
    const Solution& u = *model.solution();
    for (double sigma : u.fields.principalStress)
      r.largestStress = std::max(r.largestStress, std::abs(sigma));
    if (round == 0) stressThreshold = a.stressFraction * r.largestStress;

    const Stopwatch estimateWatch;
    std::vector<ElementId> marked;
    if (a.criterion == AdaptCriterion::Stress) {
      for (std::size_t e = 0; e < r.elements; ++e)
        if (level[e] < a.maxLevel &&
            std::abs(u.fields.principalStress[ElementId(e)]) > stressThreshold)
          marked.push_back(ElementId(e));
      if (marked.empty())
        r.stop = "no element below the largest level (" + std::to_string(a.maxLevel) +
                 ") has a principal stress above the threshold";
    } else {
      marked = markByError(report, a, r);
    }
    r.estimateSeconds = estimateWatch.seconds();
    const std::size_t children = a.split == RefineSplit::Octants ? 8 : 2;
    const std::size_t dofsPerElement = r.elements ? r.dofs / r.elements : 0;
    if (r.stop.empty() && round == a.maxRounds)
      r.stop = "the largest number of rounds (" + std::to_string(a.maxRounds) + ") is reached";
    if (r.stop.empty() && a.maxDofs &&
        r.dofs + marked.size() * (children - 1) * dofsPerElement > *a.maxDofs)
      r.stop =
          "the next refinement would exceed the DOF budget (" + std::to_string(*a.maxDofs) + ")";
    if (!r.stop.empty()) {
      r.elementsAfter = r.elements;
      rounds.push_back(r);
      report.rounds = std::move(rounds);
      report.options = options;
      return report;
    }
    r.marked = marked.size();
    const Stopwatch refineWatch;
    RefineRequest request;
    request.elements = std::move(marked);
    request.split = a.split;
    // The next round's solve validates the whole mesh's geometry (the edit leaves its validity
    // unknown) and its factorization fails on a singular stiffness: the region DG checks would
    // factorize the refined region once more (issue 17 measures them at 100x a cut).
    request.checks = CheckLevel::None;
    const RefineReport refined = model.refine(request);
    if (!refined.operation.check.passed)
      throw CheckFailure("refinement round " + std::to_string(round + 1) + " failed its checks (" +
                         refined.operation.check.failure + ")");
    r.refineSeconds = refineWatch.seconds();
    r.elementsAfter = model.mesh().numElements();
    std::unordered_set<std::uint32_t> split;
    for (ElementId e : request.elements) split.insert(e.value);
    level = levelsAfter(level, refined.operation.lineage, r.elementsAfter, split);
    rounds.push_back(r);
  }
}

}  // namespace polydg
