#include "cli/bench/csv.h"

#include <map>
#include <stdexcept>
#include <vector>

namespace polydg::bench {

namespace {

/// Flattens `value` into `out` under `prefix` ("a.b" for nested objects).
void flatten(const nlohmann::json& value, const std::string& prefix,
             std::vector<std::pair<std::string, std::string>>& out) {
  if (value.is_object()) {
    for (const auto& [key, inner] : value.items())
      flatten(inner, prefix.empty() ? key : prefix + "." + key, out);
    return;
  }
  std::string text;
  if (value.is_string()) {
    text = value.get<std::string>();
  } else if (value.is_array()) {
    for (std::size_t i = 0; i < value.size(); ++i)
      text +=
          (i ? ";" : "") + (value[i].is_string() ? value[i].get<std::string>() : value[i].dump());
  } else if (!value.is_null()) {
    text = value.dump();  // numbers in shortest round-trip form, booleans as true/false
  }
  out.emplace_back(prefix, std::move(text));
}

std::string csvField(const std::string& field) {
  if (field.find_first_of(",\"\r\n") == std::string::npos) return field;
  std::string out = "\"";
  for (char c : field) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

}  // namespace

std::string toCsv(const nlohmann::json& rows) {
  if (!rows.is_array()) throw std::invalid_argument("toCsv: expected an array of objects");
  std::vector<std::string> columns;
  std::map<std::string, std::size_t> index;
  std::vector<std::vector<std::pair<std::string, std::string>>> flat;
  for (const nlohmann::json& row : rows) {
    if (!row.is_object()) throw std::invalid_argument("toCsv: expected an array of objects");
    flat.emplace_back();
    flatten(row, "", flat.back());
    for (const auto& [key, text] : flat.back())
      if (index.emplace(key, columns.size()).second) columns.push_back(key);
  }
  std::string csv;
  for (std::size_t c = 0; c < columns.size(); ++c) csv += (c ? "," : "") + csvField(columns[c]);
  csv += "\r\n";
  for (const auto& row : flat) {
    std::vector<std::string> fields(columns.size());
    for (const auto& [key, text] : row) fields[index.at(key)] = text;
    for (std::size_t c = 0; c < fields.size(); ++c) csv += (c ? "," : "") + csvField(fields[c]);
    csv += "\r\n";
  }
  return csv;
}

}  // namespace polydg::bench
