// polydg run: a JSON pipeline of steps (mesh, cut, merge, check, solve, write) applied to one
// input or to many, each input in its own output folder with its own report; one failing input
// never stops or spoils the others. The pipeline format is documented in README.md ("Pipelines")
// and checked completely before any input is touched.
//
// Sample runs:
//   polydg run testdata/pipeline.json --out runs/
//   polydg run testdata/pipeline.json --inputs a.obj b.stl c.vtu --jobs 2 --out runs/
//       --report runs/summary.json   (one line)
#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>
#include <thread>
#include <variant>

#include <unistd.h>

#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "cli/json_reports.h"
#include "cli/progress.h"
#include "cli/report.h"
#include "polydg/cut/cut.h"
#include "polydg/mesh/geometry.h"
#include "polydg/mesh/meshing.h"
#include "polydg/mesh/surface_io.h"
#include "polydg/mesh/validate.h"
#include "polydg/mesh/vtu_io.h"
#include "polydg/physics/post_process.h"
#include "polydg/physics/static_solver.h"
#include "polydg/physics/validation.h"

namespace polydg::cli {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

/// Largest number of DOFs for which the check step counts the zero modes of the global
/// stiffness (as `polydg check`: under about 2 s on two cores).
constexpr std::size_t kGlobalRigidModesDofLimit = 25'000;

// --- the pipeline, typed -------------------------------------------------------------------

struct MeshStep {
  std::optional<double> cell;
  int cells = 0;
  RepairMode repair = RepairMode::None;
  double sliverTau = MeshingOptions{}.sliverTau;
};
struct CutStep {
  Blade blade;
  CutOptions options;
};
struct MergeStep {
  double fraction = kDefaultSliverFraction;
};
struct CheckStep {
  int degree = 1;
};
struct PlaneLoad {
  int axis = 0;
  double value = 0.0;
  Vec3 traction = Vec3::Zero();  ///< tractions only
};
struct SolveStep {
  Method method = Method::IP;
  int degree = 1;
  Material material;
  Vec3 gravity = Vec3::Zero();
  std::vector<PlaneLoad> clamps, tractions;
  std::string output;  ///< VTU with the solution, relative to the input's folder; "" for none
};
struct WriteStep {
  std::string path;
};
using Step = std::variant<MeshStep, CutStep, MergeStep, CheckStep, SolveStep, WriteStep>;

struct Pipeline {
  std::vector<std::string> inputs;  ///< resolved against the pipeline file's folder
  std::vector<Step> steps;
};

const char* stepName(const Step& s) {
  static const char* names[] = {"mesh", "cut", "merge", "check", "solve", "write"};
  return names[s.index()];
}

// --- reading and checking the pipeline file ------------------------------------------------

/// Reads one JSON object of the pipeline, naming `path` (e.g. "steps[2]") in every error, and
/// refuses keys it was not asked about.
class ObjectReader {
 public:
  ObjectReader(const json& j, std::string path, std::string file)
      : j_(j), path_(std::move(path)), file_(std::move(file)) {
    if (!j.is_object()) fail(path_, "expected an object");
  }

  [[noreturn]] void fail(const std::string& where, const std::string& what) const {
    throw UserError(file_ + ": " + where + ": " + what + "; see the pipeline format in README.md");
  }
  std::string at(const std::string& key) const { return path_ + "." + key; }
  bool has(const std::string& key) {
    known_.insert(key);
    return j_.contains(key);
  }
  const json& get(const std::string& key) {
    known_.insert(key);
    if (!j_.contains(key)) fail(at(key), "missing");
    return j_.at(key);
  }
  double number(const std::string& key, double lo, double hi) {
    const json& v = get(key);
    if (!v.is_number() || !(v.get<double>() >= lo && v.get<double>() <= hi))
      fail(at(key), "expected a number in [" + fmt(lo) + ", " + fmt(hi) + "]");
    return v.get<double>();
  }
  int integer(const std::string& key, int lo, int hi) {
    const json& v = get(key);
    if (!v.is_number_integer() || v.get<long long>() < lo || v.get<long long>() > hi)
      fail(at(key),
           "expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return v.get<int>();
  }
  std::string string(const std::string& key) {
    const json& v = get(key);
    if (!v.is_string()) fail(at(key), "expected a string");
    return v.get<std::string>();
  }
  template <class T>
  T choice(const std::string& key, const std::map<std::string, T>& options) {
    const std::string s = string(key);
    const auto it = options.find(s);
    if (it == options.end()) {
      std::string names;
      for (const auto& [name, value] : options) names += (names.empty() ? "" : ", ") + name;
      fail(at(key), "'" + s + "' is not one of " + names);
    }
    return it->second;
  }
  /// A list of `n` numbers (n = 0: any length >= 1 is not allowed; use numbers()).
  std::vector<double> numbers(const json& v, const std::string& where, std::size_t n) const {
    if (!v.is_array() || v.size() != n) fail(where, "expected " + std::to_string(n) + " numbers");
    std::vector<double> out;
    for (const json& x : v) {
      if (!x.is_number() || !std::isfinite(x.get<double>()))
        fail(where, "expected " + std::to_string(n) + " finite numbers");
      out.push_back(x.get<double>());
    }
    return out;
  }
  Vec3 vec3(const json& v, const std::string& where) const {
    const auto x = numbers(v, where, 3);
    return {x[0], x[1], x[2]};
  }
  /// Call after reading: any key not asked about is an error.
  void finish() const {
    for (const auto& [key, value] : j_.items())
      if (!known_.count(key)) fail(at(key), "unknown key");
  }

 private:
  static std::string fmt(double x) {
    std::ostringstream s;
    s << x;
    return s.str();
  }
  const json& j_;
  std::string path_, file_;
  std::set<std::string> known_;
};

int parseAxis(ObjectReader& r, const json& v, const std::string& where) {
  static const std::map<std::string, int> axes{{"x", 0}, {"y", 1}, {"z", 2}};
  if (!v.is_string() || !axes.count(v.get<std::string>()))
    r.fail(where, "expected \"x\", \"y\" or \"z\"");
  return axes.at(v.get<std::string>());
}

PlaneLoad parsePlaneLoad(const json& j, const std::string& where, const std::string& file,
                         bool traction) {
  ObjectReader r(j, where, file);
  PlaneLoad p;
  p.axis = parseAxis(r, r.get("axis"), r.at("axis"));
  p.value = r.number("value", -1e300, 1e300);
  if (traction) p.traction = r.vec3(r.get("traction"), r.at("traction"));
  r.finish();
  return p;
}

/// A relative path inside the input's folder, with {stem} the only substitution.
std::string parseOutputPath(ObjectReader& r, const std::string& key) {
  const std::string s = r.string(key);
  const fs::path p(s);
  if (s.empty() || p.is_absolute())
    r.fail(r.at(key), "expected a relative path (inside the input's output folder)");
  for (const fs::path& part : p)
    if (part == "..") r.fail(r.at(key), "'..' would leave the input's output folder");
  if (p.extension() != ".vtu") r.fail(r.at(key), "the output must be a .vtu file");
  std::string rest = s;
  for (std::size_t at = rest.find('{'); at != std::string::npos; at = rest.find('{', at + 1))
    if (rest.compare(at, 6, "{stem}") != 0) r.fail(r.at(key), "the only substitution is {stem}");
  return s;
}

Step parseStep(const json& j, const std::string& where, const std::string& file) {
  ObjectReader r(j, where, file);
  static const std::map<std::string, int> kinds{{"mesh", 0},  {"cut", 1},   {"merge", 2},
                                                {"check", 3}, {"solve", 4}, {"write", 5}};
  const int kind = r.choice("step", kinds);
  Step step;
  switch (kind) {
    case 0: {
      MeshStep s;
      const bool cell = r.has("cell"), cells = r.has("cells");
      if (cell == cells) r.fail(where, "a mesh step needs exactly one of \"cell\" and \"cells\"");
      if (cell) s.cell = r.number("cell", 1e-300, 1e300);
      if (cells) s.cells = r.integer("cells", 1, 4096);
      if (r.has("repair"))
        s.repair = r.choice<RepairMode>(
            "repair",
            {{"none", RepairMode::None}, {"fill", RepairMode::Fill}, {"wrap", RepairMode::Wrap}});
      if (r.has("merge_slivers")) s.sliverTau = r.number("merge_slivers", 0.0, 1.0);
      step = s;
      break;
    }
    case 1: {
      CutStep s;
      const bool plane = r.has("plane"), polygon = r.has("polygon");
      if (plane == polygon)
        r.fail(where, "a cut step needs exactly one of \"plane\" and \"polygon\"");
      try {
        if (plane) {
          const auto v = r.numbers(r.get("plane"), r.at("plane"), 4);
          s.blade = Blade::plane(Vec3(v[0], v[1], v[2]), v[3]);
        } else {
          const json& corners = r.get("polygon");
          if (!corners.is_array()) r.fail(r.at("polygon"), "expected a list of [x, y, z] corners");
          std::vector<Vec3> points;
          for (std::size_t k = 0; k < corners.size(); ++k)
            points.push_back(r.vec3(corners[k], r.at("polygon") + "[" + std::to_string(k) + "]"));
          s.blade = Blade::fromPolygon(std::move(points));
        }
      } catch (const std::invalid_argument& e) {
        r.fail(r.at(plane ? "plane" : "polygon"), e.what());
      }
      if (r.has("remove_side"))
        s.options.removeSide = r.choice<int>("remove_side", {{"+", 1}, {"-", -1}, {"none", 0}});
      if (r.has("validate"))
        s.options.validation =
            r.choice<ValidationLevel>("validate", {{"none", ValidationLevel::None},
                                                   {"local", ValidationLevel::Local},
                                                   {"full", ValidationLevel::Full}});
      if (r.has("sliver_fraction"))
        s.options.sliverFraction = r.number("sliver_fraction", 0.0, 1.0);
      step = s;
      break;
    }
    case 2: {
      MergeStep s;
      if (r.has("fraction")) s.fraction = r.number("fraction", 0.0, 1.0);
      step = s;
      break;
    }
    case 3: {
      CheckStep s;
      if (r.has("degree")) s.degree = r.integer("degree", 1, 3);
      step = s;
      break;
    }
    case 4: {
      SolveStep s;
      if (r.has("method"))
        s.method = r.choice<Method>("method", {{"ip", Method::IP}, {"bz", Method::BZ}});
      if (r.has("degree")) s.degree = r.integer("degree", 1, 3);
      if (r.has("material")) {
        ObjectReader m(r.get("material"), r.at("material"), file);
        if (m.has("E")) s.material.youngsModulus = m.number("E", 1e-300, 1e300);
        if (m.has("nu")) s.material.poissonRatio = m.number("nu", -0.999999, 0.499999999);
        if (m.has("density")) s.material.density = m.number("density", 0.0, 1e300);
        m.finish();
      }
      if (r.has("gravity")) s.gravity = r.vec3(r.get("gravity"), r.at("gravity"));
      for (const char* key : {"clamp", "traction"}) {
        if (!r.has(key)) continue;
        const json& list = r.get(key);
        if (!list.is_array()) r.fail(r.at(key), "expected a list of objects");
        for (std::size_t k = 0; k < list.size(); ++k)
          (key == std::string("clamp") ? s.clamps : s.tractions)
              .push_back(parsePlaneLoad(list[k], r.at(key) + "[" + std::to_string(k) + "]", file,
                                        key != std::string("clamp")));
      }
      if (s.clamps.empty())
        r.fail(r.at("clamp"), "nothing holds the body: give at least one clamp");
      if (r.has("output")) s.output = parseOutputPath(r, "output");
      step = s;
      break;
    }
    default: {
      WriteStep s;
      s.path = parseOutputPath(r, "path");
      step = s;
      break;
    }
  }
  r.finish();
  return step;
}

Pipeline readPipeline(const std::string& file) {
  std::ifstream in(file);
  if (!in) throw UserError(file + ": cannot open the pipeline file");
  json j;
  try {
    j = json::parse(in);
  } catch (const json::parse_error& e) {
    throw UserError(file + ": not valid JSON (" + std::string(e.what()) + ")");
  }
  ObjectReader r(j, "pipeline", file);
  Pipeline p;
  if (r.has("description")) r.string("description");
  if (r.has("inputs")) {
    const json& inputs = r.get("inputs");
    if (!inputs.is_array()) r.fail(r.at("inputs"), "expected a list of file names");
    const fs::path base = fs::path(file).parent_path();
    for (std::size_t k = 0; k < inputs.size(); ++k) {
      if (!inputs[k].is_string() || inputs[k].get<std::string>().empty())
        r.fail(r.at("inputs") + "[" + std::to_string(k) + "]", "expected a file name");
      const fs::path input(inputs[k].get<std::string>());
      p.inputs.push_back((input.is_absolute() ? input : base / input).lexically_normal().string());
    }
  }
  const json& steps = r.get("steps");
  if (!steps.is_array() || steps.empty())
    r.fail(r.at("steps"), "expected a non-empty list of steps");
  for (std::size_t k = 0; k < steps.size(); ++k) {
    p.steps.push_back(parseStep(steps[k], "steps[" + std::to_string(k) + "]", file));
    if (std::holds_alternative<MeshStep>(p.steps.back()) && k != 0)
      r.fail("steps[" + std::to_string(k) + "]", "the mesh step must be the first step");
  }
  r.finish();
  return p;
}

// --- running one input ---------------------------------------------------------------------

/// A step's failure for this input (the others go on).
struct StepFailure : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// The mesh of one input as it goes through the steps: a PolyMesh, and from the first cut or
/// merge on a MeshEditor owning it.
class WorkMesh {
 public:
  WorkMesh(PolyMesh mesh, double referenceVolume)
      : mesh_(std::move(mesh)), referenceVolume_(referenceVolume) {}
  const PolyMesh& mesh() const { return editor_ ? editor_->mesh() : mesh_; }
  MeshEditor& editor() {
    if (!editor_) editor_ = std::make_unique<MeshEditor>(std::move(mesh_), referenceVolume_);
    return *editor_;
  }

 private:
  PolyMesh mesh_;
  std::unique_ptr<MeshEditor> editor_;
  double referenceVolume_;  ///< what sliver fractions multiply
};

double meshVolume(const PolyMesh& mesh) {
  double v = 0.0;
  for (std::size_t e = 0; e < mesh.numElements(); ++e) v += signedVolume(mesh, ElementId(e));
  return v;
}

/// The median element volume: the reference of sliver fractions for a mesh read from a file.
double medianVolume(const PolyMesh& mesh) {
  std::vector<double> v(mesh.numElements());
  for (std::size_t e = 0; e < v.size(); ++e) v[e] = signedVolume(mesh, ElementId(e));
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

std::string substituteStem(const std::string& path, const std::string& stem) {
  std::string out = path;
  for (std::size_t at = out.find("{stem}"); at != std::string::npos;
       at = out.find("{stem}", at + stem.size()))
    out.replace(at, 6, stem);
  return out;
}

/// x with `precision` significant digits.
std::string formatNumber(double x, int precision = 6) {
  std::ostringstream s;
  s << std::setprecision(precision) << x;
  return s.str();
}

/// Runs one input through the steps; every file goes into `folder`.
class InputRun {
 public:
  InputRun(const Pipeline& pipeline, std::string input, std::string stem, fs::path folder)
      : pipeline_(pipeline),
        input_(std::move(input)),
        stem_(std::move(stem)),
        folder_(std::move(folder)) {}

  /// Runs every step; throws on the first failure (the report keeps the steps done so far).
  void run() {
    std::size_t first = 0;
    if (isVolumeMeshPath(input_)) {
      const auto t0 = Clock::now();
      if (!fs::exists(input_)) throw StepFailure(input_ + ": no such file");
      PolyMesh mesh = readVtu(input_);
      const double reference = medianVolume(mesh);
      work_.emplace(std::move(mesh), reference);
      steps_.push_back({{"step", "read"},
                        {"file", input_},
                        {"elements", work_->mesh().numElements()},
                        {"time_s", secondsSince(t0)}});
      log("read " + std::to_string(work_->mesh().numElements()) + " elements");
      if (!pipeline_.steps.empty() && std::holds_alternative<MeshStep>(pipeline_.steps.front()))
        first = 1;  // a simulation mesh needs no meshing
    } else if (pipeline_.steps.empty() ||
               !std::holds_alternative<MeshStep>(pipeline_.steps.front())) {
      throw StepFailure(input_ + ": a surface needs a mesh step first (or give a .vtu mesh)");
    }
    for (std::size_t k = first; k < pipeline_.steps.size(); ++k) {
      const Step& step = pipeline_.steps[k];
      const auto t0 = Clock::now();
      json result{{"step", stepName(step)}, {"index", k}};
      try {
        std::visit([&](const auto& s) { apply(s, result); }, step);
      } catch (const StepFailure& e) {
        result["time_s"] = secondsSince(t0);
        result["error"] = e.what();
        steps_.push_back(result);
        throw StepFailure("step " + std::to_string(k) + " (" + stepName(step) + "): " + e.what());
      } catch (const std::exception& e) {
        result["time_s"] = secondsSince(t0);
        result["error"] = e.what();
        steps_.push_back(result);
        throw StepFailure("step " + std::to_string(k) + " (" + stepName(step) + "): " + e.what());
      } catch (...) {
        result["time_s"] = secondsSince(t0);
        result["error"] = "an unknown error";
        steps_.push_back(result);
        throw StepFailure("step " + std::to_string(k) + " (" + stepName(step) +
                          "): an unknown error");
      }
      result["time_s"] = secondsSince(t0);
      steps_.push_back(result);
    }
  }

  const json& steps() const { return steps_; }
  const std::string& log() const { return log_; }
  std::size_t elements() const { return work_ ? work_->mesh().numElements() : 0; }
  std::optional<double> volume() const {
    if (!work_) return std::nullopt;
    return meshVolume(work_->mesh());
  }

 private:
  void log(const std::string& line) { log_ += "  " + line + "\n"; }
  const PolyMesh& mesh() const { return work_->mesh(); }

  void apply(const MeshStep& s, json& result) {
    const TriangleSurface surface = readSurface(input_);
    MeshingOptions options;
    options.cellSize = s.cell;
    options.cellsAlongLongest = s.cells;
    options.repair = s.repair;
    options.sliverTau = s.sliverTau;
    MeshingResult meshed;
    try {
      meshed = meshSurface(surface, options);
    } catch (const InputError& e) {
      throw StepFailure(input_ + ": " + e.what());
    }
    result.update(toJson(meshed.report));
    if (!meshed.report.validation.passed)
      throw StepFailure("the new mesh is invalid (" +
                        (meshed.report.validation.messages.empty()
                             ? std::string("see the report")
                             : meshed.report.validation.messages.front()) +
                        ")");
    const double cell = meshed.report.grid.cellSize;
    log("meshed: " + std::to_string(meshed.report.elements) + " elements, volume " +
        formatNumber(meshed.report.outputVolume));
    work_.emplace(std::move(meshed.mesh), cell * cell * cell);
  }

  void apply(const CutStep& s, json& result) {
    const OperationReport r = work_->editor().cut(s.blade, s.options);
    result["operations"] = json::array({toJson(r)});
    result["output"] = {{"elements", mesh().numElements()}, {"volume", work_->editor().volume()}};
    if (!r.validation.passed)
      throw StepFailure("the cut failed its validation: " + r.validation.failure);
    log("cut: " + std::to_string(r.elementsSplit) + " elements split, " +
        std::to_string(r.elementsRemoved) + " removed, " + std::to_string(mesh().numElements()) +
        " elements");
  }

  void apply(const MergeStep& s, json& result) {
    const OperationReport r = work_->editor().mergeSlivers(s.fraction);
    result["operations"] = json::array({toJson(r)});
    result["output"] = {{"elements", mesh().numElements()}, {"volume", work_->editor().volume()}};
    if (!r.validation.passed)
      throw StepFailure("merging failed its validation: " + r.validation.failure);
    log("merge: " + std::to_string(r.sliversMerged) + " slivers merged, " +
        std::to_string(mesh().numElements()) + " elements");
  }

  void apply(const CheckStep& s, json& result) {
    const ValidationReport geometry = validate(mesh());
    result["validation"] = toJson(geometry);
    if (!geometry.passed)
      throw StepFailure(
          "the mesh is invalid (" +
          (geometry.messages.empty() ? std::string("see the report") : geometry.messages.front()) +
          ")");
    auto t0 = Clock::now();
    LocalDgCheckOptions local;
    local.basis.degree = s.degree;
    MomentCache moments(mesh(), 2 * s.degree);
    moments.update();
    const LocalDgCheck dg = localDgChecks(mesh(), moments, local);
    result["validation"].update(toJson(dg, secondsSince(t0)));
    const std::size_t dofs = mesh().numElements() * 3 * numMonomials(s.degree);
    bool rigidPassed = true;
    if (dofs <= kGlobalRigidModesDofLimit) {
      t0 = Clock::now();
      PhysicsCheckOptions global;
      global.basis.degree = s.degree;
      const ZeroModeReport modes = rigidModes(mesh(), global);
      result["validation"]["rigid_modes_global"] = modes.zeroModes;
      result["validation"]["rigid_modes_per_component"] = modes.zeroModesPerComponent;
      result["validation"]["rigid_modes_seconds"] = secondsSince(t0);
      for (std::size_t m : modes.zeroModesPerComponent) rigidPassed = rigidPassed && m == 6;
    } else {
      result["validation"]["rigid_modes_global"] = nullptr;
    }
    result["validation"]["rigid_modes_expected"] = 6 * geometry.components;
    const bool passed = dg.passed() && rigidPassed;
    result["validation"]["passed"] = passed;
    if (!passed) {
      const auto messages = failureMessages(dg);
      throw StepFailure(messages.empty()
                            ? "the global stiffness does not have 6 zero modes per component"
                            : messages.front());
    }
    log("check: valid, " + std::to_string(geometry.components) +
        " component(s), patch test error " + formatNumber(dg.maxPatchTestError, 3));
  }

  void apply(const SolveStep& s, json& result) {
    LoadCase loads;
    for (const PlaneLoad& c : s.clamps)
      loads.dirichlet.push_back({FaceSelector::plane(c.axis, c.value), {}});
    for (const PlaneLoad& t : s.tractions)
      loads.tractions.push_back({FaceSelector::plane(t.axis, t.value), t.traction});
    loads.gravity = s.gravity;
    s.material.check();
    StaticOptions so;
    so.discretization.method = s.method;
    so.discretization.basis.degree = s.degree;
    StaticSolver solver(mesh(), s.material, so);
    solver.integrate();
    solver.assemble(loads);
    if (solver.report().dirichletFaces == 0)
      throw StepFailure("no boundary face lies in a clamp plane");
    const Eigen::VectorXd& u = solver.solve();
    const StaticReport& r = solver.report();
    if (!r.solver.success) throw StepFailure("the linear solver failed (is every piece clamped?)");
    const CornerValues corners = cornerDisplacements(mesh(), solver.basis(), u);
    const double maxDisplacement = corners.largestNorm();
    result.update({{"method", toString(s.method)},
                   {"degree", s.degree},
                   {"dofs", r.dofs},
                   {"nonzeros", r.nonzeros},
                   {"eta", r.eta},
                   {"dirichlet_faces", r.dirichletFaces},
                   {"traction_faces", r.tractionFaces},
                   {"residual", r.solver.residual},
                   {"energy", r.energy},
                   {"max_displacement", maxDisplacement},
                   {"timings_s",
                    {{"integrate", r.integrateSeconds},
                     {"assemble", r.assembleSeconds},
                     {"solve", r.solveSeconds}}}});
    if (!s.output.empty()) {
      const ElementFields fields =
          elementFields(mesh(), solver.basis(), solver.moments(), u, s.material);
      const std::string file = (folder_ / substituteStem(s.output, stem_)).string();
      fs::create_directories(fs::path(file).parent_path());
      CellArray vonMises{"von_mises", 1, fields.vonMises.raw()};
      writeVtu(mesh(), file, {}, {vonMises}, {}, {displacementPointData(corners)});
      result["output"] = substituteStem(s.output, stem_);
    }
    log("solve: " + std::to_string(r.dofs) + " DOFs, max |u| " + formatNumber(maxDisplacement));
  }

  void apply(const WriteStep& s, json& result) {
    const std::string relative = substituteStem(s.path, stem_);
    const fs::path file = folder_ / relative;
    fs::create_directories(file.parent_path());
    writeVtu(mesh(), file.string());
    result["path"] = relative;
    result["elements"] = mesh().numElements();
    log("wrote " + relative);
  }

  const Pipeline& pipeline_;
  std::string input_, stem_;
  fs::path folder_;
  std::optional<WorkMesh> work_;
  json steps_ = json::array();
  std::string log_;
};

// --- many inputs ---------------------------------------------------------------------------

struct RunOptions {
  std::string pipeline;
  std::vector<std::string> inputs;
  int jobs = 1;
  std::string out;
  std::string report;
};

struct InputOutcome {
  std::string input, stem;
  bool passed = false;
  std::size_t elements = 0;
  std::optional<double> volume;
  double seconds = 0.0;
  std::string error;
  json report;
  std::string log;
};

/// Output folder names: the inputs' stems, made unique with _2, _3, ... in input order.
std::vector<std::string> uniqueStems(const std::vector<std::string>& inputs) {
  std::vector<std::string> stems;
  std::set<std::string> used;
  for (const std::string& input : inputs) {
    std::string stem = fs::path(input).stem().string();
    if (stem.empty()) stem = "input";
    std::string name = stem;
    for (int k = 2; used.count(name); ++k) name = stem + "_" + std::to_string(k);
    used.insert(name);
    stems.push_back(name);
  }
  return stems;
}

/// Runs one input in a staging folder beside its final folder and moves it into place at the
/// end: a success leaves all its outputs, a failure only its report.
InputOutcome runInput(const Pipeline& pipeline, const std::string& input, const std::string& stem,
                      const fs::path& out) {
  const auto t0 = Clock::now();
  InputOutcome o;
  o.input = input;
  o.stem = stem;
  const fs::path staging = out / ("." + stem + ".partial-" + std::to_string(::getpid()));
  const fs::path final = out / stem;
  std::error_code ec;
  fs::remove_all(staging, ec);
  fs::create_directories(staging);
  InputRun run(pipeline, input, stem, staging);
  try {
    run.run();
    o.passed = true;
  } catch (const std::exception& e) {
    o.error = e.what();
  } catch (...) {
    o.error = "an unknown error";
  }
  o.elements = run.elements();
  try {
    o.volume = run.volume();
  } catch (const std::exception&) {
  }
  o.seconds = secondsSince(t0);
  o.log = run.log();
  o.report = {{"input", input},
              {"stem", stem},
              {"status", o.passed ? "ok" : "failed"},
              {"error", o.passed ? json(nullptr) : json(o.error)},
              {"elements", o.elements},
              {"volume", o.volume ? json(*o.volume) : json(nullptr)},
              {"time_s", o.seconds},
              {"steps", run.steps()}};
  if (!o.passed) {  // nothing half-written: drop every output, keep the report
    fs::remove_all(staging, ec);
    fs::create_directories(staging);
  }
  writeReport(staging / "report.json", o.report);
  fs::remove_all(final, ec);
  fs::rename(staging, final, ec);
  if (ec)
    throw UserError("cannot move " + staging.string() + " to " + final.string() + ": " +
                    ec.message());
  return o;
}

void printSummary(const std::vector<InputOutcome>& outcomes, std::ostream& out) {
  std::size_t width = 5;
  for (const InputOutcome& o : outcomes) width = std::max(width, o.input.size());
  out << std::left << std::setw(static_cast<int>(width)) << "input"
      << "  " << std::setw(6) << "status" << std::right << std::setw(10) << "elements"
      << std::setw(14) << "volume" << std::setw(10) << "time_s"
      << "  first error\n";
  for (const InputOutcome& o : outcomes) {
    out << std::left << std::setw(static_cast<int>(width)) << o.input << "  " << std::setw(6)
        << (o.passed ? "ok" : "FAILED") << std::right << std::setw(10)
        << (o.elements ? std::to_string(o.elements) : std::string("-")) << std::setw(14)
        << (o.volume && o.elements ? formatNumber(*o.volume, 8) : std::string("-")) << std::setw(10)
        << formatNumber(o.seconds, 3) << "  " << (o.passed ? "" : o.error) << '\n';
  }
}

/// True if `path` is `folder` or lies inside it (after resolving both).
bool isWithin(const fs::path& path, const fs::path& folder) {
  const fs::path p = fs::weakly_canonical(fs::absolute(path));
  const fs::path f = fs::weakly_canonical(fs::absolute(folder));
  const auto [fEnd, pAt] = std::mismatch(f.begin(), f.end(), p.begin(), p.end());
  return fEnd == f.end();
}

/// Each input's folder is replaced at the end of its run: no input may lie in one.
void refuseInputsInOutputs(const std::vector<std::string>& inputs,
                           const std::vector<std::string>& stems, const fs::path& out) {
  for (const std::string& input : inputs)
    for (const std::string& stem : stems)
      if (isWithin(input, out / stem))
        throw UserError("the input " + input + " lies in the output folder " +
                        (out / stem).string() + ", which the run replaces; choose another --out");
}

void runPipeline(const RunOptions& o, const CommonOptions& common, int& exitCode) {
  Pipeline pipeline = readPipeline(o.pipeline);
  if (!o.inputs.empty()) pipeline.inputs = o.inputs;
  if (pipeline.inputs.empty())
    throw UserError(o.pipeline + ": no inputs; list them under \"inputs\" or give --inputs");
  const fs::path out =
      o.out.empty() ? fs::path(fs::path(o.pipeline).stem().string() + "-out") : fs::path(o.out);
  const std::vector<std::string> stems = uniqueStems(pipeline.inputs);
  refuseInputsInOutputs(pipeline.inputs, stems, out);
  std::error_code ec;
  fs::create_directories(out, ec);
  if (ec) throw UserError("cannot create " + out.string() + ": " + ec.message());

  const std::size_t n = pipeline.inputs.size();
  std::vector<InputOutcome> outcomes(n);
  std::atomic<std::size_t> next{0};
  std::size_t done = 0;
  std::mutex printing;
  ProgressBar bar("run", common.quiet);
  const auto worker = [&] {
    for (std::size_t i = next++; i < n; i = next++) {
      InputOutcome outcome;
      try {
        outcome = runInput(pipeline, pipeline.inputs[i], stems[i], out);
      } catch (const std::exception& e) {  // the folder could not be written
        outcome.input = pipeline.inputs[i];
        outcome.stem = stems[i];
        outcome.error = e.what();
      }
      const std::lock_guard lock(printing);
      bar.finish();  // clear the bar's line before the input's lines; redrawn below
      if (!common.quiet) {
        std::cout << outcome.input << ": " << (outcome.passed ? "ok" : "FAILED") << " -> "
                  << (out / stems[i]).string() << '\n'
                  << outcome.log;
        if (!outcome.passed) std::cout << "  error: " << outcome.error << '\n';
        std::cout << std::flush;
      }
      outcomes[i] = std::move(outcome);
      bar.update(static_cast<double>(++done) / static_cast<double>(n));
    }
  };
  const int jobs = std::max(1, std::min<int>(o.jobs, static_cast<int>(n)));
  std::vector<std::thread> threads;
  for (int t = 1; t < jobs; ++t) threads.emplace_back(worker);
  worker();
  for (std::thread& t : threads) t.join();
  bar.finish();

  std::size_t failed = 0;
  json inputs = json::array();
  for (const InputOutcome& outcome : outcomes) {
    failed += !outcome.passed;
    inputs.push_back(
        outcome.report.is_null()
            ? json{{"input", outcome.input}, {"status", "failed"}, {"error", outcome.error}}
            : outcome.report);
  }
  if (!o.report.empty())
    writeReport(o.report, {{"command", "run"},
                           {"pipeline", o.pipeline},
                           {"out", out.string()},
                           {"inputs", inputs},
                           {"failed", failed},
                           {"passed", failed == 0}});
  if (!common.quiet) {
    std::cout << '\n';
    printSummary(outcomes, std::cout);
  } else {
    for (const InputOutcome& outcome : outcomes)
      if (!outcome.passed)
        std::cerr << "polydg: " << outcome.input << ": " << outcome.error << '\n';
  }
  exitCode = failed == 0 ? 0 : 1;
}

}  // namespace

void addRunCommand(CLI::App& app, const CommonOptions& common, int& exitCode) {
  auto o = std::make_shared<RunOptions>();
  CLI::App* cmd = app.add_subcommand(
      "run", "Run a JSON pipeline of steps (mesh, cut, merge, check, solve, write) on inputs");
  cmd->add_option("pipeline", o->pipeline, "pipeline file (.json; format in README.md)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--inputs", o->inputs, "inputs instead of the pipeline's (surfaces or .vtu)");
  cmd->add_option("--jobs", o->jobs, "inputs run at the same time")
      ->check(CLI::Range(1, 256))
      ->capture_default_str();
  cmd->add_option("--out", o->out,
                  "output folder: one subfolder per input (default: PIPELINE-out)");
  cmd->add_option("--report", o->report, "write every input's report and the summary as JSON");
  cmd->callback([o, &common, &exitCode] { runPipeline(*o, common, exitCode); });
}

}  // namespace polydg::cli
