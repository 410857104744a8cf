// Benchmark runs (a JSON array of objects) as CSV for spreadsheets and plotting tools.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

namespace polydg::bench {

/// RFC 4180 CSV of `rows`, an array of JSON objects: one header line, then one line per row.
/// Columns are the keys of all rows in order of first appearance; nested objects are flattened
/// to "outer.inner" columns and arrays of numbers to "a;b;c". Numbers keep full precision
/// (shortest round-trip form), booleans are true/false, null and missing keys are empty, and
/// fields containing a comma, quote or line break are quoted. Throws std::invalid_argument if
/// `rows` is not an array of objects.
std::string toCsv(const nlohmann::json& rows);

}  // namespace polydg::bench
