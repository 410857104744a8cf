// The benchmark outputs: the CSV writer, the SVG plotter (axis labels, ticks, points mapped
// monotonically, log axes dropping what they cannot show) and `polydg bench --suite stability
// --quick` end to end (every file written, the B4 JSON keys and findings).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include <unistd.h>

#include <nlohmann/json.hpp>

#include "cli/csv.h"
#include "cli/plot.h"

#include "tests/support/run_polydg.h"

namespace polydg::cli {
namespace {

namespace fs = std::filesystem;

// --- CSV ------------------------------------------------------------------------------------

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

// --- plots ----------------------------------------------------------------------------------

struct Marker {
  double px, py;
};

/// The markers of each series, in drawing order, from the SVG text.
std::vector<std::vector<Marker>> markers(const std::string& svg) {
  std::vector<std::vector<Marker>> out;
  const std::regex marker(R"re(data-px="([-0-9.]+)" data-py="([-0-9.]+)")re");
  std::size_t pos = 0;
  while ((pos = svg.find("<g class=\"series\"", pos)) != std::string::npos) {
    const std::size_t end = svg.find("</g>", pos);
    const std::string group = svg.substr(pos, end - pos);
    out.emplace_back();
    for (auto it = std::sregex_iterator(group.begin(), group.end(), marker);
         it != std::sregex_iterator(); ++it)
      out.back().push_back({std::stod((*it)[1]), std::stod((*it)[2])});
    pos = end;
  }
  return out;
}

Plot samplePlot() {
  Plot p;
  p.title = "Error <against> time";
  p.x = {"wall time [s]", AxisScale::Log};
  p.y = {"L2 error", AxisScale::Log};
  p.series.push_back({"IP p=1", {0.01, 0.1, 1.0, 10.0}, {1e-3, 1e-4, 1e-5, 1e-6}});
  // A non-positive and a non-finite value: left out on log axes.
  p.series.push_back({"IP p=2", {0.02, 0.0, 0.2, 2.0}, {5e-4, 1e-5, std::nan(""), 1e-7}});
  return p;
}

TEST(Plot, LabelsTitleLegendAndDecadeTicks) {
  const std::string svg = renderSvg(samplePlot());
  EXPECT_EQ(svg.rfind("<?xml", 0), 0u);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  EXPECT_NE(svg.find("class=\"title\""), std::string::npos);
  EXPECT_NE(svg.find("Error &lt;against&gt; time"), std::string::npos);  // escaped
  EXPECT_NE(svg.find(">wall time [s]</text>"), std::string::npos);
  EXPECT_NE(svg.find(">L2 error</text>"), std::string::npos);
  EXPECT_NE(svg.find(">IP p=1</text>"), std::string::npos);
  EXPECT_NE(svg.find(">IP p=2</text>"), std::string::npos);
  // x spans 1e-2 .. 1e1: four decade labels; y 1e-7 .. 1e-3: five.
  for (int k : {-2, -1, 0, 1, -7, -6, -5, -4, -3})
    EXPECT_NE(svg.find(">" + std::to_string(k) + "</tspan>"), std::string::npos) << k;
}

TEST(Plot, PointsMapMonotonicallyAndLogAxesDropNonPositive) {
  const PlotLayout layout;
  const auto m = markers(renderSvg(samplePlot(), layout));
  ASSERT_EQ(m.size(), 2u);
  ASSERT_EQ(m[0].size(), 4u);
  ASSERT_EQ(m[1].size(), 2u);  // x = 0 and y = NaN left out
  for (std::size_t i = 1; i < m[0].size(); ++i) {
    EXPECT_GT(m[0][i].px, m[0][i - 1].px);  // larger x further right
    EXPECT_GT(m[0][i].py, m[0][i - 1].py);  // smaller y further down
    // Equal ratios, equal steps on log axes.
    EXPECT_NEAR(m[0][i].px - m[0][i - 1].px, m[0][1].px - m[0][0].px, 0.02);
  }
  for (const auto& s : m)
    for (const Marker& p : s) {
      EXPECT_GE(p.px, layout.left - 1e-9);
      EXPECT_LE(p.px, layout.width - layout.right + 1e-9);
      EXPECT_GE(p.py, layout.top - 1e-9);
      EXPECT_LE(p.py, layout.height - layout.bottom + 1e-9);
    }
  // The extreme decades of the data sit on the frame: x = 1e-2 on the left edge.
  EXPECT_NEAR(m[0][0].px, layout.left, 0.01);
  EXPECT_NEAR(m[0][3].px, layout.width - layout.right, 0.01);
}

TEST(Plot, LinearAxisTicksAreRoundNumbers) {
  EXPECT_EQ(axisTicks(0.0, 1.0, AxisScale::Linear),
            (std::vector<double>{0.0, 0.2, 0.4, 0.6000000000000001, 0.8, 1.0}));
  const auto t = axisTicks(3.81, 4.04, AxisScale::Linear);
  ASSERT_GE(t.size(), 3u);
  for (double x : t) EXPECT_NEAR(x * 20.0, std::round(x * 20.0), 1e-9);  // multiples of 0.05
  EXPECT_EQ(axisTicks(1e-3, 1e2, AxisScale::Log),
            (std::vector<double>{1e-3, 1e-2, 1e-1, 1.0, 10.0, 100.0}));
  // Under two decades: 2 and 5 times the powers of ten too.
  EXPECT_EQ(axisTicks(1.0, 10.0, AxisScale::Log), (std::vector<double>{1.0, 2.0, 5.0, 10.0}));
}

TEST(Plot, CategoricalAxisLabelsEachValue) {
  Plot p;
  p.title = "phases";
  p.x = {"phase", AxisScale::Linear, {"integration", "assembly", "solve"}};
  p.y = {"time", AxisScale::Log};
  p.series.push_back({"run", {1, 2, 3}, {0.01, 0.1, 1.0}});
  const std::string svg = renderSvg(p);
  for (const char* c : {">integration</text>", ">assembly</text>", ">solve</text>"})
    EXPECT_NE(svg.find(c), std::string::npos) << c;
  const auto m = markers(svg);
  ASSERT_EQ(m.size(), 1u);
  ASSERT_EQ(m[0].size(), 3u);
  // Equally spaced, half a step of margin on both sides.
  EXPECT_NEAR(m[0][2].px - m[0][1].px, m[0][1].px - m[0][0].px, 0.02);
  EXPECT_NEAR(m[0][0].px - PlotLayout{}.left, (m[0][1].px - m[0][0].px) / 2, 0.02);
}

TEST(Plot, EmptyPlotStillRenders) {
  Plot p;
  p.title = "nothing";
  p.x = {"x", AxisScale::Log};
  p.y = {"y", AxisScale::Linear};
  const std::string svg = renderSvg(p);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  EXPECT_TRUE(markers(svg).empty());
}

// --- polydg bench ---------------------------------------------------------------------------

using Result = polydg::testing::CommandResult;

Result run(const std::string& arguments) { return polydg::testing::runPolydg(arguments); }

TEST(BenchCommand, StabilitySuiteWritesJsonCsvAndPlots) {
  // Unique per process: two test runs at once must not share (and delete) the folder.
  const fs::path dir =
      fs::temp_directory_path() / ("polydg_bench_stability_" + std::to_string(getpid()));
  fs::remove_all(dir);
  const Result r = run("bench --suite stability --quick --quiet --out " + dir.string());
  ASSERT_EQ(r.exitCode, 0) << r.out;
  EXPECT_TRUE(r.out.empty()) << r.out;  // --quiet
  for (const char* file :
       {"stability.json", "stability.csv", "stability_sliver.svg", "stability_thin_neck.svg",
        "stability_incompressible.svg", "stability_scale.svg"})
    EXPECT_TRUE(fs::exists(dir / file)) << file;
  std::ifstream in(dir / "stability.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_TRUE(j["cond_method"].get<std::string>().find("Lanczos") != std::string::npos);
  ASSERT_FALSE(j["sliver"].empty());
  for (const nlohmann::json& s : j["sliver"]) {
    ASSERT_TRUE(s.contains("volume_ratio") && s.contains("merged") && s.contains("cond"));
    if (s["merged"].get<bool>()) {
      EXPECT_LE(s["cond_over_regular"].get<double>(), 100.0);
    }
  }
  for (const nlohmann::json& s : j["thin_neck"]) EXPECT_TRUE(s["positive_definite"].get<bool>());
  EXPECT_EQ(j["incompressible"].size(), 8u);  // 4 values of nu, p = 1 and 2
  for (const nlohmann::json& s : j["incompressible"])
    EXPECT_TRUE(s.contains("tip") && s.contains("reference") && s.contains("nu"));
  EXPECT_EQ(j["scale"].size(), 12u);  // B1 and B3, 3 scales, 2 offsets
  // Round-off: the coordinates' relative resolution amplified by the stiffness's condition
  // number, an order-of-magnitude bound (its constant is not known; the full suite reaches 2.6).
  constexpr double kRoundoffBoundFactor = 10.0;
  for (const nlohmann::json& s : j["scale"])
    EXPECT_LE(s["change"].get<double>(), kRoundoffBoundFactor * s["roundoff_bound"].get<double>())
        << s.dump();
  std::ifstream csv(dir / "stability.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_NE(header.find("case"), std::string::npos);
  EXPECT_NE(header.find("volume_ratio"), std::string::npos);
  fs::remove_all(dir);
}

TEST(BenchCommand, CuttingSuiteReintegratesOnlyWhatEachCutTouched) {
  const fs::path dir =
      fs::temp_directory_path() / ("polydg_bench_cutting_" + std::to_string(getpid()));
  fs::remove_all(dir);
  const Result r = run("bench --suite cutting --quick --quiet --out " + dir.string());
  ASSERT_EQ(r.exitCode, 0) << r.out;
  for (const char* file : {"cutting.json", "cutting.csv", "cutting.svg"})
    EXPECT_TRUE(fs::exists(dir / file)) << file;
  std::ifstream in(dir / "cutting.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  ASSERT_GE(j["runs"].size(), 4u);  // 3 cuts with validation none, at least 1 with local
  for (const nlohmann::json& run : j["runs"]) {
    EXPECT_TRUE(run["validation_passed"].get<bool>()) << run.dump();
    EXPECT_GT(run["elements_split"].get<std::size_t>(), 0u) << run.dump();
    // Each split element re-integrates its own faces only: far fewer than the mesh's faces.
    EXPECT_LT(run["faces_reintegrated"].get<std::size_t>(),
              run["faces_total"].get<std::size_t>() / 4)
        << run.dump();
  }
  fs::remove_all(dir);
}

TEST(BenchCommand, UnknownSuiteIsRefusedWithOneLine) {
  const Result r = run("bench --suite nonsense --out " +
                       (fs::temp_directory_path() / "polydg_bench_unknown").string());
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
  EXPECT_FALSE(fs::exists(fs::temp_directory_path() / "polydg_bench_unknown"));
}

}  // namespace
}  // namespace polydg::cli
