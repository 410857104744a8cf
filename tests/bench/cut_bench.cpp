// Time per plane cut against the number of elements it touches, on a 47^3 grid of hexahedra
// (103,823 elements), and incremental re-integration against a full MomentCache rebuild.
//
// Sample runs:
//   build/tests/cut_bench            # the table in the note (validation none, then local)
//
// Each row cuts a corner off the same editor (normal (+-1, +-1, +-1), growing corners), so
// the mesh stays ~100k elements and the cuts do not overlap; the last row cuts through the
// middle. "full rebuild" is a fresh MomentCache of the whole mesh (degree 2, both cores).
#include <chrono>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include "cut/cut.h"
#include "mesh/primitives.h"

namespace polydg {
namespace {

double secondsOf(const std::function<void()>& f) {
  const auto t0 = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void run(ValidationLevel level, const char* name) {
  constexpr int n = 47;
  MeshEditor editor(hexGridMesh(n, n, n, Box3(Vec3(0, 0, 0), Vec3(1, 1, 1))));
  CutOptions options;
  options.validation = level;
  std::printf("\nvalidation %s, %zu elements, %zu faces\n", name, editor.mesh().numElements(),
              editor.mesh().numFaces());
  std::printf("%-28s %9s %9s %10s %10s %9s %12s\n", "plane", "split", "elements", "faces int.",
              "faces", "cut [ms]", "rebuild [ms]");
  struct Row {
    Vec3 normal;
    double offset;
  };
  // Corner k: normal s = (+-1, +-1, +-1); the corner point c has c_i = 0 where s_i > 0.
  // The plane s.x = s.c + depth cuts off a corner tetrahedron of that depth.
  std::vector<Row> rows;
  const double depths[] = {0.01, 0.04, 0.1, 0.2, 0.35, 0.5, 0.7, 0.9};
  for (int k = 0; k < 8; ++k) {
    const Vec3 s(k & 1 ? -1 : 1, k & 2 ? -1 : 1, k & 4 ? -1 : 1);
    const Vec3 corner((k & 1) ? 1 : 0, (k & 2) ? 1 : 0, (k & 4) ? 1 : 0);
    rows.push_back({s, s.dot(corner) + depths[k]});
  }
  rows.push_back({Vec3(1, 0.3, 0.1), Vec3(1, 0.3, 0.1).dot(Vec3(0.5, 0.5, 0.5))});
  for (const Row& row : rows) {
    OperationReport r;
    const double cut = secondsOf([&] { r = editor.cut(Blade::plane(row.normal, row.offset), options); });
    const double rebuild = secondsOf([&] {
      MomentCache fresh(editor.mesh(), editor.moments().degree());
      fresh.update();
    });
    char plane[64];
    std::snprintf(plane, sizeof plane, "(%g,%g,%g).x=%g", row.normal.x(), row.normal.y(),
                  row.normal.z(), row.offset);
    std::printf("%-28s %9zu %9zu %10zu %10zu %9.2f %12.1f%s\n", plane, r.elementsSplit,
                editor.mesh().numElements(), r.facesReintegrated, r.facesTotal, 1e3 * cut,
                1e3 * rebuild, r.validation.passed ? "" : "  VALIDATION FAILED");
    if (!r.validation.passed) std::printf("  %s\n", r.validation.failure.c_str());
  }
}

}  // namespace
}  // namespace polydg

int main(int argc, char** argv) {
  const std::string only = argc > 1 ? argv[1] : "";
  if (only.empty() || only == "none") polydg::run(polydg::ValidationLevel::None, "none");
  if (only.empty() || only == "local") polydg::run(polydg::ValidationLevel::Local, "local");
  return 0;
}
