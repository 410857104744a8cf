#include "model/json_reader.h"
#include "util/format.h"

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

namespace polydg {

using nlohmann::json;

JsonObjectReader::JsonObjectReader(const json& object, std::string place, std::string file,
                                   std::string hint)
    : object_(object), place_(std::move(place)), file_(std::move(file)), hint_(std::move(hint)) {
  if (!object.is_object()) fail(place_, "expected an object");
}

void JsonObjectReader::fail(const std::string& place, const std::string& what) const {
  throw InputError(file_ + ": " + (place.empty() ? "" : place + ": ") + what +
                   (hint_.empty() ? "" : "; " + hint_));
}

bool JsonObjectReader::has(const std::string& key) {
  known_.insert(key);
  return object_.contains(key);
}

const json& JsonObjectReader::get(const std::string& key) {
  known_.insert(key);
  if (!object_.contains(key)) fail(at(key), "missing");
  return object_.at(key);
}

double JsonObjectReader::number(const std::string& key, double lo, double hi) {
  const json& v = get(key);
  if (!v.is_number() || !std::isfinite(v.get<double>()) ||
      !(v.get<double>() >= lo && v.get<double>() <= hi))
    fail(at(key), "expected a number in [" + formatNumber(lo) + ", " + formatNumber(hi) + "]");
  return v.get<double>();
}

double JsonObjectReader::number(const std::string& key) {
  const json& v = get(key);
  if (!v.is_number() || !std::isfinite(v.get<double>())) fail(at(key), "expected a finite number");
  return v.get<double>();
}

int JsonObjectReader::integer(const std::string& key) {
  const json& v = get(key);
  if (!v.is_number_integer() || v.get<long long>() < std::numeric_limits<int>::min() ||
      v.get<long long>() > std::numeric_limits<int>::max())
    fail(at(key), "expected an integer");
  return v.get<int>();
}

int JsonObjectReader::integer(const std::string& key, int lo, int hi) {
  const json& v = get(key);
  if (!v.is_number_integer() || v.get<long long>() < lo || v.get<long long>() > hi)
    fail(at(key),
         "expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return v.get<int>();
}

bool JsonObjectReader::boolean(const std::string& key) {
  const json& v = get(key);
  if (!v.is_boolean()) fail(at(key), "expected true or false");
  return v.get<bool>();
}

std::string JsonObjectReader::string(const std::string& key) {
  const json& v = get(key);
  if (!v.is_string()) fail(at(key), "expected a string");
  return v.get<std::string>();
}

std::vector<double> JsonObjectReader::numbers(const json& value, const std::string& place,
                                              std::size_t n) const {
  const std::string expected = "expected " + std::to_string(n) + " finite numbers";
  if (!value.is_array() || value.size() != n) fail(place, expected);
  std::vector<double> out;
  for (const json& x : value) {
    if (!x.is_number() || !std::isfinite(x.get<double>())) fail(place, expected);
    out.push_back(x.get<double>());
  }
  return out;
}

Vec3 JsonObjectReader::vec3(const json& value, const std::string& place) const {
  const auto x = numbers(value, place, 3);
  return {x[0], x[1], x[2]};
}

FaceSelector JsonObjectReader::selection() {
  const bool below = has("below"), plane = has("plane"), box = has("box"), axis = has("axis");
  if (below + plane + box + axis != 1)
    fail(place_,
         "give exactly one region: \"below\" [a, b, c, d], \"plane\" [a, b, c, d], "
         "\"box\" [[x0, y0, z0], [x1, y1, z1]] or \"axis\" with \"value\"");
  try {
    if (below || plane) {
      const std::string key = below ? "below" : "plane";
      const auto v = numbers(get(key), at(key), 4);
      const Plane p = Plane::make(Vec3(v[0], v[1], v[2]), v[3]);
      return below ? FaceSelector::below(p) : FaceSelector::inPlane(p);
    }
    if (box) {
      const json& corners = get("box");
      if (!corners.is_array() || corners.size() != 2)
        fail(at("box"), "expected two corners [[x0, y0, z0], [x1, y1, z1]]");
      return FaceSelector::inBox(
          Box3(vec3(corners[0], at("box") + "[0]"), vec3(corners[1], at("box") + "[1]")));
    }
    const json& name = get("axis");
    const std::string a = name.is_string() ? name.get<std::string>() : "";
    if (a != "x" && a != "y" && a != "z") fail(at("axis"), "expected \"x\", \"y\" or \"z\"");
    return FaceSelector::inPlane(a[0] - 'x', number("value", -1e300, 1e300));
  } catch (const std::invalid_argument& e) {
    fail(place_, e.what());
  }
}

JsonObjectReader JsonObjectReader::object(const std::string& key) {
  return JsonObjectReader(get(key), at(key), file_, hint_);
}

JsonObjectReader JsonObjectReader::element(const json& list, const std::string& place,
                                           std::size_t i) const {
  return JsonObjectReader(list.at(i), place + "[" + std::to_string(i) + "]", file_, hint_);
}

void JsonObjectReader::finish() const {
  for (const auto& [key, value] : object_.items())
    if (!known_.count(key)) fail(at(key), "unknown key");
}

const json& JsonObjectReader::list(const std::string& key, const std::string& expected) {
  const json& v = get(key);
  if (!v.is_array()) fail(at(key), expected);
  return v;
}

json readJsonDocument(const std::string& file, const std::string& what) {
  std::ifstream in(file);
  if (!in) throw InputError(file + ": cannot open the " + what + " file");
  try {
    return json::parse(in);
  } catch (const json::parse_error& e) {
    throw InputError(file + ": not valid JSON (" + std::string(e.what()) + ")");
  }
}

}  // namespace polydg
