// The methods on tet meshes beside DG (physics/fem/): linear FEM and the face-based smoothed
// FEM, each linear or corotational (Zhang et al. 2017).
#pragma once

namespace polydg {

/// The method on a tet mesh.
enum class TetMethod {
  Fem,    ///< linear FEM: one domain per tet, its constant strain
  FsFem,  ///< FS-FEM: one domain per face (the face and its tets' centroids), smoothed strain
};

}  // namespace polydg
