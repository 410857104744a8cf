// The model: provenance that travels with the mesh, a moment cache that every operation shares
// (each face integrated once), region selections, and operations that refuse to leave nothing.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>

#include "mesh/primitives.h"
#include "polydg/integrate/moment_cache.h"
#include "polydg/mesh/geometry_checks.h"
#include "polydg/mesh/surface_shapes.h"
#include "polydg/model/model.h"
#include "polydg/model/report_json.h"
#include "polydg/util/error.h"

namespace polydg {
namespace {

namespace fs = std::filesystem;

/// A scratch folder per test, removed at the end.
class ModelTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("polydg_model_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

/// The unit box [0,1]^3 meshed with 4 cells along each side (plus the slicer's boundary layer).
Model unitBox(MeshReport& report, int momentDegree = 0) {
  MeshOptions options;
  options.cells = 4;
  options.momentDegree = momentDegree;
  return Model::fromSurface(boxSurface(Box3(Vec3::Zero(), Vec3::Ones())), options, report,
                            "box.obj");
}

TEST_F(ModelTest, ProvenanceTravelsWithTheMeshThroughAFile) {
  MeshReport report;
  MeshOptions options;
  options.cells = 5;
  options.sliverFraction = 0.03;
  const TriangleSurface torusSurface = torus(Vec3::Zero(), 1.0, 0.4, 48, 24);
  Model meshed = Model::fromSurface(torusSurface, options, report, "torus.obj");
  ASSERT_TRUE(report.passed());
  const Provenance& p = meshed.provenance();
  EXPECT_EQ(p.referenceKind, ReferenceKind::GridCell);
  EXPECT_EQ(p.cellSize, report.meshing.grid.cellSize);
  EXPECT_EQ(p.referenceVolume, p.cellSize * p.cellSize * p.cellSize);
  EXPECT_EQ(p.sliverFraction, 0.03);
  EXPECT_EQ(p.source, "torus.obj");

  const std::string file = (dir_ / "torus.vtu").string();
  meshed.write(file);
  ReadReport read;
  const Model back = Model::read(file, &read);
  EXPECT_TRUE(read.provenanceRestored);
  EXPECT_EQ(back.provenance().referenceKind, ReferenceKind::GridCell);
  EXPECT_EQ(back.provenance().cellSize, p.cellSize);  // bit for bit
  EXPECT_EQ(back.provenance().referenceVolume, p.referenceVolume);
  EXPECT_EQ(back.provenance().sliverFraction, 0.03);
  EXPECT_EQ(back.provenance().source, "torus.obj");
  EXPECT_EQ(back.mesh().numElements(), meshed.mesh().numElements());
}

// An output into a folder that does not exist is refused before the surface is sliced; one that
// fails when written is reported under its own name, not the temporary file's.
TEST_F(ModelTest, AnOutputThatCannotBeWrittenIsNamedAndAMissingFolderCostsNoMeshing) {
  MeshOptions options;
  options.cells = 6;
  int progressCalls = 0;
  options.progress = [&](double) { ++progressCalls; };
  const TriangleSurface surface = torus(Vec3::Zero(), 1.0, 0.4, 48, 24);
  MeshReport report;
  options.output = (dir_ / "missing" / "torus.vtu").string();
  try {
    (void)Model::fromSurface(surface, options, report);
    ADD_FAILURE() << "meshing into a missing folder did not fail";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("does not exist"), std::string::npos) << e.what();
  }
  EXPECT_EQ(progressCalls, 0);
  // /proc takes no new files: refused before the work, or by the writer (as root, who may write
  // to any folder), under the name asked for either way.
  options.output = "/proc/torus.vtu";
  try {
    (void)Model::fromSurface(surface, options, report);
    ADD_FAILURE() << "meshing into /proc did not fail";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("cannot write /proc/torus.vtu:"), std::string::npos) << message;
    EXPECT_EQ(message.find("pending"), std::string::npos) << message;
  }
}

TEST_F(ModelTest, MeshingTakesTheWholeCellsClosureFromHowTheyWereBuilt) {
  // Whole grid cells are validated as a class: their closure is not tested one by one, and the
  // report counts them; the rest of the validation, and its verdict, are as before.
  MeshReport report;
  MeshOptions options;
  options.cells = 16;
  options.dgChecks = false;
  const TriangleSurface torusSurface = torus(Vec3::Zero(), 1.0, 0.4, 48, 24);
  const Model meshed = Model::fromSurface(torusSurface, options, report, "torus.obj");
  ASSERT_TRUE(report.passed());
  const GeometryCheck& g = report.meshing.geometry;
  EXPECT_GT(g.closedByConstruction, 100u);
  EXPECT_LE(g.closedByConstruction, report.meshing.hexahedra);
  const GeometryCheck all = checkGeometry(meshed.mesh());
  EXPECT_EQ(all.closedByConstruction, 0u);
  EXPECT_EQ(all.passed, g.passed);
  EXPECT_EQ(all.openElements, 0u);
  EXPECT_EQ(all.volume, g.volume);
}

TEST_F(ModelTest, AMeshWithoutProvenanceUsesItsMedianElementVolume) {
  PolyMesh grid = hexGridMesh(3, 2, 1, Box3(Vec3::Zero(), Vec3(3.0, 2.0, 0.5)));
  const Model model(std::move(grid));
  EXPECT_EQ(model.provenance().referenceKind, ReferenceKind::MedianElement);
  EXPECT_DOUBLE_EQ(model.provenance().referenceVolume, 0.5);  // every cell 1 x 1 x 0.5
  EXPECT_EQ(model.provenance().sliverFraction, kDefaultSliverFraction);
}

TEST_F(ModelTest, CutsLeaveTheMomentsAFreshIntegrationComputes) {
  // Only what a cut touched is integrated again: every face and element moment must still
  // equal a fresh integration of the edited mesh (a face the cut changed and the cache kept
  // would not). Cuts with validation off, so that nothing else re-integrates.
  MeshReport report;
  Model model = unitBox(report, 2);
  ASSERT_TRUE(report.passed());
  // Plane cuts, then a removal and a polygon cut: these leave dead faces whose ids the next
  // cut's new faces take, over cache entries that are stale until integrated again.
  struct Step {
    Blade blade;
    int removeSide;
  };
  const std::vector<Step> steps = {
      {Blade::plane(Vec3(1.0, 0.3, 0.2), 0.55), 0},
      {Blade::plane(Vec3(0.0, 1.0, 0.0), 0.37), 0},
      {Blade::plane(Vec3(-0.4, 0.2, 1.0), 0.3), 0},
      {Blade::plane(Vec3(0.3, 1.0, 0.1), 0.8), +1},
      {Blade::fromPolygon({Vec3(-0.1, -0.1, 0.45), Vec3(0.8, -0.1, 0.45), Vec3(0.8, 0.9, 0.45),
                           Vec3(-0.1, 0.9, 0.45)}),
       0},
      {Blade::plane(Vec3(1.0, 0.0, 0.1), 0.7), 0}};
  for (const Step& step : steps) {
    CutRequest cut;
    cut.blade = step.blade;
    cut.removeSide = step.removeSide;
    cut.checks = CheckLevel::None;
    const std::size_t before = model.mesh().numElements();
    const OperationReport r = model.cut(cut);
    ASSERT_GT(r.elementsSplit, 0u);
    if (step.removeSide == 0) {
      ASSERT_GT(model.mesh().numElements(), before);
    }
  }
  const MomentCache& cached = model.moments(2);
  MomentCache fresh(model.mesh(), 2);
  fresh.update();
  auto same = [](std::span<const double> a, std::span<const double> b) {
    double worst = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i)
      worst = std::max(worst, std::abs(a[i] - b[i]) / std::max(1e-3, std::abs(a[i])));
    return worst;
  };
  double worst = 0.0;
  for (std::size_t f = 0; f < model.mesh().numFaces(); ++f)
    worst = std::max(worst, same(fresh.face(FaceId(f)), cached.face(FaceId(f))));
  for (std::size_t e = 0; e < model.mesh().numElements(); ++e)
    worst = std::max(worst, same(fresh.element(ElementId(e)), cached.element(ElementId(e))));
  EXPECT_LT(worst, 1e-12);
}

TEST_F(ModelTest, EveryFaceIsIntegratedOnceAcrossCutCheckAndSolve) {
  MeshReport report;
  Model model = unitBox(report, 4);  // degree 4: enough for checks and solves of degree 2
  ASSERT_TRUE(report.passed());
  const std::size_t meshed = model.facesIntegrated();
  EXPECT_EQ(meshed, model.mesh().numFaces());  // the DG checks read the model's moments

  CutRequest cut;
  cut.blade = Blade::plane(Vec3(1.0, 0.3, 0.2), 0.55);
  const OperationReport op = model.cut(cut);
  ASSERT_TRUE(op.check.passed) << op.check.failure;
  EXPECT_GT(op.facesReintegrated, 0u);
  EXPECT_EQ(model.facesIntegrated(), meshed + op.facesReintegrated);

  MeshCheckOptions check;
  check.physics.discretization.basis.degree = 2;
  const MeshCheck c = model.check(check);
  ASSERT_TRUE(c.passed());
  EXPECT_EQ(c.facesIntegrated, 0u);

  SolveOptions solve;
  solve.discretization.basis.degree = 2;
  solve.clamps.push_back(FaceSelector::below(Plane::make(Vec3::UnitZ(), 0.0)));
  solve.gravity = Vec3(0.0, 0.0, -1.0);
  const SolveReport s = model.solve(solve);
  EXPECT_EQ(s.facesIntegrated, 0u);
  EXPECT_EQ(s.solve.facesIntegrated, 0u);
  EXPECT_EQ(model.facesIntegrated(), meshed + op.facesReintegrated);

  // A degree the cache does not hold integrates every face once more, and only once.
  check.physics.discretization.basis.degree = 3;
  const std::size_t faces = model.mesh().numFaces();
  model.check(check);
  model.check(check);
  EXPECT_EQ(model.facesIntegrated(), meshed + op.facesReintegrated + faces);
}

TEST_F(ModelTest, SelectionsPickTheFacesInTheirRegion) {
  MeshReport report;
  Model model = unitBox(report);
  ASSERT_TRUE(report.passed());
  SolveOptions solve;
  solve.discretization.basis.degree = 1;
  solve.gravity = Vec3(0.0, 0.0, -1.0);
  // The bottom z = 0: as a plane, as a half-space and as a thin box, the same 16 faces (the
  // unit box sliced by a 4 x 4 x 4 grid of cell 0.25 plus a layer of boundary cells).
  const std::vector<FaceSelector> bottoms{
      FaceSelector::inPlane(2, 0.0), FaceSelector::inPlane(Plane::make(Vec3(0, 0, 2), 0.0)),
      FaceSelector::below(Plane::make(Vec3::UnitZ(), 0.0)),
      FaceSelector::inBox(Box3(Vec3(-1, -1, -1), Vec3(2, 2, 0)))};
  std::vector<std::size_t> counts;
  for (const FaceSelector& bottom : bottoms) {
    solve.clamps = {bottom};
    counts.push_back(model.solve(solve).clampFaces.front());
  }
  EXPECT_GT(counts.front(), 0u);
  for (std::size_t c : counts) EXPECT_EQ(c, counts.front());
  // Below z = 0.5 also takes the lower half of the sides.
  solve.clamps = {FaceSelector::below(Plane::make(Vec3::UnitZ(), 0.5))};
  EXPECT_GT(model.solve(solve).clampFaces.front(), counts.front());
}

TEST_F(ModelTest, ASelectionOfNoFaceIsAnErrorNamingIt) {
  MeshReport report;
  Model model = unitBox(report);
  SolveOptions solve;
  solve.clamps = {FaceSelector::below(Plane::make(Vec3::UnitZ(), -0.5))};
  try {
    model.solve(solve);
    FAIL() << "a clamp below the body was accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("below 0,0,1,-0.5"), std::string::npos) << what;
    EXPECT_NE(what.find("selects no boundary face"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos);
  }
  solve.clamps = {FaceSelector::inPlane(0, 0.0)};
  solve.tractions = {{FaceSelector::inBox(Box3(Vec3(5, 5, 5), Vec3(6, 6, 6))), Vec3(1, 0, 0)}};
  EXPECT_THROW(model.solve(solve), InputError);
}

TEST_F(ModelTest, ACutThatRemovesEverythingFails) {
  MeshReport report;
  Model model = unitBox(report);
  CutRequest cut;
  cut.blade = Blade::plane(Vec3::UnitZ(), 2.0);  // everything is below z = 2
  cut.removeSide = -1;
  const OperationReport r = model.cut(cut);
  EXPECT_FALSE(r.check.passed);
  EXPECT_NE(r.check.failure.find("left no element"), std::string::npos) << r.check.failure;
  EXPECT_EQ(model.mesh().numElements(), 0u);
  // The model refuses further use rather than writing an empty mesh.
  EXPECT_THROW(model.write((dir_ / "empty.vtu").string()), CheckFailure);
  EXPECT_FALSE(fs::exists(dir_ / "empty.vtu"));
}

TEST_F(ModelTest, CutsUseTheMeshesSliverRule) {
  MeshReport report;
  MeshOptions options;
  options.cells = 4;
  options.sliverFraction = 0.05;
  Model model = Model::fromSurface(boxSurface(Box3(Vec3::Zero(), Vec3::Ones())), options, report);
  CutRequest cut;
  cut.blade = Blade::plane(Vec3::UnitX(), 0.3);
  const OperationReport r = model.cut(cut);
  const double cell = report.meshing.grid.cellSize;
  EXPECT_DOUBLE_EQ(r.sliverThreshold, 0.05 * cell * cell * cell);
  cut.blade = Blade::plane(Vec3::UnitY(), 0.3);
  cut.sliverFraction = 0.0;
  EXPECT_EQ(model.cut(cut).sliverThreshold, 0.0);
}

TEST_F(ModelTest, SolveReportsAndWritesTheSolution) {
  // A column under its own weight, against its closed form: the unit box, E = 1, nu = 0, density
  // 1, clamped at z = 0, gravity (0, 0, -1). With nu = 0 the stress is uniaxial, sigma_zz =
  // -(1 - z), and u = (0, 0, -(z - z^2 / 2)) is quadratic: degree 2 reproduces it to round-off.
  // An element's mean stress is the (linear) stress at its centroid, so its von Mises stress is
  // 1 - z_c; the top corners move by 1/2, no jump opens, the energy is int (1 - z)^2 / 2 = 1/6.
  MeshReport report;
  Model model = unitBox(report);
  SolveOptions solve;
  solve.material.poissonRatio = 0.0;
  solve.discretization.basis.degree = 2;
  solve.clamps = {FaceSelector::inPlane(2, 0.0)};
  solve.gravity = Vec3(0.0, 0.0, -1.0);
  const SolveReport r = model.solve(solve);
  ASSERT_NE(model.solution(), nullptr);
  // Round-off: measured 4.7e-15 at most (von Mises; |u| 3.8e-15, the jump 6.9e-16).
  constexpr double kRoundoff = 1e-13;
  EXPECT_NEAR(r.maxDisplacement, 0.5, kRoundoff);
  EXPECT_NEAR(r.solve.energy, 1.0 / 6.0, kRoundoff);
  EXPECT_LT(r.maxJump, kRoundoff);
  const ElementData<double>& vonMises = model.solution()->fields.vonMises;
  double lowest = 1.0, worst = 0.0;
  for (std::size_t e = 0; e < model.mesh().numElements(); ++e) {
    const double z = model.moments(1).centroid(ElementId(e)).z();
    lowest = std::min(lowest, z);
    worst = std::max(worst, std::abs(vonMises[ElementId(e)] - (1.0 - z)));
  }
  std::printf("column: |u| %.17g, energy %.17g, jump %.2e, von Mises off by %.2e, largest %.17g\n",
              r.maxDisplacement, r.solve.energy, r.maxJump, worst, r.maxVonMises);
  EXPECT_LT(worst, kRoundoff);
  EXPECT_NEAR(r.maxVonMises, 1.0 - lowest, kRoundoff);
  const nlohmann::json j = toJson(r);
  EXPECT_EQ(j["clamps"][0]["faces"], r.clampFaces[0]);
  EXPECT_EQ(j["method"], "ip");
  const WriteReport w = model.write((dir_ / "solved.vtu").string());
  EXPECT_TRUE(w.withSolution);
  // An edit drops the solution: it no longer belongs to the mesh.
  CutRequest cut;
  cut.blade = Blade::plane(Vec3::UnitX(), 0.55);
  model.cut(cut);
  EXPECT_EQ(model.solution(), nullptr);
}

/// The surface of `box` with each side an m x m grid of squares, two triangles each (outward).
TriangleSurface finelyTriangulatedBox(const Box3& box, int m) {
  TriangleSurface s;
  std::map<std::array<int, 3>, std::uint32_t> index;  // lattice point -> vertex
  auto vertex = [&](const std::array<int, 3>& q) {
    const auto [it, added] = index.try_emplace(q, static_cast<std::uint32_t>(s.vertices.size()));
    if (added) {
      Vec3 x;
      for (int l = 0; l < 3; ++l) x[l] = box.min()[l] + box.sizes()[l] * q[l] / m;
      s.vertices.push_back(x);
    }
    return it->second;
  };
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      // (u, v, axis) right-handed: u x v is +axis; swapped on the low side, so normals point out.
      int u = (axis + 1) % 3, v = (axis + 2) % 3;
      if (side == 0) std::swap(u, v);
      auto at = [&](int i, int j) {
        std::array<int, 3> q{};
        q[axis] = side * m;
        q[u] = i;
        q[v] = j;
        return vertex(q);
      };
      for (int i = 0; i < m; ++i)
        for (int j = 0; j < m; ++j) {
          s.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
          s.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
        }
    }
  return s;
}

TEST_F(ModelTest, SplittingTheClampedFacesIntoManyTrianglesLeavesTheSolutionAlone) {
  // The same body, its sides as 2 or as 2 x 12^2 triangles: under the clamp each element then
  // has up to 60 Dirichlet faces instead of 1 or 2. The penalty bound spreads the penalty by
  // the element's mean coupled face area (penaltyThreshold()), so the penalty per unit area of
  // every face is the same in both meshes; with each face's own area (eq. 7) the bound grew
  // with the face count and stiffened the clamp (the energies differed by 3.5% at p = 1).
  // With nu = 0 the lambda term drops out (its lifting weight c_K counts faces): the form, and
  // the solution, are then the same to round-off.
  const Box3 box(Vec3(0.05, 0.1, 0.15), Vec3(0.95, 0.8, 0.85));
  MeshOptions mo;
  mo.cells = 3;
  mo.dgChecks = false;
  SolveOptions so;
  so.material.poissonRatio = 0.0;
  so.clamps = {FaceSelector::inPlane(2, 0.15)};
  so.gravity = Vec3(0.0, 0.0, -1.0);
  for (int degree = 1; degree <= 2; ++degree) {
    so.discretization.basis.degree = degree;
    std::array<SolveReport, 2> r;
    for (int k = 0; k < 2; ++k) {
      MeshReport report;
      Model model = Model::fromSurface(finelyTriangulatedBox(box, k == 0 ? 1 : 12), mo, report);
      ASSERT_TRUE(report.passed());
      r[k] = model.solve(so);
    }
    EXPECT_GE(r[1].clampFaces[0], 20 * r[0].clampFaces[0]) << "degree " << degree;
    EXPECT_NEAR(r[1].solve.energy, r[0].solve.energy, 1e-10 * std::abs(r[0].solve.energy))
        << "degree " << degree;
    EXPECT_NEAR(r[1].maxDisplacement, r[0].maxDisplacement, 1e-10 * r[0].maxDisplacement)
        << "degree " << degree;
  }
}

}  // namespace
}  // namespace polydg
