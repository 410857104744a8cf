// The SVG plotter of `polydg bench` (cli/bench/plot.h): axis labels, ticks, points mapped
// monotonically, log axes dropping what they cannot show, categorical axes, empty plots.
#include "cli/bench/plot.h"

#include <gtest/gtest.h>

#include <cmath>
#include <regex>
#include <string>
#include <vector>

namespace polydg::bench {
namespace {

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

}  // namespace
}  // namespace polydg::bench
