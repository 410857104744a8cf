// The uniform grid's slicing without its shortcut for whole cells: the reference tests hold the
// shortcut to.
#pragma once

#include "polydg/mesh/slice.h"

namespace polydg {

/// sliceSurface() splitting every cell by its planes, including the cells of a box that the
/// surface does not enter (which sliceSurface() makes from the grid instead). Its mesh is
/// sliceSurface()'s: the same elements in the same order, each with the same faces; only the
/// order of an element's faces and the first corner of a face's loop may differ.
PolyMesh sliceSurfaceSplittingEveryCell(const TriangleSurface& surface, const Grid& grid,
                                        SliceStats* stats = nullptr);

}  // namespace polydg
