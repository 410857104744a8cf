// Reading polydg's JSON documents (pipelines and simulation scenes) strictly: every key
// is checked, values must have the expected type and range, and every error is one line naming
// the file and the place ("pipeline.json: steps[1].plnae: unknown key; see ...").
#pragma once

#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "polydg/mesh/poly_mesh.h"
#include "polydg/model/model.h"
#include "polydg/model/names.h"
#include "polydg/physics/dg/loads.h"
#include "polydg/util/error.h"

namespace polydg {

/// Reads one JSON object of a document. Each accessor records the key as known; finish()
/// refuses any key nobody asked about. Errors throw InputError("FILE: PLACE: WHAT; HINT").
class JsonObjectReader {
 public:
  /// `place` names the object in messages ("pipeline", "steps[2]"); `hint` ends every message.
  JsonObjectReader(const nlohmann::json& object, std::string place, std::string file,
                   std::string hint);

  [[noreturn]] void fail(const std::string& place, const std::string& what) const;
  /// "PLACE.key".
  std::string at(const std::string& key) const { return place_.empty() ? key : place_ + "." + key; }
  const std::string& place() const { return place_; }

  bool has(const std::string& key);
  /// The value of a required key (fails if missing).
  const nlohmann::json& get(const std::string& key);
  /// A finite number in [lo, hi].
  double number(const std::string& key, double lo, double hi);
  /// A finite number (for values whose option checks their range itself: see checked()).
  double number(const std::string& key);
  /// An integer in [lo, hi].
  int integer(const std::string& key, int lo, int hi);
  /// An integer (for values whose option checks their range itself).
  int integer(const std::string& key);
  /// Runs `check`, an option struct's check(), and reports what it refuses at the key it names
  /// under this object ("FILE: PLACE.KEY: PROBLEM; HINT"). One rule, the option's own, for
  /// files, Python and code alike.
  template <class Check>
  void checked(Check&& check) const {
    try {
      check();
    } catch (const InvalidOption& e) {
      fail(at(e.key), e.problem);
    }
  }
  bool boolean(const std::string& key);
  std::string string(const std::string& key);
  /// One of `names` (model/names.h), the choices listed in the error.
  template <class E>
  E choice(const std::string& key, const Names<E>& names) {
    const std::string s = string(key);
    if (const auto v = parseName(names, s)) return *v;
    fail(at(key), "'" + s + "' is not one of " + listNames(names));
  }
  /// `value` as exactly n finite numbers (`place` names it in errors).
  std::vector<double> numbers(const nlohmann::json& value, const std::string& place,
                              std::size_t n) const;
  Vec3 vec3(const nlohmann::json& value, const std::string& place) const;
  /// A region of the boundary, from the keys of this object: "below" [a, b, c, d] (the
  /// half-space a x + b y + c z <= d), "plane" [a, b, c, d] (faces lying in the plane),
  /// "box" [[x0, y0, z0], [x1, y1, z1]], or "axis" ("x", "y", "z") with "value" (the plane
  /// axis = value). Exactly one form.
  FaceSelector selection();
  /// A reader of the object under `key` (fails unless it is an object).
  JsonObjectReader object(const std::string& key);
  /// The value of a required key that must be a JSON array (else fails with `expected`, e.g.
  /// "expected a list of regions").
  const nlohmann::json& list(const std::string& key, const std::string& expected);
  /// A reader of element i of the list `list` (named `place` in errors).
  JsonObjectReader element(const nlohmann::json& list, const std::string& place,
                           std::size_t i) const;
  /// Call after reading: any key not asked about is an error.
  void finish() const;

 private:
  const nlohmann::json& object_;
  std::string place_, file_, hint_;
  std::set<std::string> known_;
};

/// The JSON document in `file` (a `what` file: "pipeline", "scene"). Throws InputError
/// ("FILE: cannot open the WHAT file", "FILE: not valid JSON (...)").
nlohmann::json readJsonDocument(const std::string& file, const std::string& what);

/// Readers shared by pipeline steps and simulation scenes. A cut from the keys of `r`: "plane"
/// [a, b, c, d] or "polygon" [[x, y, z], ...], and optional "remove_side", "validate",
/// "sliver_fraction".
CutRequest readCutRequest(JsonObjectReader& r);
/// The object under "material" of `r` ("E", "nu", "density"), over `defaults`.
Material readMaterial(JsonObjectReader& r, Material defaults);
/// "method" of `r`, if given: a DG method (methodNames) into `dg`, or a tet method
/// (tetMethodNames) into `tets`; with a tet method, the DG keys "degree" and "bz_penalty" are
/// refused.
void readMethod(JsonObjectReader& r, Method& dg, std::optional<TetMethod>& tets);

}  // namespace polydg
