#include "cli/bench/check_mesh_output.h"

#include <cstdlib>
#include <sstream>

namespace polydg::bench {

namespace {

std::string trimmed(const std::string& line) {
  const std::size_t first = line.find_first_not_of(" \t\r");
  if (first == std::string::npos) return {};
  return line.substr(first, line.find_last_not_of(" \t\r") - first + 1);
}

/// The number right after the first `marker` in `line`, if both are there.
std::optional<double> numberAfter(const std::string& line, const std::string& marker) {
  const std::size_t at = line.find(marker);
  if (at == std::string::npos) return std::nullopt;
  const char* start = line.c_str() + at + marker.size();
  char* end = nullptr;
  const double value = std::strtod(start, &end);
  if (end == start) return std::nullopt;
  return value;
}

}  // namespace

CheckMeshSummary parseCheckMesh(const std::string& text) {
  CheckMeshSummary s;
  std::istringstream in(text);
  for (std::string raw; std::getline(in, raw);) {
    const std::string line = trimmed(raw);
    if (line.rfind("cells:", 0) == 0 && !s.cells) {
      if (const auto n = numberAfter(line, "cells:")) s.cells = static_cast<std::size_t>(*n);
    } else if (line.rfind("***", 0) == 0) {
      s.failures.push_back(trimmed(line.substr(3)));
    }
    if (const auto v = numberAfter(line, "Total volume = ")) s.totalVolume = v;
    if (const auto v = numberAfter(line, "Mesh non-orthogonality Max: ")) s.maxNonOrthogonality = v;
    if (const auto v = numberAfter(line, "Max skewness = ")) s.maxSkewness = v;
    if (const auto v = numberAfter(line, "Max aspect ratio = ")) s.maxAspectRatio = v;
    if (const auto v = numberAfter(line, "Max aspect ratio: ")) s.maxAspectRatio = v;
    if (line == "Mesh OK.") {
      s.verdict = "Mesh OK";
      s.failedChecks = 0;
    } else if (line.rfind("Failed ", 0) == 0 && line.find(" mesh checks.") != std::string::npos) {
      s.failedChecks = std::atoi(line.c_str() + 7);
      s.verdict = "Failed " + std::to_string(s.failedChecks) + " mesh checks";
    }
  }
  return s;
}

}  // namespace polydg::bench
