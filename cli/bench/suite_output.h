// What a suite of `polydg bench` produces (a JSON report, CSV rows and SVG plots), how it is
// written to DIR/NAME.json, DIR/NAME.csv and DIR/NAME*.svg, and the helpers the suites share
// to build it.
#pragma once

#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli/bench/plot.h"
#include "cli/bench/problems.h"

namespace polydg::bench {

/// Where a suite's progress lines go: each is printed on stdout unless the suite runs quiet.
using Log = std::function<void(const std::string&)>;

/// A plot and the file (name only, no folder) it goes to.
struct NamedPlot {
  std::string file;
  Plot plot;
};

/// What a suite writes: `json` as NAME.json, `rows` (an array of flat objects) as NAME.csv and
/// each plot as its file.
struct SuiteOutput {
  std::string name;
  nlohmann::json json;
  nlohmann::json rows = nlohmann::json::array();
  std::vector<NamedPlot> plots;
};

/// Writes the suite's files into `dir` (each atomically: a temporary file, then renamed), and
/// unless `quiet` one line naming them. Throws InputError if a file cannot be written.
void writeSuite(const std::filesystem::path& dir, const SuiteOutput& suite, bool quiet);

/// Plot series keyed by label, filled in run order: add() appends a point to the series of
/// `key`, starting a new series (after the existing ones) for a new key.
class SeriesSet {
 public:
  void add(const std::string& key, double x, double y);
  std::vector<PlotSeries>& series() { return series_; }

 private:
  std::map<std::string, std::size_t> index_;
  std::vector<PlotSeries> series_;
};

/// `s` in upper case (ASCII).
std::string upper(std::string s);
/// `v` with three significant digits ("%.3g"), for labels and log lines.
std::string shortNumber(double v);

/// One B1 or B2 run as a row of the accuracy and table41 reports: method, degree, mesh, n,
/// elements, dofs, nonzeros, sparsity, t_integrate, t_assemble, t_solve (wall seconds),
/// l2_error, h1_error, eta, solver, iterations, residual.
nlohmann::json runJson(const BenchmarkRun& run);
/// One line on stdout describing `run`: method, degree, mesh, n, DOFs, phase times, L2 error.
void printRun(const BenchmarkRun& run);

}  // namespace polydg::bench
