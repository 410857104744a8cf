// polydg cut: plane cuts of a simulation mesh in place, each operation validated; the output
// is written only if every operation passed.
//
// Sample runs:
//   polydg cut mesh.vtu -o half.vtu --plane "0,0,1,0.5" --remove-side + --report cut.json
//   polydg cut mesh.vtu -o slit.vtu --polygon "0,0,0.5;1,0,0.5;1,1,0.5;0,1,0.5"
#include <iostream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "cli/json_reports.h"
#include "cli/progress.h"
#include "cli/report.h"
#include "polydg/cut/cut.h"
#include "polydg/mesh/validate.h"
#include "polydg/mesh/vtu_io.h"

namespace polydg::cli {

namespace {

struct CutCommandOptions {
  std::string input, output, report;
  std::vector<std::string> planes;
  std::string polygon;
  std::string removeSide;  ///< "", "+" or "-"
  double sliverFraction = kDefaultSliverFraction;
  ValidationLevel validation = ValidationLevel::Local;
};

/// Comma- or semicolon-separated numbers; throws UserError naming `what` if one is not a
/// finite number or the count is not `count` (0: any).
std::vector<double> parseNumbers(const std::string& text, char separator, std::size_t count,
                                 const std::string& what) {
  std::vector<double> values;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, separator)) {
    std::size_t used = 0;
    double v = 0.0;
    try {
      v = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    while (used < item.size() && std::isspace(static_cast<unsigned char>(item[used]))) ++used;
    if (used == 0 || used != item.size() || !std::isfinite(v))
      throw UserError(what + ": '" + item + "' is not a number");
    values.push_back(v);
  }
  if (count != 0 && values.size() != count)
    throw UserError(what + ": expected " + std::to_string(count) + " numbers, got " +
                    std::to_string(values.size()));
  return values;
}

Blade parsePlane(const std::string& text) {
  const std::string what = "--plane \"" + text + "\" (nx,ny,nz,d)";
  const auto v = parseNumbers(text, ',', 4, what);
  try {
    return Blade::plane(Vec3(v[0], v[1], v[2]), v[3]);
  } catch (const std::invalid_argument& e) {
    throw UserError(what + ": " + e.what());
  }
}

Blade parsePolygon(const std::string& text) {
  const std::string what = "--polygon (x1,y1,z1;x2,y2,z2;...)";
  std::vector<Vec3> corners;
  std::stringstream in(text);
  std::string corner;
  while (std::getline(in, corner, ';')) {
    const auto v = parseNumbers(corner, ',', 3, what);
    corners.emplace_back(v[0], v[1], v[2]);
  }
  try {
    return Blade::fromPolygon(std::move(corners));
  } catch (const std::invalid_argument& e) {
    throw UserError(what + ": " + e.what());
  }
}

std::string describe(const Blade& blade) {
  std::ostringstream s;
  if (blade.finite())
    s << "polygon with " << blade.polygon.size() << " corners";
  else
    s << "plane " << blade.normal.x() << "," << blade.normal.y() << "," << blade.normal.z() << ","
      << blade.offset;
  return s.str();
}

void run(const CutCommandOptions& o, bool quiet, int& exitCode) {
  if (!isVolumeMeshPath(o.input))
    throw UserError(o.input + ": cut reads simulation meshes (.vtu); make one with 'polydg mesh'");
  if (!isVolumeMeshPath(o.output)) throw UserError(o.output + ": the output must be a .vtu file");
  requireDistinct(o.output, o.input);
  if (!o.report.empty()) requireDistinct(o.report, o.input);
  std::vector<Blade> blades;
  for (const std::string& p : o.planes) blades.push_back(parsePlane(p));
  if (!o.polygon.empty()) blades.push_back(parsePolygon(o.polygon));
  if (blades.empty()) throw UserError("nothing to cut with: give --plane or --polygon");
  CutOptions options;
  options.removeSide = o.removeSide == "+" ? 1 : (o.removeSide == "-" ? -1 : 0);
  options.sliverFraction = o.sliverFraction;
  options.validation = o.validation;

  PolyMesh input = readVtu(o.input);
  const ValidationReport before = validate(input);
  if (!before.passed)
    throw UserError(
        o.input + ": the mesh is invalid (" +
        (before.messages.empty() ? std::string("see polydg check") : before.messages.front()) +
        "); run 'polydg check' on it");
  MeshEditor editor(std::move(input));
  nlohmann::json report{
      {"command", "cut"},
      {"input", {{"path", o.input}, {"elements", before.elements}, {"volume", before.volume}}}};
  report["operations"] = nlohmann::json::array();
  ProgressBar progress("cutting", quiet || blades.size() < 2);
  std::string failure;
  for (std::size_t i = 0; i < blades.size(); ++i) {
    const OperationReport r = editor.cut(blades[i], options);
    report["operations"].push_back(toJson(r));
    progress.update(double(i + 1) / double(blades.size()));
    if (!r.validation.passed) {
      failure = "operation " + std::to_string(i + 1) + " (" + r.op + ", " + describe(blades[i]) +
                ") failed its " + toString(r.validation.level) +
                " validation: " + r.validation.failure;
      break;
    }
  }
  progress.finish();
  std::size_t components = 0;
  connectedComponents(editor.mesh(), components);
  report["output"] = {{"path", failure.empty() ? o.output : std::string()},
                      {"elements", editor.mesh().numElements()},
                      {"components", components},
                      {"volume", editor.volume()}};
  report["passed"] = failure.empty();
  if (!failure.empty()) report["failure"] = failure;
  if (!o.report.empty()) writeReport(o.report, report);
  if (!failure.empty()) {
    std::cerr << "polydg: error: " << failure << "; nothing written\n";
    exitCode = 1;
    return;
  }
  writeVtu(editor.mesh(), o.output);
  if (!quiet)
    std::cout << o.output << ": " << editor.mesh().numElements() << " elements, " << components
              << " component(s), volume " << editor.volume() << " (input " << before.volume << "), "
              << blades.size() << " operation(s)\n";
  exitCode = 0;
}

}  // namespace

void addCutCommand(CLI::App& app, const CommonOptions& common, int& exitCode) {
  auto o = std::make_shared<CutCommandOptions>();
  CLI::App* cmd = app.add_subcommand(
      "cut",
      "Cut a simulation mesh with planes or a convex polygon, in place, validating each "
      "operation");
  cmd->add_option("mesh", o->input, "simulation mesh (.vtu)")->required()->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", o->output, "output mesh (.vtu)")->required();
  cmd->add_option(
      "--plane", o->planes,
      "the plane {x : n.x = d} as \"nx,ny,nz,d\"; repeat to cut several times, in order");
  cmd->add_option("--polygon", o->polygon,
                  "a convex planar polygon blade \"x1,y1,z1;x2,y2,z2;...\" (after the planes)");
  cmd->add_option("--remove-side", o->removeSide,
                  "delete what lies on this side of each plane: + (n.x > d) or -")
      ->check(CLI::IsMember({"+", "-"}));
  cmd->add_option("--merge-slivers", o->sliverFraction,
                  "merge pieces below this fraction of the median element volume (0: never)")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  const std::map<std::string, ValidationLevel> levels{{"none", ValidationLevel::None},
                                                      {"local", ValidationLevel::Local},
                                                      {"full", ValidationLevel::Full}};
  cmd->add_option("--validate", o->validation, "checks after each operation: none, local, full")
      ->transform(CLI::CheckedTransformer(levels, CLI::ignore_case))
      ->default_str("local");
  cmd->add_option("--report", o->report, "write a JSON report to this file");
  cmd->callback([o, &common, &exitCode] { run(*o, common.quiet, exitCode); });
}

}  // namespace polydg::cli
