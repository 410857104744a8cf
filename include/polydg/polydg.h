// polydg: surface meshes in, polyhedral discontinuous Galerkin simulation meshes out, cut,
// checked and solved. One header for library users: the model and its operations, and the
// layers below it (mesh, exact integration, DG physics, cutting).
//
//   #include <polydg/polydg.h>
//   polydg::MeshReport report;
//   polydg::Model model = polydg::Model::fromSurface(polydg::readSurface("part.obj"),
//                                                    {.cells = 16}, report);
//
// CMake: find_package(polydg REQUIRED); target_link_libraries(app PRIVATE polydg::polydg).
// examples/ holds commented programs.
#pragma once

#include "polydg/version.h"

#include "polydg/mesh/geometry.h"
#include "polydg/mesh/geometry_checks.h"
#include "polydg/mesh/meshing.h"
#include "polydg/mesh/plane.h"
#include "polydg/mesh/poly_mesh.h"
#include "polydg/mesh/surface.h"
#include "polydg/mesh/surface_io.h"
#include "polydg/mesh/surface_shapes.h"
#include "polydg/mesh/vtu_io.h"

#include "polydg/integrate/moment_cache.h"
#include "polydg/integrate/moments.h"

#include "polydg/physics/checks/dg_checks.h"
#include "polydg/physics/checks/mesh_checks.h"
#include "polydg/physics/dg/loads.h"
#include "polydg/physics/dg/material.h"
#include "polydg/physics/dg/post_process.h"
#include "polydg/physics/solvers/static_solver.h"

#include "polydg/cut/cut.h"

#include "polydg/model/files.h"
#include "polydg/model/info.h"
#include "polydg/model/model.h"
#include "polydg/model/names.h"
#include "polydg/model/pipeline.h"
#include "polydg/model/provenance.h"
#include "polydg/model/report_json.h"

#include "polydg/util/error.h"
