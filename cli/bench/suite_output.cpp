#include "cli/bench/suite_output.h"

#include <cctype>
#include <cstdio>
#include <iostream>

#include "cli/bench/csv.h"
#include "model/files.h"
#include "polydg/model/names.h"
#include "util/format.h"

namespace polydg::bench {

void writeSuite(const std::filesystem::path& dir, const SuiteOutput& s, bool quiet) {
  writeJsonFile(dir / (s.name + ".json"), s.json);
  const std::string csv = toCsv(s.rows);
  writeFileAtomically(dir / (s.name + ".csv"), [&](std::ostream& os) { os << csv; });
  for (const NamedPlot& p : s.plots) {
    const std::string svg = renderSvg(p.plot);
    writeFileAtomically(dir / p.file, [&](std::ostream& os) { os << svg; });
  }
  if (!quiet) {
    std::cout << "wrote " << (dir / (s.name + ".json")).string() << ", " << s.name << ".csv";
    for (const NamedPlot& p : s.plots) std::cout << ", " << p.file;
    std::cout << std::endl;
  }
}

void SeriesSet::add(const std::string& key, double x, double y) {
  auto [it, fresh] = index_.emplace(key, series_.size());
  if (fresh) series_.push_back({key, {}, {}});
  series_[it->second].x.push_back(x);
  series_[it->second].y.push_back(y);
}

std::string upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

std::string shortNumber(double v) { return formatNumber(v, 3); }

nlohmann::json runJson(const BenchmarkRun& r) {
  return {{"method", toString(r.method)},
          {"degree", r.degree},
          {"mesh", r.mesh == BenchmarkMesh::Hex ? "hex" : "sliced"},
          {"n", r.n},
          {"elements", r.report.elements},
          {"dofs", r.report.dofs},
          {"nonzeros", r.report.nonzeros},
          {"sparsity", r.sparsity},
          {"t_integrate", r.report.integrateSeconds},
          {"t_assemble", r.report.assembleSeconds},
          {"t_solve", r.report.solveSeconds},
          {"l2_error", r.l2Error},
          {"h1_error", r.h1Error},
          {"eta", r.report.eta},
          {"solver", toString(r.report.solver.used)},
          {"iterations", r.report.solver.iterations},
          {"residual", r.report.solver.residual}};
}

void printRun(const BenchmarkRun& r) {
  std::cout << toString(r.method) << " p=" << r.degree << ' '
            << (r.mesh == BenchmarkMesh::Hex ? "hex" : "sliced") << " n=" << r.n << ": "
            << r.report.dofs << " DOFs, integrate " << r.report.integrateSeconds << " s, assemble "
            << r.report.assembleSeconds << " s, solve " << r.report.solveSeconds << " s";
  if (r.l2Error > 0) std::cout << ", L2 " << r.l2Error;
  std::cout << std::endl;
}

}  // namespace polydg::bench
