// Loading polydg's OpenVDB module (distance_grids.h) the first time a field is built.
#include "physics/contact/distance_grids.h"

#include "util/modules.h"

namespace polydg {

std::shared_ptr<const DistanceGrids> buildDistanceGrids(const IndexSpaceSurface& surface) {
  // Loaded once; a failure is not remembered, so a later call tries again.
  static const auto build = reinterpret_cast<BuildDistanceGrids>(loadModuleEntry(
      POLYDG_OPENVDB_MODULE, POLYDG_BIN_TO_LIB, kBuildDistanceGrids,
      "the distance field of a surface obstacle", "reinstall polydg, or use half-space obstacles"));
  return std::shared_ptr<const DistanceGrids>(build(surface));
}

}  // namespace polydg
