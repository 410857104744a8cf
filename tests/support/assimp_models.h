// The assimp-testmodels corpus (Debian package assimp-testmodels): where it is and which of its
// files are models, for tests that run over every model.
#pragma once

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <set>
#include <string>

namespace polydg::corpus {

inline const std::filesystem::path kAssimpModels = "/usr/share/assimp/models";

/// True for files assimp reads as models (by extension; Ogre XML by its double extension).
inline bool isSupportedModel(const std::filesystem::path& path) {
  static const std::set<std::string> kExtensions = {
      "obj",  "stl",     "ply", "off", "gltf",  "glb", "3ds", "dae", "fbx", "x",   "ase", "lwo",
      "ms3d", "md2",     "md3", "mdl", "blend", "ac",  "3mf", "amf", "ifc", "nff", "raw", "smd",
      "xgl",  "irrmesh", "cob", "q3o", "q3s",   "ter", "hmp", "lws", "csm", "b3d"};
  std::string name = path.filename().string();
  for (char& ch : name) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  if (name.size() > 9 && name.ends_with(".mesh.xml")) return true;  // Ogre XML
  const std::size_t dot = name.rfind('.');
  return dot != std::string::npos && kExtensions.contains(name.substr(dot + 1));
}

}  // namespace polydg::corpus
