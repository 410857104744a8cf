// The suites of `polydg bench` (shared/BENCHMARKS.md), each a function from the options to the
// files it writes (cli/bench/suite_output.h):
//   accuracy   B1 with IP and BZ, degrees 1-3, hex grids (p = 1: n = 4, 8, 16, 24; p = 2: 2, 4,
//              8, 12; p = 3: 2, 3, 4, 6, 8) and sliced cubes (p = 1: 4, 8, 12; p = 2: 2, 4, 8;
//              p = 3: 2, 4, 6). Plot: L2 error against integration + assembly + solve time
//              (everything from the mesh to the solution).
//   table41    B2 (10^3 hexahedra) with BZ and IP, degrees 1 and 2, beside the thesis's Table 4.1.
//              Each case runs five times; the fastest run (by total time) is reported.
//   stability  B4: sliver (volume ratio 1 .. 1e-12 by factors of 10, and 0.05 and 0.02 near
//              the merge threshold; merged or not, p = 1, 2), thin neck (eps
//              1e-1 .. 1e-9), near-incompressible cantilever (nu 0.3 .. 0.4999, p = 1, 2),
//              scale and position (B1 and B3 scaled by 1e-6, 1, 1e6, offsets 0 and
//              (1e6, -1e6, 1e6), p = 2).
//   meshing    the meshing pipeline and its validation (geometric, DG checks) for the bundled
//              torus.obj and the generated sphere and torus knot at 16 .. 128 cells; the whole
//              `polydg mesh` command on the bunny (DATA/models/bunny.off) beside Debian's
//              `tetgen -pQ` (64 cells) and beside Gmsh's HXT (`gmsh -3 -nt 2`, 64, 128 and 200
//              cells, Gmsh's largest mesh size polydg's cell edge): wall time, peak memory,
//              cells per second and bytes per cell, and plots of both against the cells. Each
//              comparison is skipped, with one line, without the bunny or its program.
//   cutting    plane cuts of growing size on a 47^3 hex grid (103,823 elements): time per cut
//              against elements split, validation none and local, beside a full moment rebuild.
//   dynamics   B6 (linear, p = 2, 10 periods of dt = T/200: energy against time and the first
//              period, per integrator), B7 (b) (the spinning cube, one turn: volume change and
//              angular momentum, linear against corotational, per integrator), and wall time per
//              step against DOFs (B10's beam under gravity, p = 1, corotational, 7.7k, 87k and
//              960k DOFs, with rotation, assembly and solve apart). The longest suite, most of
//              it the 960k-DOF steps, which also need the most memory.
//   contact    B9 and collision handling: the MLS embedding of a 74,884-triangle sphere in a
//              mesh of 4 cells per side (p = 1, 2: setup, W's nonzeros, time per surface update),
//              100k obstacle queries against the ground and B9's bowl as distance fields (voxel
//              diagonal / 100, simulate's default, and / 200), a step of the drop with that
//              surface's vertices as contact points against its collision time and the surface
//              update (the goal: each below 10%), and B9's drops onto the ground and into the
//              bowl (contacts, penetration, energies per step).
//   adaptivity B11 (the bent bar of thesis Fig. 4.9 refined by principal stress, 1-to-8 and 1-to-2
//              at tau = 0.25, 0.5, 0.75, beside the thesis's 274 and 77) and B12 (the steep
//              bump: uniform 8, 16, 32 against solve --adapt from 4; DOFs to each uniform L2
//              error, effectivity of the estimate on every mesh).
//   multigrid  CG iterations of the p-multigrid on real models: the Stanford bunny (fetched by
//              scripts/get-models.sh into DATA/models/bunny.off; skipped with a note if absent)
//              and the bundled torus, sliced at 16 cells, then also cut by a plane and a finite
//              polygon, IP at p = 1, 2, clamped at the bottom under gravity (B2's material),
//              beside B2 on the unit cube of about as many elements: DOFs, iterations and their
//              ratio to the cube's, setup and solve time.
//   sfem       the tet methods beside DG (Zhang et al. 2017 section 5): the cubic cantilever under
//              pressure on 625 tets distorted by alpha = 0 .. 0.4 (L-FEM, LFS-FEM, IP p = 1, 2
//              on the tets; IP p = 3 on 12^3 hexahedra the reference), and the falling beam's
//              volume (1,440 tets; L-FEM, LFS-FEM, C-FEM, CS-FEM), and speed against error
//              on B1 (FEM, FS-FEM on tets, IP p = 1-3 on hexahedra).
//   openfoam   polydg beside OpenFOAM's snappyHexMesh (issue 34) on the bundled torus (12 and 24
//              cells) and the bunny (32 and 64; skipped with a note if absent): the whole
//              commands timed alternately (polydg mesh + export against blockMesh +
//              surfaceFeatureExtract + snappyHexMesh on the same background cells), checkMesh's
//              verdict and figures on both cases, their cells, volume error and the largest
//              distance of their boundary from the surface. Skipped, with one line, without
//              OpenFOAM's tools.
// With `quick` each runs reduced sizes (a smoke test of every output, as the tests run it).
#pragma once

#include <string>

#include "cli/bench/suite_output.h"

namespace polydg::bench {

struct BenchOptions {
  std::string suite;        ///< accuracy, ..., multigrid, sfem, openfoam or all
  std::string out;          ///< the folder the files go to
  bool skipSliced = false;  ///< accuracy: hex grids only
  bool quick = false;
  /// The folder of the bundled models the meshing and openfoam suites read (torus.obj, and
  /// models/bunny.off of scripts/get-models.sh); `polydg bench` uses
  /// dataDirectory() (cli/bench/data_files.h) unless --data names another.
  std::string dataDir;
};

SuiteOutput accuracySuite(const BenchOptions& options, bool quiet);
SuiteOutput table41Suite(bool quiet);
SuiteOutput stabilitySuite(const BenchOptions& options, bool quiet);
/// Throws InputError if DATA_DIR/torus.obj does not exist.
SuiteOutput meshingSuite(const BenchOptions& options, bool quiet);
SuiteOutput cuttingSuite(const BenchOptions& options, bool quiet);
SuiteOutput dynamicsSuite(const BenchOptions& options, bool quiet);
SuiteOutput contactSuite(const BenchOptions& options, bool quiet);
SuiteOutput adaptivitySuite(const BenchOptions& options, bool quiet);
SuiteOutput multigridSuite(const BenchOptions& options, bool quiet);
SuiteOutput sfemSuite(const BenchOptions& options, bool quiet);
/// Throws InputError if DATA_DIR/torus.obj does not exist.
SuiteOutput openfoamSuite(const BenchOptions& options, bool quiet);

}  // namespace polydg::bench
