#include "model/time_series.h"

#include <cstdio>

#include "mesh/vtp_io.h"
#include "model/files.h"
#include "polydg/physics/dg/post_process.h"
#include "polydg/util/error.h"

namespace polydg {

namespace fs = std::filesystem;

TimeSeries::TimeSeries(const fs::path& folder, VtuEncoding encoding)
    : folder_(folder), encoding_(encoding) {
  std::error_code ec;
  fs::create_directories(folder_, ec);
  if (ec || !fs::is_directory(folder_))
    throw InputError("cannot create the output folder " + folder_.string() + ": " +
                     (ec ? ec.message() : "a file has that name") + "; choose another -o");
}

SimulationFrame TimeSeries::write(const PolyMesh& mesh, const DynamicSolver& solver, int step,
                                  const TriangleSurface* surface,
                                  const Eigen::Matrix<double, Eigen::Dynamic, 3>* displacement) {
  SimulationFrame frame =
      writeMesh(mesh, step, solver.time(), {CellArray{"von_mises", 1, solver.vonMises()}}, {},
                {displacementPointData(mesh, solver.basis(), solver.displacement()),
                 displacementPointData(mesh, solver.basis(), solver.velocity(), "velocity")});
  char name[32];
  if (surface) {
    std::snprintf(name, sizeof name, "scene_%06d.vtp", step);
    frame.surfaceFile = name;
    std::vector<Vec3> deformed(surface->vertices.size());
    std::vector<double> u(3 * deformed.size());
    for (std::size_t p = 0; p < deformed.size(); ++p) {
      const Vec3 d = displacement->row(static_cast<Eigen::Index>(p)).transpose();
      deformed[p] = surface->vertices[p] + d;
      for (int k = 0; k < 3; ++k) u[3 * p + static_cast<std::size_t>(k)] = d[k];
    }
    try {
      writeVtp((folder_ / name).string(), deformed, surface->triangles,
               {SurfacePointArray{"displacement", 3, u}}, encoding_);
    } catch (const std::runtime_error& e) {
      throw InputError(e.what());
    }
  }
  frames_.push_back(frame);
  writeCollection();
  return frame;
}

SimulationFrame TimeSeries::write(const PolyMesh& mesh, int step, double t,
                                  const std::vector<CellArray>& cells,
                                  const std::vector<PointArray>& points) {
  SimulationFrame frame = writeMesh(mesh, step, t, cells, points, {});
  frames_.push_back(frame);
  writeCollection();
  return frame;
}

SimulationFrame TimeSeries::writeMesh(const PolyMesh& mesh, int step, double t,
                                      const std::vector<CellArray>& cells,
                                      const std::vector<PointArray>& points,
                                      const std::vector<CornerArray>& corners) {
  SimulationFrame frame;
  frame.step = step;
  frame.t = t;
  char name[32];
  std::snprintf(name, sizeof name, "scene_%06d.vtu", step);
  frame.file = name;
  VtuWriteOptions options;
  options.encoding = encoding_;
  try {
    if (!layout_ || !layout_->fits(mesh)) layout_ = std::make_unique<VtuLayout>(mesh);
    writeVtu(*layout_, (folder_ / name).string(), options, cells, points, corners);
  } catch (const std::runtime_error& e) {
    throw InputError(e.what());
  }
  return frame;
}

void TimeSeries::writeCollection() const {
  writeFileAtomically(folder_ / "scene.pvd", [&](std::ostream& os) {
    os << "<?xml version=\"1.0\"?>\n"
          "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
          "  <Collection>\n";
    os.precision(17);
    // Part 0 is the mesh, part 1 the deformed embedded surface (ParaView shows them as one
    // multiblock data set per time).
    for (const SimulationFrame& f : frames_) {
      os << "    <DataSet timestep=\"" << f.t << "\" group=\"\" part=\"0\" file=\"" << f.file
         << "\"/>\n";
      if (!f.surfaceFile.empty())
        os << "    <DataSet timestep=\"" << f.t << "\" group=\"\" part=\"1\" file=\""
           << f.surfaceFile << "\"/>\n";
    }
    os << "  </Collection>\n</VTKFile>\n";
  });
}

}  // namespace polydg
