// The time series of a simulation: one VTU per frame (and the deformed embedded surface as a
// VTP) and the ParaView collection scene.pvd listing them, rewritten (atomically) after every
// frame so that an interrupted run leaves a readable series. Private to model/.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "mesh/vtu_layout.h"
#include "physics/dynamics/dynamics.h"
#include "polydg/model/scene.h"

namespace polydg {

class TimeSeries {
 public:
  /// Creates `folder` if missing; throws InputError if it cannot.
  TimeSeries(const std::filesystem::path& folder, VtuEncoding encoding);

  std::string pvd() const { return (folder_ / "scene.pvd").string(); }

  /// The frame of `solver`'s state after `step` steps: point data displacement and velocity,
  /// cell data von_mises; with `surface`, also the deformed surface (`displacement`: #V by 3).
  /// Throws InputError if a file cannot be written.
  SimulationFrame write(const PolyMesh& mesh, const DynamicSolver& solver, int step,
                        const TriangleSurface* surface,
                        const Eigen::Matrix<double, Eigen::Dynamic, 3>* displacement);
  /// The mesh was edited since the last frame: the next one lays its cells out again (the
  /// layout is kept between frames of an unchanged mesh).
  void meshChanged() { layout_.reset(); }
  /// A frame with the given point and cell data on `mesh` (the tet methods' frames: point
  /// displacement and velocity).
  SimulationFrame write(const PolyMesh& mesh, int step, double t,
                        const std::vector<CellArray>& cells, const std::vector<PointArray>& points);

 private:
  /// Writes the frame's VTU (scene_NNNNNN.vtu) and returns the frame, not yet listed.
  SimulationFrame writeMesh(const PolyMesh& mesh, int step, double t,
                            const std::vector<CellArray>& cells,
                            const std::vector<PointArray>& points,
                            const std::vector<CornerArray>& corners);
  void writeCollection() const;

  std::filesystem::path folder_;
  VtuEncoding encoding_;
  std::vector<SimulationFrame> frames_;
  std::unique_ptr<VtuLayout> layout_;  ///< of the mesh of the last frame
};

}  // namespace polydg
