// The p-multigrid of a time step's matrix: its build (what the step after a cut or a refresh
// waits for) and one V-cycle (what each CG iteration costs), on B10's beam as the dynamics
// suite slices it (hexahedra of 10/cells, 10 x 1 x 1, clamped at x = 0), p = 1, IP.
//
// Sample runs:
//   build/tests/multigrid_bench                                  # 90 and 130 cells
//   build/tests/multigrid_bench --benchmark_filter=Build/130 --benchmark_repetitions=5
// The step's matrix is M + dt^2 K for dt = 0.01, E = 1000, nu = 0.3, density 1: with the
// orthonormal basis M is the identity, so it is 1e-4 K plus the identity.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <map>
#include <utility>

#include "mesh/primitives.h"
#include "physics/dg/block_rows.h"
#include "physics/solvers/p_multigrid.h"
#include "tests/support/dg_systems.h"

namespace polydg {
namespace {

struct StepMatrix {
  BlockRows<double> rows;
  ElementFrames frames;
};

/// The beam at `cells` cells along it: its step matrix by block rows, and its frames.
const StepMatrix& stepMatrix(int cells) {
  static std::map<int, StepMatrix> made;
  auto it = made.find(cells);
  if (it != made.end()) return it->second;
  const int across = std::max(1, cells / 10);
  const PolyMesh mesh = hexGridMesh(cells, across, across, Box3(Vec3::Zero(), Vec3(10, 1, 1)));
  const FramedSystem s =
      framedSystem(mesh, Material{1000, 0.3, 1}, bench::benchmarkB2Loads(), Method::IP, 1);
  StepMatrix m;
  m.rows.build(s.system.matrix, 4, 2.0);
  BlockRows<double>& rows = m.rows;
  for (auto& v : rows.values) v *= 1e-4;
  for (int e = 0; e < rows.elements(); ++e)
    for (int k = rows.start[static_cast<std::size_t>(e)];
         k < rows.start[static_cast<std::size_t>(e) + 1]; ++k)
      if (rows.element[static_cast<std::size_t>(k)] == e)
        for (int c = 0; c < rows.bs; ++c)
          rows.values[rows.offset[static_cast<std::size_t>(k)] +
                      static_cast<std::size_t>(c * rows.bs + c)] += 1.0;
  m.frames = s.frames;
  return made.emplace(cells, std::move(m)).first->second;
}

/// PMultigrid::computeCopy() of the step matrix, as a time step builds it.
void Build(benchmark::State& state) {
  const StepMatrix& m = stepMatrix(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    PMultigrid mg(MatrixTerms::StiffnessAndMass);
    if (!mg.computeCopy(m.rows, 1, &m.frames)) state.SkipWithError("not positive definite");
    benchmark::DoNotOptimize(mg.levels());
  }
  state.counters["unknowns"] = static_cast<double>(m.rows.elements()) * m.rows.bs;
}

/// One V-cycle (PMultigrid::apply()).
void VCycle(benchmark::State& state) {
  const StepMatrix& m = stepMatrix(static_cast<int>(state.range(0)));
  PMultigrid mg(MatrixTerms::StiffnessAndMass);
  if (!mg.computeCopy(m.rows, 1, &m.frames)) state.SkipWithError("not positive definite");
  const Eigen::VectorXd r = Eigen::VectorXd::LinSpaced(m.rows.elements() * m.rows.bs, -1.0, 1.0);
  Eigen::VectorXd z;
  for (auto _ : state) {
    mg.apply(r, z);
    benchmark::DoNotOptimize(z.data());
  }
  state.counters["unknowns"] = static_cast<double>(r.size());
}

BENCHMARK(Build)->Arg(90)->Arg(130)->Unit(benchmark::kMillisecond);
BENCHMARK(VCycle)->Arg(90)->Arg(130)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace polydg

BENCHMARK_MAIN();
