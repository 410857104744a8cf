// polydg info: counts, closedness, bounding box and enclosed volume of a surface or a VTU mesh.
#include <iostream>

#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "cli/report.h"
#include "polydg/integrate/moment_cache.h"
#include "polydg/mesh/surface.h"
#include "polydg/mesh/surface_io.h"
#include "polydg/mesh/validate.h"
#include "polydg/mesh/vtu_io.h"

namespace polydg::cli {

namespace {

struct InfoOptions {
  std::string input;
  std::string report;
};

nlohmann::json boxJson(const Box3& box) {
  if (box.isEmpty()) return nullptr;
  return {{"min", {box.min().x(), box.min().y(), box.min().z()}},
          {"max", {box.max().x(), box.max().y(), box.max().z()}}};
}

nlohmann::json surfaceInfo(const std::string& path) {
  SurfaceReadInfo read;
  const TriangleSurface surface = readSurface(path, &read);
  const SurfaceTopology topo = analyzeTopology(surface);
  nlohmann::json j;
  j["kind"] = "surface";
  j["meshes"] = read.meshes;
  j["vertices"] = surface.vertices.size();
  j["vertices_before_weld"] = read.inputVertices;
  j["triangles"] = surface.triangles.size();
  j["degenerate_triangles_dropped"] = read.droppedDegenerate;
  j["edges"] = topo.edges;
  j["boundary_edges"] = topo.boundaryEdges;
  j["non_manifold_edges"] = topo.nonManifoldEdges;
  j["misoriented_edges"] = topo.misorientedEdges;
  j["degenerate_triangles"] = topo.degenerateTriangles;
  j["components"] = topo.components;
  j["closed"] = topo.closed();
  j["bounding_box"] = boxJson(bounds(surface));
  j["area"] = surfaceArea(surface);
  // The enclosed volume is only defined for a closed surface.
  j["volume"] = topo.closed() ? nlohmann::json(enclosedVolume(surface)) : nlohmann::json(nullptr);
  return j;
}

nlohmann::json meshInfo(const std::string& path) {
  const PolyMesh mesh = readVtu(path);
  const ValidationReport v = validate(mesh);
  MomentCache moments(mesh, 0);
  moments.update();
  double volume = 0.0;
  for (std::size_t e = 0; e < mesh.numElements(); ++e) volume += moments.volume(ElementId(e));
  std::size_t holed = 0;
  for (const Face& face : mesh.faces()) holed += face.numLoops() > 1;
  nlohmann::json j;
  j["kind"] = "volume_mesh";
  j["vertices"] = mesh.numVertices();
  j["faces"] = mesh.numFaces();
  j["faces_with_holes"] = holed;
  j["interior_faces"] = v.interiorFaces;
  j["boundary_faces"] = v.boundaryFaces;
  j["elements"] = mesh.numElements();
  j["components"] = v.components;
  j["closed"] = v.openElements == 0;
  j["valid"] = v.passed;
  j["bounding_box"] = boxJson(meshBounds(mesh));
  j["volume"] = volume;
  return j;
}

void printInfo(const std::string& path, const nlohmann::json& j) {
  std::cout << path << ": " << j["kind"].get<std::string>() << '\n';
  for (const auto& [key, value] : j.items()) {
    if (key == "kind") continue;
    std::cout << "  " << key << ": " << value.dump() << '\n';
  }
}

}  // namespace

bool isVolumeMeshPath(const std::string& path) {
  const auto ext = std::filesystem::path(path).extension().string();
  return ext == ".vtu" || ext == ".VTU";
}

void addInfoCommand(CLI::App& app, const CommonOptions& common, int& exitCode) {
  auto options = std::make_shared<InfoOptions>();
  CLI::App* cmd = app.add_subcommand(
      "info", "Counts, closedness, bounding box and enclosed volume of a surface or VTU mesh");
  cmd->add_option("input", options->input, "surface file (any format assimp reads) or .vtu")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--report", options->report, "write the figures as JSON to this file");
  cmd->callback([options, &common, &exitCode] {
    const nlohmann::json j =
        isVolumeMeshPath(options->input) ? meshInfo(options->input) : surfaceInfo(options->input);
    if (!options->report.empty()) {
      requireDistinct(options->report, options->input);
      nlohmann::json report = j;
      report["command"] = "info";
      report["input"] = options->input;
      writeReport(options->report, report);
    }
    if (!common.quiet) printInfo(options->input, j);
    exitCode = 0;
  });
}

}  // namespace polydg::cli
