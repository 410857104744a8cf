#include "mesh/vtk_cell_types.h"

namespace polydg::vtk_format {

const LinearCellType* linearCellType(std::int64_t type) {
  static const std::vector<LinearCellType> kTypes = [] {
    const std::vector<std::vector<int>> hex = {{0, 4, 7, 3}, {1, 2, 6, 5}, {0, 1, 5, 4},
                                               {3, 7, 6, 2}, {0, 3, 2, 1}, {4, 5, 6, 7}};
    // A voxel numbers its points x fastest, then y, then z; as a hexahedron: 0 1 3 2 4 5 7 6.
    const int voxelToHex[8] = {0, 1, 3, 2, 4, 5, 7, 6};
    std::vector<std::vector<int>> voxel = hex;
    for (auto& face : voxel)
      for (int& p : face) p = voxelToHex[p];
    return std::vector<LinearCellType>{
        {10, 4, {{0, 1, 3}, {1, 2, 3}, {2, 0, 3}, {0, 2, 1}}},
        {11, 8, voxel},
        {12, 8, hex},
        {13, 6, {{0, 1, 2}, {3, 5, 4}, {0, 3, 4, 1}, {1, 4, 5, 2}, {2, 5, 3, 0}}},
        {14, 5, {{0, 3, 2, 1}, {0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}}},
        {15,
         10,
         {{0, 4, 3, 2, 1},
          {5, 6, 7, 8, 9},
          {0, 1, 6, 5},
          {1, 2, 7, 6},
          {2, 3, 8, 7},
          {3, 4, 9, 8},
          {4, 0, 5, 9}}},
        {16,
         12,
         {{0, 5, 4, 3, 2, 1},
          {6, 7, 8, 9, 10, 11},
          {0, 1, 7, 6},
          {1, 2, 8, 7},
          {2, 3, 9, 8},
          {3, 4, 10, 9},
          {4, 5, 11, 10},
          {5, 0, 6, 11}}}};
  }();
  for (const auto& t : kTypes)
    if (t.type == type) return &t;
  return nullptr;
}

}  // namespace polydg::vtk_format
