// The CSV writer of `polydg bench` (cli/bench/csv.h): union of columns, flattening, quoting,
// numbers that round-trip, and what it refuses.
#include "cli/bench/csv.h"

#include <gtest/gtest.h>

#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace polydg::bench {
namespace {

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::string line;
  std::istringstream in(text);
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    out.push_back(line);
  }
  return out;
}

TEST(Csv, UnionOfColumnsFlattenedAndQuoted) {
  const nlohmann::json rows = nlohmann::json::parse(R"([
    {"a": 1, "b": "x,y", "t": {"slice": 0.5}},
    {"a": 0.1, "c": true, "b": "say \"hi\"", "v": [1, 2.5], "n": null}
  ])");
  const std::vector<std::string> l = lines(toCsv(rows));
  ASSERT_EQ(l.size(), 3u);
  EXPECT_EQ(l[0], "a,b,t.slice,c,n,v");
  EXPECT_EQ(l[1], "1,\"x,y\",0.5,,,");
  EXPECT_EQ(l[2], "0.1,\"say \"\"hi\"\"\",,true,,1;2.5");
}

TEST(Csv, NumbersRoundTrip) {
  const double x = 0.1 + 0.2, y = 1e-300 / 3;
  const std::vector<std::string> l = lines(toCsv(nlohmann::json::array({{{"x", x}, {"y", y}}})));
  ASSERT_EQ(l.size(), 2u);
  const auto comma = l[1].find(',');
  EXPECT_EQ(std::stod(l[1].substr(0, comma)), x);
  EXPECT_EQ(std::stod(l[1].substr(comma + 1)), y);
}

TEST(Csv, RefusesWhatIsNotAnArrayOfObjects) {
  EXPECT_THROW(toCsv(nlohmann::json::object()), std::invalid_argument);
  EXPECT_THROW(toCsv(nlohmann::json::array({1, 2})), std::invalid_argument);
  EXPECT_EQ(lines(toCsv(nlohmann::json::array())).size(), 1u);  // an empty header line
}

}  // namespace
}  // namespace polydg::bench
