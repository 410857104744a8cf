// A scene on a tet mesh by a tet method (scene "method": "fem" or "fs-fem"): the body moved by
// TetDynamics (physics/fem/) with the scene's material, integrator, solver, gravity, damping,
// fixed regions, loads in time and initial motion, frames with point displacement and velocity,
// and the report the DG simulation gives. Model::simulate() runs it. Private to model/.
#pragma once

#include "polydg/mesh/tet_mesh.h"
#include "polydg/model/scene.h"

namespace polydg {

/// Runs `scene` (its tetMethod set) on `mesh`. A fixed region holds every corner of the
/// boundary faces it selects; a load puts a third of each selected face's force on each
/// corner. Throws InputError for a bad scene or a region that selects no boundary face,
/// CheckFailure if a step's solve fails. `finalDisplacement`, if given, takes the nodes'
/// displacement at the end (node-major).
SimulationReport simulateOnTets(const TetMesh& mesh, const Scene& scene,
                                const SimulateOptions& options,
                                Eigen::VectorXd* finalDisplacement = nullptr);

}  // namespace polydg
