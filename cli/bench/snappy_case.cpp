#include "cli/bench/snappy_case.h"

#include <algorithm>
#include <cmath>
#include <system_error>
#include <tuple>
#include <utility>

#include "cli/bench/stl_file.h"
#include "model/files.h"
#include "polydg/mesh/slice.h"
#include "polydg/util/error.h"
#include "util/format.h"

namespace polydg::bench {

namespace fs = std::filesystem;

namespace {

/// About this many block cells along the longest side are tried for locationInMesh at first
/// (every cell of a block that small): a cheap search that finds the deep cells of a thick
/// model; every cell is tried when it finds none.
constexpr int kLocationSamples = 16;

std::string foamVector(const Vec3& v) {
  return "(" + formatNumber(v.x(), 17) + " " + formatNumber(v.y(), 17) + " " +
         formatNumber(v.z(), 17) + ")";
}

std::string header(const std::string& object) {
  return "FoamFile\n{\n    version 2.0;\n    format ascii;\n    class dictionary;\n    object " +
         object + ";\n}\n\n";
}

void write(const fs::path& file, const std::string& text) {
  writeFileAtomically(file, [&](std::ostream& os) { os << text; });
}

/// The centre of block cell (i, j, k).
Vec3 cellCentre(const SnappySetup& s, int i, int j, int k) {
  return s.blockMin + s.cellSize * Vec3(i + 0.5, j + 0.5, k + 0.5);
}

/// The deepest inside of the block cell centres every `stride` cells; depth -1 if none is
/// inside.
std::pair<Vec3, double> deepestCentre(const SnappySetup& s, const SurfaceDistance& distance,
                                      int stride) {
  std::pair<Vec3, double> best{Vec3::Zero(), -1.0};
  for (int i = stride / 2; i < s.blockCells[0]; i += stride)
    for (int j = stride / 2; j < s.blockCells[1]; j += stride)
      for (int k = stride / 2; k < s.blockCells[2]; k += stride) {
        const Vec3 p = cellCentre(s, i, j, k);
        const double d = distance.distance(p);
        if (d > best.second && distance.inside(p)) best = {p, d};
      }
  return best;
}

std::string blockMeshDict(const SnappySetup& s) {
  const Vec3 &a = s.blockMin, &b = s.blockMax;
  std::string vertices;
  for (const Vec3& v :
       {a, Vec3(b.x(), a.y(), a.z()), Vec3(b.x(), b.y(), a.z()), Vec3(a.x(), b.y(), a.z()),
        Vec3(a.x(), a.y(), b.z()), Vec3(b.x(), a.y(), b.z()), b, Vec3(a.x(), b.y(), b.z())})
    vertices += "    " + foamVector(v) + "\n";
  return header("blockMeshDict") + "scale 1;\n\nvertices\n(\n" + vertices +
         ");\n\nblocks\n(\n    hex (0 1 2 3 4 5 6 7) (" + std::to_string(s.blockCells[0]) + " " +
         std::to_string(s.blockCells[1]) + " " + std::to_string(s.blockCells[2]) +
         ") simpleGrading (1 1 1)\n);\n\nedges ();\n\n"
         "boundary\n(\n    background\n    {\n        type patch;\n        faces\n        (\n"
         "            (3 7 6 2)\n            (0 4 7 3)\n            (2 6 5 1)\n"
         "            (1 5 4 0)\n            (0 3 2 1)\n            (4 5 6 7)\n        );\n"
         "    }\n);\n";
}

/// snappyHexMeshDict after OpenFOAM's motorBike and flange tutorials: castellated and snapped at
/// the surface level, features snapped explicitly, no layers, the default mesh quality controls
/// (etc/caseDicts/meshQualityDict) written out so that the case needs no file of OpenFOAM's.
std::string snappyHexMeshDict(const SnappySetup& s) {
  const std::string level = std::to_string(s.surfaceLevel);
  return header("snappyHexMeshDict") +
         "castellatedMesh true;\nsnap true;\naddLayers false;\n\n"
         "geometry\n{\n    " +
         s.surface + ".stl\n    {\n        type triSurfaceMesh;\n        name " + s.surface +
         ";\n    }\n}\n\n"
         "castellatedMeshControls\n{\n"
         "    maxLocalCells 100000000;\n    maxGlobalCells 100000000;\n"
         "    minRefinementCells 0;\n    maxLoadUnbalance 0.10;\n    nCellsBetweenLevels 1;\n"
         "    features\n    (\n        { file \"" +
         s.surface + ".extendedFeatureEdgeMesh\"; level " + level +
         "; }\n    );\n"
         "    refinementSurfaces\n    {\n        " +
         s.surface + "\n        {\n            level (" + level + " " + level +
         ");\n            patchInfo { type wall; }\n        }\n    }\n"
         "    resolveFeatureAngle 30;\n    refinementRegions {}\n"
         "    locationInMesh " +
         foamVector(s.locationInMesh) +
         ";\n    allowFreeStandingZoneFaces true;\n}\n\n"
         "snapControls\n{\n    nSmoothPatch 3;\n    tolerance 2.0;\n    nSolveIter 30;\n"
         "    nRelaxIter 5;\n    nFeatureSnapIter 10;\n    implicitFeatureSnap false;\n"
         "    explicitFeatureSnap true;\n    multiRegionFeatureSnap false;\n}\n\n"
         "addLayersControls\n{\n    relativeSizes true;\n    layers {}\n    expansionRatio 1.0;\n"
         "    finalLayerThickness 0.3;\n    minThickness 0.1;\n    nGrow 0;\n"
         "    featureAngle 60;\n    nRelaxIter 3;\n    nSmoothSurfaceNormals 1;\n"
         "    nSmoothNormals 3;\n    nSmoothThickness 10;\n    maxFaceThicknessRatio 0.5;\n"
         "    maxThicknessToMedialRatio 0.3;\n    minMedialAxisAngle 90;\n"
         "    nBufferCellsNoExtrude 0;\n    nLayerIter 50;\n}\n\n"
         "meshQualityControls\n{\n    maxNonOrtho 65;\n    maxBoundarySkewness 20;\n"
         "    maxInternalSkewness 4;\n    maxConcave 80;\n    minVol 1e-13;\n"
         "    minTetQuality 1e-15;\n    minArea -1;\n    minTwist 0.02;\n"
         "    minDeterminant 0.001;\n    minFaceWeight 0.05;\n    minVolRatio 0.01;\n"
         "    minTriangleTwist -1;\n    nSmoothScale 4;\n    errorReduction 0.75;\n}\n\n"
         "mergeTolerance 1e-6;\n";
}

}  // namespace

SnappySetup snappySetup(const TriangleSurface& surface, const SurfaceDistance& distance, int cells,
                        const std::string& name) {
  const Grid grid = Grid::withCellsAlongLongest(bounds(surface), cells);
  SnappySetup s;
  s.surface = name;
  s.cellSize = grid.cellSize;
  for (int a = 0; a < 3; ++a) {
    s.blockMin[a] = grid.plane(a, 0) - grid.cellSize;
    s.blockMax[a] = grid.plane(a, grid.cells[a]) + grid.cellSize;
    s.blockCells[a] = grid.cells[a] + 2;
  }
  const double wholeCell = 0.5 * std::sqrt(3.0) * grid.cellSize;
  const int stride = std::max(1, (cells + 2) / kLocationSamples);
  for (int step : {stride, 1}) {
    std::tie(s.locationInMesh, s.depth) = deepestCentre(s, distance, step);
    if (s.depth > wholeCell || step == 1) break;
  }
  if (!(s.depth > wholeCell))
    throw InputError("no background cell lies wholly inside " + name + " at " +
                     std::to_string(cells) + " cells: snappyHexMesh's locationInMesh needs one");
  return s;
}

void writeSnappyCase(const fs::path& dir, const TriangleSurface& surface, const SnappySetup& s) {
  std::error_code ec;
  fs::create_directories(dir / "system", ec);
  fs::create_directories(dir / "constant" / "triSurface", ec);
  if (ec) throw InputError("cannot create " + dir.string() + ": " + ec.message());
  const fs::path system = dir / "system";
  write(system / "controlDict",
        header("controlDict") +
            "application snappyHexMesh;\nstartFrom startTime;\nstartTime 0;\nstopAt endTime;\n"
            "endTime 1;\ndeltaT 1;\nwriteControl timeStep;\nwriteInterval 1;\n"
            "writeFormat ascii;\nwritePrecision 17;\nwriteCompression off;\n"
            "timeFormat general;\ntimePrecision 6;\nrunTimeModifiable false;\n");
  write(system / "fvSchemes",
        header("fvSchemes") + "gradSchemes {}\ndivSchemes {}\nlaplacianSchemes {}\n");
  write(system / "fvSolution", header("fvSolution"));
  write(system / "blockMeshDict", blockMeshDict(s));
  write(system / "surfaceFeatureExtractDict",
        header("surfaceFeatureExtractDict") + s.surface +
            ".stl\n{\n    extractionMethod extractFromSurface;\n    includedAngle " +
            formatNumber(s.includedAngle, 17) + ";\n    writeObj no;\n}\n");
  write(system / "snappyHexMeshDict", snappyHexMeshDict(s));
  writeAsciiStl(dir / "constant" / "triSurface" / (s.surface + ".stl"), surface, s.surface);
}

}  // namespace polydg::bench
