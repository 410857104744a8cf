// A small SVG line plotter for the benchmark reports: linear or logarithmic axes (decade ticks),
// one polyline with markers per series, a legend, a title and axis labels. Written by hand
// because the one plotting library Debian offers for C/C++ (PLplot) pulls gfortran and
// wxWidgets/GTK into the build for what is a few hundred lines of SVG.
#pragma once

#include <string>
#include <vector>

namespace polydg::bench {

enum class AxisScale { Linear, Log };

struct PlotAxis {
  std::string label;
  AxisScale scale = AxisScale::Linear;
  /// If not empty (linear axes only): a categorical axis, value i + 1 labelled categories[i],
  /// ticks only there.
  std::vector<std::string> categories = {};
};

/// One line of a plot: points (x[i], y[i]) joined in the given order. On a log axis,
/// non-positive values are left out; non-finite values are always left out.
struct PlotSeries {
  std::string label;
  std::vector<double> x, y;
};

struct Plot {
  std::string title;
  PlotAxis x, y;
  std::vector<PlotSeries> series;
};

/// Geometry of the rendered figure, in SVG user units (pixels).
struct PlotLayout {
  double width = 860, height = 500;
  double left = 80, right = 260, top = 44, bottom = 60;  ///< margins; the legend is on the right
};

/// The plot as a standalone SVG document. Every drawn data point is a
/// `<path class="marker" data-px=".." data-py=".." .../>` (its centre in pixels) inside the
/// `<g class="series" data-label="..">` of its series; tick labels have class "tick-label", the
/// axis labels "x-label" and "y-label", the title "title", legend entries "legend-entry". With
/// no finite point at all, the axes span [1, 10] (log) or [0, 1] (linear).
std::string renderSvg(const Plot& plot, const PlotLayout& layout = {});

/// Tick positions of an axis over [lo, hi]: on a log axis the powers of ten in the range (with
/// 2 and 5 times them when it spans under two decades), on a linear axis multiples of 1, 2 or
/// 5 times a power of ten, about five of them.
std::vector<double> axisTicks(double lo, double hi, AxisScale scale);

}  // namespace polydg::bench
