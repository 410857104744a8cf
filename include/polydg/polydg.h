// polydg: surface meshes in, polyhedral discontinuous Galerkin simulation meshes out, cut,
// checked, solved and simulated. One header for library users: the model, its operations,
// their requests and reports, and the mesh and surface types they take and return. The
// headers below are the whole installed API; solver internals are not installed.
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

#include "polydg/util/error.h"
#include "polydg/util/process.h"

#include "polydg/mesh/geometry.h"
#include "polydg/mesh/surface_io.h"
#include "polydg/mesh/surface_shapes.h"
#include "polydg/mesh/tet_mesh.h"
#include "polydg/mesh/tetrahedralize.h"
#include "polydg/mesh/vtu_io.h"

#include "polydg/model/info.h"
#include "polydg/model/model.h"
#include "polydg/model/names.h"
#include "polydg/model/pipeline.h"
#include "polydg/model/provenance.h"
#include "polydg/model/report_json.h"
#include "polydg/model/scene.h"
