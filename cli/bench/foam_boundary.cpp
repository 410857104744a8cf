#include "cli/bench/foam_boundary.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <fstream>
#include <iterator>
#include <string_view>
#include <system_error>
#include <utility>

#include "polydg/util/error.h"

namespace polydg::bench {

namespace fs = std::filesystem;

namespace {

/// The tokens of one OpenFOAM ASCII file after its FoamFile header: words and numbers, the
/// punctuation ( ) { } ; each a token of its own, quoted strings whole, comments skipped.
class FoamText {
 public:
  explicit FoamText(const fs::path& file) : name_(file.string()) {
    std::ifstream in(file, std::ios::binary);
    if (!in) {
      std::error_code ec;
      if (fs::exists(file.string() + ".gz", ec))
        throw InputError(name_ + ".gz is gzipped; write the case with writeCompression off");
      throw InputError(name_ + " not found");
    }
    text_.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    if (peek() == "FoamFile") readHeader();
  }

  const std::string& foamClass() const { return class_; }

  std::string_view peek() {
    const std::size_t at = pos_;
    const std::string_view token = next(false);
    pos_ = at;
    return token;
  }

  std::string_view next(bool required = true) {
    skipSpaceAndComments();
    if (pos_ >= text_.size()) {
      if (required) fail("the file ends early");
      return {};
    }
    const std::size_t start = pos_;
    const char c = text_[pos_];
    if (c == '(' || c == ')' || c == '{' || c == '}' || c == ';') {
      ++pos_;
    } else if (c == '"') {
      pos_ = text_.find('"', pos_ + 1);
      if (pos_ == std::string::npos) fail("a quoted string does not end");
      ++pos_;
    } else {
      while (pos_ < text_.size() && !std::isspace(static_cast<unsigned char>(text_[pos_])) &&
             std::string_view("(){};/\"").find(text_[pos_]) == std::string_view::npos)
        ++pos_;
    }
    return std::string_view(text_).substr(start, pos_ - start);
  }

  void expect(std::string_view token) {
    if (next() != token) fail("expected '" + std::string(token) + "'");
  }

  std::size_t label() { return number<std::size_t>("a label"); }
  double scalar() { return number<double>("a number"); }

  [[noreturn]] void fail(const std::string& what) const {
    const auto line = std::count(text_.begin(), text_.begin() + std::min(pos_, text_.size()), '\n');
    throw InputError(name_ + ":" + std::to_string(line + 1) + ": " + what +
                     "; polydg reads OpenFOAM's ASCII polyMesh files");
  }

 private:
  template <class T>
  T number(const char* what) {
    const std::string_view token = next();
    T value{};
    const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (ec != std::errc() || end != token.data() + token.size())
      fail("expected " + std::string(what) + ", found '" + std::string(token) + "'");
    return value;
  }

  void skipSpaceAndComments() {
    while (pos_ < text_.size()) {
      if (std::isspace(static_cast<unsigned char>(text_[pos_]))) {
        ++pos_;
      } else if (text_.compare(pos_, 2, "//") == 0) {
        pos_ = std::min(text_.find('\n', pos_), text_.size());
      } else if (text_.compare(pos_, 2, "/*") == 0) {
        const std::size_t end = text_.find("*/", pos_ + 2);
        pos_ = end == std::string::npos ? text_.size() : end + 2;
      } else {
        return;
      }
    }
  }

  /// FoamFile { key value; ... }: keeps the class and refuses a binary format.
  void readHeader() {
    next();
    expect("{");
    for (std::string_view key = next(); key != "}"; key = next()) {
      const std::string_view value = next();
      expect(";");
      if (key == "class") class_ = value;
      if (key == "format" && value != "ascii")
        fail("format " + std::string(value) + "; write the case with writeFormat ascii");
    }
  }

  std::string name_, text_, class_;
  std::size_t pos_ = 0;
};

/// `N (` of a list, or `N {` of a uniform one (then `uniform` is set): returns N.
std::size_t listStart(FoamText& t, bool& uniform) {
  const std::size_t n = t.label();
  const std::string_view open = t.next();
  if (open != "(" && open != "{") t.fail("expected '(' or '{' after a list's size");
  uniform = open == "{";
  return n;
}

std::vector<std::size_t> readLabels(FoamText& t) {
  bool uniform = false;
  const std::size_t n = listStart(t, uniform);
  std::vector<std::size_t> labels;
  if (uniform) {
    labels.assign(n, t.label());
    t.expect("}");
    return labels;
  }
  labels.reserve(n);
  for (std::size_t i = 0; i < n; ++i) labels.push_back(t.label());
  t.expect(")");
  return labels;
}

std::vector<Vec3> readPoints(const fs::path& file) {
  FoamText t(file);
  bool uniform = false;
  const std::size_t n = listStart(t, uniform);
  if (uniform) t.fail("a uniform list of points");
  std::vector<Vec3> points(n);
  for (Vec3& p : points) {
    t.expect("(");
    for (int a = 0; a < 3; ++a) p[a] = t.scalar();
    t.expect(")");
  }
  t.expect(")");
  return points;
}

/// The patches of the boundary file: `N ( name { ... nFaces n; startFace s; ... } ... )`.
std::vector<FoamPatch> readPatches(const fs::path& file) {
  FoamText t(file);
  bool uniform = false;
  const std::size_t n = listStart(t, uniform);
  if (uniform) t.fail("a uniform list of patches");
  std::vector<FoamPatch> patches(n);
  for (FoamPatch& patch : patches) {
    patch.name = t.next();
    t.expect("{");
    bool size = false, start = false;
    for (std::string_view key = t.next(); key != "}"; key = t.next()) {
      if (key == "nFaces" || key == "startFace") {
        (key == "nFaces" ? size : start) = true;
        (key == "nFaces" ? patch.faces : patch.start) = t.label();
        t.expect(";");
        continue;
      }
      // Any other entry is skipped: its value up to ';', or a sub-dictionary in braces.
      for (int depth = 0;;) {
        const std::string_view v = t.next();
        if (v == "{") ++depth;
        if (v == "}" && --depth < 0) t.fail("a '}' too many in patch " + patch.name);
        if ((v == "}" && depth == 0) || (v == ";" && depth == 0)) break;
      }
    }
    if (!size || !start) t.fail("patch " + patch.name + " lacks nFaces or startFace");
  }
  t.expect(")");
  return patches;
}

/// Whether face `f` belongs to a patch (the patches sorted by start).
bool onBoundary(const std::vector<FoamPatch>& patches, std::size_t f) {
  return std::any_of(patches.begin(), patches.end(),
                     [&](const FoamPatch& p) { return f >= p.start && f < p.start + p.faces; });
}

/// The faces of the faces file that lie in a patch, by their index in the file.
std::vector<std::pair<std::size_t, std::vector<std::uint32_t>>> readPatchFaces(
    const fs::path& file, const std::vector<FoamPatch>& patches) {
  FoamText t(file);
  std::vector<std::pair<std::size_t, std::vector<std::uint32_t>>> faces;
  if (t.foamClass() == "faceCompactList") {
    const std::vector<std::size_t> offsets = readLabels(t), indices = readLabels(t);
    for (std::size_t f = 0; f + 1 < offsets.size(); ++f) {
      if (!onBoundary(patches, f)) continue;
      if (offsets[f] > offsets[f + 1] || offsets[f + 1] > indices.size())
        t.fail("face offsets out of order or beyond the indices");
      faces.emplace_back(f, std::vector<std::uint32_t>(indices.begin() + offsets[f],
                                                       indices.begin() + offsets[f + 1]));
    }
    return faces;
  }
  bool uniform = false;
  const std::size_t n = listStart(t, uniform);
  if (uniform) t.fail("a uniform list of faces");
  for (std::size_t f = 0; f < n; ++f) {
    const std::vector<std::size_t> face = readLabels(t);
    if (onBoundary(patches, f))
      faces.emplace_back(f, std::vector<std::uint32_t>(face.begin(), face.end()));
  }
  t.expect(")");
  return faces;
}

}  // namespace

FoamBoundary readFoamBoundary(const fs::path& caseDir) {
  const fs::path dir = caseDir / "constant" / "polyMesh";
  FoamBoundary b;
  b.points = readPoints(dir / "points");
  b.patches = readPatches(dir / "boundary");
  auto faces = readPatchFaces(dir / "faces", b.patches);
  for (const FoamPatch& p : b.patches) {
    const auto first =
        std::lower_bound(faces.begin(), faces.end(), p.start,
                         [](const auto& face, std::size_t f) { return face.first < f; });
    if (static_cast<std::size_t>(faces.end() - first) < p.faces ||
        (p.faces && first->first != p.start))
      throw InputError((dir / "boundary").string() + ": patch " + p.name +
                       " names faces beyond the faces file");
    for (std::size_t k = 0; k < p.faces; ++k) b.faces.push_back(first[k].second);
  }
  for (const auto& face : b.faces)
    for (std::uint32_t v : face)
      if (v >= b.points.size())
        throw InputError((dir / "faces").string() + ": point " + std::to_string(v) +
                         " beyond the " + std::to_string(b.points.size()) + " points");
  return b;
}

std::vector<Vec3> boundarySamples(const FoamBoundary& b) {
  std::vector<Vec3> samples;
  for (const auto& face : b.faces) {
    Vec3 mean = Vec3::Zero();
    for (std::size_t k = 0; k < face.size(); ++k) {
      const Vec3& p = b.points[face[k]];
      const Vec3& q = b.points[face[(k + 1) % face.size()]];
      samples.push_back(p);
      samples.push_back(0.5 * (p + q));
      mean += p;
    }
    if (!face.empty()) samples.push_back(mean / static_cast<double>(face.size()));
  }
  return samples;
}

double enclosedVolume(const FoamBoundary& b, const Vec3& reference) {
  double sixVolume = 0.0;
  for (const auto& face : b.faces) {
    if (face.empty()) continue;
    Vec3 mean = Vec3::Zero();
    for (std::uint32_t v : face) mean += b.points[v] - reference;
    mean /= static_cast<double>(face.size());
    for (std::size_t k = 0; k < face.size(); ++k) {
      const Vec3 p = b.points[face[k]] - reference;
      const Vec3 q = b.points[face[(k + 1) % face.size()]] - reference;
      sixVolume += p.cross(q).dot(mean);
    }
  }
  return sixVolume / 6.0;
}

}  // namespace polydg::bench
