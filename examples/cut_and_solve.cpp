// Example: from a surface to a solved, cut simulation mesh with the polydg library.
//
// Sample runs:
//   cut_and_solve torus.obj torus_cut.vtu
//   cut_and_solve part.stl part_cut.vtu 24
//
// The problem. A closed surface (any file polydg reads) becomes a simulation mesh of polyhedral
// elements by slicing it with a grid of N cells along its longest side (16 unless given). The
// body is cut in two by the plane through the centre of its bounding box across its longest
// side, and the half on the plus side is removed. The rest is checked (the geometric validation
// and the DG patch test and rigid modes of every element), held at its lowest tenth and loaded by
// its own weight (E = 1e6, nu = 0.3, density 1, gravity -9.81 along z), solved with the interior
// penalty DG method of degree 2, and written as a VTU file with its displacement and stress.
// The program prints what each step did and exits with 1 if a check fails.
#include <polydg/polydg.h>

#include <cstdlib>
#include <iostream>

int main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: cut_and_solve SURFACE OUT.vtu [CELLS]\n";
    return 2;
  }
  try {
    // 1. The surface: triangles from the file, welded by position.
    polydg::SurfaceReadInfo read;
    const polydg::TriangleSurface surface = polydg::readSurface(argv[1], &read);
    for (const std::string& warning : read.warnings) std::cerr << "warning: " << warning << '\n';
    std::cout << "polydg " << polydg::libraryVersion() << ": " << surface.triangles.size()
              << " triangles\n";

    // 2. Slicing: the model owns the mesh with its moments, kept for the operations below
    //    (degree 4 covers a degree-2 solve: each face is integrated once).
    polydg::MeshOptions meshing;
    meshing.cells = argc > 3 ? std::atoi(argv[3]) : 16;
    meshing.momentDegree = 4;
    polydg::MeshReport meshed;
    polydg::Model model = polydg::Model::fromSurface(surface, meshing, meshed, argv[1]);
    if (!meshed.passed()) {
      std::cerr << "the new mesh failed its checks: " << meshed.failures().front() << '\n';
      return 1;
    }
    std::cout << "meshed: " << model.mesh().numElements() << " elements, volume " << model.volume()
              << " (surface " << meshed.meshing.inputVolume << ")\n";

    // 3. The cut: across the longest side, through the centre; the plus side is removed. The
    //    operation re-integrates only the faces it made and validates the region it touched.
    const polydg::Box3 box = polydg::meshBounds(model.mesh());
    int longest = 0;
    box.diagonal().maxCoeff(&longest);
    polydg::CutRequest cut;
    cut.blade = polydg::Blade::plane(polydg::Vec3::Unit(longest), box.center()[longest]);
    cut.removeSide = +1;
    const polydg::OperationReport op = model.cut(cut);
    if (!op.check.passed) {
      std::cerr << "the cut failed its validation: " << op.check.failure << '\n';
      return 1;
    }
    std::cout << "cut: " << op.elementsSplit << " elements split, " << op.elementsRemoved
              << " removed, " << op.facesReintegrated << " faces integrated\n";

    // 4. The checks of the whole mesh, with the moments the model keeps.
    polydg::MeshCheckOptions checks;
    checks.physics.discretization.basis.degree = 2;
    const polydg::MeshCheck check = model.check(checks);
    if (!check.passed()) {
      std::cerr << "check failed: " << check.failures().front() << '\n';
      return 1;
    }
    std::cout << "check: valid, local patch test error " << check.local->maxPatchTestError << '\n';

    // 5. The solve: clamped below the lowest tenth of the height, under gravity.
    const double z = box.min().z() + 0.1 * box.sizes().z();
    polydg::SolveOptions solve;
    solve.discretization.basis.degree = 2;
    solve.material = {.youngsModulus = 1e6, .poissonRatio = 0.3, .density = 1.0};
    solve.gravity = polydg::Vec3(0.0, 0.0, -9.81);
    solve.clamps = {polydg::FaceSelector::below(polydg::Plane::make(polydg::Vec3::UnitZ(), z))};
    const polydg::SolveReport solved = model.solve(solve);
    std::cout << "solve: " << solved.solve.dofs << " DOFs, " << solved.clampFaces.front()
              << " clamped faces, max |u| " << solved.maxDisplacement << ", max von Mises "
              << solved.maxVonMises << "\n";

    // 6. The file: the mesh with its provenance and the solution, written atomically. Every
    //    report has a JSON form (polydg/model/report_json.h), as the polydg commands write it.
    model.write(argv[2]);
    std::cout << "wrote " << argv[2] << "; faces integrated in all: " << model.facesIntegrated()
              << "\n"
              << polydg::toJson(solved)["solver"].dump() << '\n';
    return 0;
  } catch (const polydg::CheckFailure& e) {  // an operation ran, and its result failed a check
    std::cerr << "check failed: " << e.what() << '\n';
    return 1;
  } catch (const polydg::Error& e) {  // bad input: nothing was changed or written
    std::cerr << "error: " << e.what() << '\n';
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << '\n';
    return 2;
  }
}
