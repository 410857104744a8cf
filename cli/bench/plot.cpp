#include "cli/bench/plot.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "mesh/xml_escape.h"

namespace polydg::bench {

namespace {

/// Matplotlib's "tab10" colours: distinct, readable on white.
constexpr std::array<const char*, 10> kColours{"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728",
                                               "#9467bd", "#8c564b", "#e377c2", "#7f7f7f",
                                               "#bcbd22", "#17becf"};
constexpr int kMarkerShapes = 5;
constexpr double kMarkerRadius = 4.0;

std::string fixed(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", v);
  return buf;
}

bool usable(double v, AxisScale scale) {
  return std::isfinite(v) && (scale == AxisScale::Linear || v > 0.0);
}

/// The axis range [lo, hi] covering `values`: whole decades on a log axis, a 5% margin on a
/// linear one.
std::array<double, 2> axisRange(const std::vector<double>& values, AxisScale scale) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (double v : values)
    if (usable(v, scale)) {
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  if (scale == AxisScale::Log) {
    if (!(lo <= hi)) return {1.0, 10.0};
    // The nearest values 1, 2 or 5 times a power of ten around the data.
    const double a = std::pow(10.0, std::floor(std::log10(lo))),
                 b = std::pow(10.0, std::ceil(std::log10(hi)));
    double from = a, to = b;
    for (double m : {2.0, 5.0})
      if (m * a <= lo) from = m * a;
    for (double m : {0.5, 0.2})
      if (m * b >= hi) to = m * b;
    if (from == to) {
      from /= 10.0;
      to *= 10.0;
    }
    return {from, to};
  }
  if (!(lo <= hi)) return {0.0, 1.0};
  if (lo == hi) {
    const double pad = lo == 0.0 ? 1.0 : 0.1 * std::abs(lo);
    return {lo - pad, hi + pad};
  }
  const double pad = 0.05 * (hi - lo);
  return {lo - pad, hi + pad};
}

/// Position along an axis in [0, 1].
double fraction(double v, const std::array<double, 2>& range, AxisScale scale) {
  if (scale == AxisScale::Log)
    return (std::log10(v) - std::log10(range[0])) / (std::log10(range[1]) - std::log10(range[0]));
  return (v - range[0]) / (range[1] - range[0]);
}

/// "10<sup>k</sup>" for exact powers of ten on a log axis, else the shortest %g form.
std::string tickLabel(double v, AxisScale scale) {
  if (scale == AxisScale::Log) {
    const double k = std::round(std::log10(v));
    if (std::abs(std::log10(v) - k) < 1e-9)
      return "10<tspan dy=\"-6\" font-size=\"9\">" + std::to_string(static_cast<int>(k)) +
             "</tspan>";
  }
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", std::abs(v) < 1e-12 ? 0.0 : v);
  return buf;
}

/// An SVG path of marker `shape` centred at (x, y).
std::string markerPath(int shape, double x, double y) {
  const double r = kMarkerRadius;
  std::ostringstream d;
  switch (shape % kMarkerShapes) {
    case 0:  // circle
      d << "M" << fixed(x - r) << ',' << fixed(y) << " a" << r << ',' << r << " 0 1,0 " << 2 * r
        << ",0 a" << r << ',' << r << " 0 1,0 " << -2 * r << ",0 Z";
      break;
    case 1:  // square
      d << "M" << fixed(x - r) << ',' << fixed(y - r) << " h" << 2 * r << " v" << 2 * r << " h"
        << -2 * r << " Z";
      break;
    case 2:  // triangle
      d << "M" << fixed(x) << ',' << fixed(y - r * 1.2) << " L" << fixed(x + r * 1.1) << ','
        << fixed(y + r * 0.8) << " L" << fixed(x - r * 1.1) << ',' << fixed(y + r * 0.8) << " Z";
      break;
    case 3:  // diamond
      d << "M" << fixed(x) << ',' << fixed(y - r * 1.3) << " L" << fixed(x + r) << ',' << fixed(y)
        << " L" << fixed(x) << ',' << fixed(y + r * 1.3) << " L" << fixed(x - r) << ',' << fixed(y)
        << " Z";
      break;
    default:  // inverted triangle
      d << "M" << fixed(x) << ',' << fixed(y + r * 1.2) << " L" << fixed(x + r * 1.1) << ','
        << fixed(y - r * 0.8) << " L" << fixed(x - r * 1.1) << ',' << fixed(y - r * 0.8) << " Z";
  }
  return d.str();
}

/// Series k's marker: after every ten series (one cycle of colours) the shapes shift by one,
/// so that colour and shape together stay distinct for 50 series.
int markerShape(std::size_t k) {
  return static_cast<int>((k + k / kColours.size()) % kMarkerShapes);
}
/// Series of the second, fourth, ... colour cycle are dashed.
std::string dash(std::size_t k) {
  return (k / kColours.size()) % 2 ? " stroke-dasharray=\"7,3\"" : "";
}

}  // namespace

std::vector<double> axisTicks(double lo, double hi, AxisScale scale) {
  std::vector<double> ticks;
  if (!(lo < hi)) return ticks;
  if (scale == AxisScale::Log) {
    const int a = static_cast<int>(std::floor(std::log10(lo) + 1e-9));
    const int b = static_cast<int>(std::ceil(std::log10(hi) - 1e-9));
    const int decades = b - a;
    const bool narrow = std::log10(hi / lo) < 2.0 - 1e-9;
    // Thin the labels of long ranges to at most about 12 decades.
    const int every = std::max(1, (decades + 11) / 12);
    for (int k = a; k <= b; ++k) {
      const double p = std::pow(10.0, k);
      if (k % every == 0 && p >= lo * (1 - 1e-12) && p <= hi * (1 + 1e-12)) ticks.push_back(p);
      if (narrow && k < b)
        for (double m : {2.0, 5.0})
          if (m * p >= lo && m * p <= hi) ticks.push_back(m * p);
    }
    std::sort(ticks.begin(), ticks.end());
    return ticks;
  }
  const double raw = (hi - lo) / 5.0;
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  double step = magnitude;
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * magnitude >= raw) {
      step = m * magnitude;
      break;
    }
  for (double t = std::ceil(lo / step) * step; t <= hi + 1e-9 * step; t += step)
    ticks.push_back(std::abs(t) < 1e-12 * step ? 0.0 : t);
  return ticks;
}

std::string renderSvg(const Plot& plot, const PlotLayout& l) {
  std::vector<double> xs, ys;
  for (const PlotSeries& s : plot.series)
    for (std::size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i)
      if (usable(s.x[i], plot.x.scale) && usable(s.y[i], plot.y.scale)) {
        xs.push_back(s.x[i]);
        ys.push_back(s.y[i]);
      }
  auto xr = axisRange(xs, plot.x.scale), yr = axisRange(ys, plot.y.scale);
  if (!plot.x.categories.empty()) xr = {0.5, plot.x.categories.size() + 0.5};
  const double w = l.width - l.left - l.right, h = l.height - l.top - l.bottom;
  auto px = [&](double v) { return l.left + w * fraction(v, xr, plot.x.scale); };
  auto py = [&](double v) { return l.top + h * (1.0 - fraction(v, yr, plot.y.scale)); };

  std::ostringstream svg;
  svg << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << l.width << "\" height=\""
      << l.height << "\" viewBox=\"0 0 " << l.width << ' ' << l.height
      << "\" font-family=\"DejaVu Sans, Arial, sans-serif\" font-size=\"12\">\n"
      << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
      << "<text class=\"title\" x=\"" << fixed(l.left + w / 2) << "\" y=\"" << fixed(l.top / 2 + 5)
      << "\" text-anchor=\"middle\" font-size=\"15\" font-weight=\"bold\">" << xmlEscape(plot.title)
      << "</text>\n";
  // Grid and ticks.
  svg << "<g class=\"grid\" stroke=\"#dddddd\" stroke-width=\"1\">\n";
  std::vector<double> xt = axisTicks(xr[0], xr[1], plot.x.scale);
  const std::vector<double> yt = axisTicks(yr[0], yr[1], plot.y.scale);
  if (!plot.x.categories.empty()) {
    xt.clear();
    for (std::size_t i = 0; i < plot.x.categories.size(); ++i) xt.push_back(i + 1.0);
  }
  auto xTickLabel = [&](double t) {
    if (plot.x.categories.empty()) return tickLabel(t, plot.x.scale);
    return xmlEscape(plot.x.categories[static_cast<std::size_t>(t) - 1]);
  };
  for (double t : xt)
    svg << "<line x1=\"" << fixed(px(t)) << "\" y1=\"" << fixed(l.top) << "\" x2=\"" << fixed(px(t))
        << "\" y2=\"" << fixed(l.top + h) << "\"/>\n";
  for (double t : yt)
    svg << "<line x1=\"" << fixed(l.left) << "\" y1=\"" << fixed(py(t)) << "\" x2=\""
        << fixed(l.left + w) << "\" y2=\"" << fixed(py(t)) << "\"/>\n";
  svg << "</g>\n<rect x=\"" << fixed(l.left) << "\" y=\"" << fixed(l.top) << "\" width=\""
      << fixed(w) << "\" height=\"" << fixed(h) << "\" fill=\"none\" stroke=\"black\"/>\n";
  for (double t : xt)
    svg << "<text class=\"tick-label\" x=\"" << fixed(px(t)) << "\" y=\"" << fixed(l.top + h + 18)
        << "\" text-anchor=\"middle\">" << xTickLabel(t) << "</text>\n";
  for (double t : yt)
    svg << "<text class=\"tick-label\" x=\"" << fixed(l.left - 8) << "\" y=\"" << fixed(py(t) + 4)
        << "\" text-anchor=\"end\">" << tickLabel(t, plot.y.scale) << "</text>\n";
  svg << "<text class=\"x-label\" x=\"" << fixed(l.left + w / 2) << "\" y=\""
      << fixed(l.height - 14) << "\" text-anchor=\"middle\" font-size=\"13\">"
      << xmlEscape(plot.x.label) << "</text>\n"
      << "<text class=\"y-label\" transform=\"translate(18," << fixed(l.top + h / 2)
      << ") rotate(-90)\" text-anchor=\"middle\" font-size=\"13\">" << xmlEscape(plot.y.label)
      << "</text>\n";
  // Series, clipped to the frame.
  svg << "<clipPath id=\"frame\"><rect x=\"" << fixed(l.left - kMarkerRadius) << "\" y=\""
      << fixed(l.top - kMarkerRadius) << "\" width=\"" << fixed(w + 2 * kMarkerRadius)
      << "\" height=\"" << fixed(h + 2 * kMarkerRadius) << "\"/></clipPath>\n";
  for (std::size_t k = 0; k < plot.series.size(); ++k) {
    const PlotSeries& s = plot.series[k];
    const char* colour = kColours[k % kColours.size()];
    const int shape = markerShape(k);
    svg << "<g class=\"series\" data-label=\"" << xmlEscape(s.label)
        << "\" clip-path=\"url(#frame)\">\n";
    std::ostringstream line, markers;
    for (std::size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
      if (!usable(s.x[i], plot.x.scale) || !usable(s.y[i], plot.y.scale)) continue;
      const double x = px(s.x[i]), y = py(s.y[i]);
      line << fixed(x) << ',' << fixed(y) << ' ';
      markers << "<path class=\"marker\" data-px=\"" << fixed(x) << "\" data-py=\"" << fixed(y)
              << "\" d=\"" << markerPath(shape, x, y) << "\" fill=\"" << colour
              << "\" stroke=\"white\" stroke-width=\"0.8\"/>\n";
    }
    svg << "<polyline class=\"line\" points=\"" << line.str() << "\" fill=\"none\" stroke=\""
        << colour << "\" stroke-width=\"1.8\"" << dash(k) << "/>\n"
        << markers.str() << "</g>\n";
  }
  // Legend, right of the frame.
  const double lx = l.left + w + 16;
  for (std::size_t k = 0; k < plot.series.size(); ++k) {
    const double y = l.top + 10 + 18.0 * static_cast<double>(k);
    const char* colour = kColours[k % kColours.size()];
    svg << "<g class=\"legend-entry\"><line x1=\"" << fixed(lx) << "\" y1=\"" << fixed(y)
        << "\" x2=\"" << fixed(lx + 26) << "\" y2=\"" << fixed(y) << "\" stroke=\"" << colour
        << "\" stroke-width=\"1.8\"" << dash(k) << "/><path d=\""
        << markerPath(markerShape(k), lx + 13, y) << "\" fill=\"" << colour << "\"/><text x=\""
        << fixed(lx + 32) << "\" y=\"" << fixed(y + 4) << "\" font-size=\"11\">"
        << xmlEscape(plot.series[k].label) << "</text></g>\n";
  }
  svg << "</svg>\n";
  return svg.str();
}

}  // namespace polydg::bench
