// Time per element of the exact moment computation (faces integrated once and shared, element
// moments accumulated from them) on hexahedral grids and on non-convex 20-30-face polyhedra.
//
// Sample runs:
//   build/tests/integrate_bench                       # all cases
//   build/tests/integrate_bench --benchmark_filter=Hex/4
// The counter `per_element` (seconds per element) is the figure quoted in the README (one thread).
#include <benchmark/benchmark.h>

#include <random>

#include <tbb/global_control.h>

#include "mesh/primitives.h"
#include "polydg/integrate/moment_cache.h"
#include "tests/support/shapes.h"

namespace polydg {
namespace {

void runCache(benchmark::State& state, const PolyMesh& mesh, int degree) {
  tbb::global_control oneThread(tbb::global_control::max_allowed_parallelism, 1);
  MomentCache cache(mesh, degree);
  for (auto _ : state) {
    cache.invalidateAll();
    benchmark::DoNotOptimize(cache.update());
    benchmark::ClobberMemory();
  }
  const double elements = static_cast<double>(mesh.numElements());
  state.counters["elements"] = elements;
  state.counters["monomials"] = numMonomials(degree);
  state.counters["per_element"] = benchmark::Counter(
      elements, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

/// Moments up to degree state.range(0) of every element of a 20^3 hexahedral grid.
void Hex(benchmark::State& state) {
  static const PolyMesh mesh = hexGridMesh(20, 20, 20, Box3(Vec3(0, 0, 0), Vec3(1, 1, 1)));
  runCache(state, mesh, static_cast<int>(state.range(0)));
}
BENCHMARK(Hex)->Arg(2)->Arg(4)->Arg(6)->Unit(benchmark::kMillisecond);

/// 2000 separate non-convex prisms over random star polygons with 18-28 sides (20-30 faces).
const PolyMesh& nonConvexSet() {
  static const PolyMesh mesh = [] {
    std::mt19937 rng(2026);
    PolyMesh all;
    for (int i = 0; i < 2000; ++i) {
      const PolyMesh one = testing::randomStarPrism(18 + i % 11, rng);
      const std::size_t first = all.numVertices();
      for (const Vec3& p : one.positions())
        all.addVertex(p + Vec3(3.0 * (i % 50), 3.0 * (i / 50), 0));
      std::vector<std::vector<Loop>> boundary;
      for (const FaceUse& use : one.element(ElementId(0)).faces) {
        const Face& face = one.face(use.face);
        std::vector<Loop> loops;
        for (std::size_t k = 0; k < face.numLoops(); ++k) {
          Loop loop;
          for (VertexId v : face.loop(k)) loop.push_back(VertexId(v.index() + first));
          loops.push_back(loop);
        }
        boundary.push_back(loops);
      }
      all.addElement(boundary, FaceOrigin::Box);
    }
    return all;
  }();
  return mesh;
}

void NonConvex(benchmark::State& state) {
  runCache(state, nonConvexSet(), static_cast<int>(state.range(0)));
}
BENCHMARK(NonConvex)->Arg(2)->Arg(4)->Arg(6)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace polydg

BENCHMARK_MAIN();
