#include "polydg/model/pipeline.h"

#include <algorithm>
#include <atomic>
#include <iomanip>
#include <mutex>
#include <set>
#include <sstream>
#include <thread>

#include <unistd.h>

#include "model/files.h"
#include "model/json_reader.h"
#include "polydg/mesh/surface_io.h"
#include "polydg/model/report_json.h"
#include "util/format.h"
#include "util/stopwatch.h"

namespace polydg {

namespace fs = std::filesystem;
using nlohmann::json;

const char* stepName(const PipelineStep& step) {
  static const char* names[] = {"mesh", "cut", "merge", "check", "solve", "write", "export"};
  return names[step.index()];
}

int Pipeline::momentDegree() const {
  int degree = 0;
  for (const PipelineStep& step : steps) {
    int need = 0;
    if (const auto* s = std::get_if<MeshStep>(&step)) need = s->options.dgChecks ? 2 : 0;
    if (const auto* s = std::get_if<CutStep>(&step)) need = 2 * s->request.checkDegree;
    if (const auto* s = std::get_if<MergeStep>(&step)) need = 2 * s->request.checkDegree;
    if (const auto* s = std::get_if<CheckStep>(&step)) need = 2 * s->options.degree();
    if (const auto* s = std::get_if<SolveStep>(&step))
      need = 2 * s->options.discretization.basis.degree;
    degree = std::max(degree, need);
  }
  return degree;
}

// --- reading -------------------------------------------------------------------------------

CutRequest readCutRequest(JsonObjectReader& r) {
  CutStep s;
  const bool plane = r.has("plane"), polygon = r.has("polygon");
  if (plane == polygon) r.fail(r.place(), "a cut needs exactly one of \"plane\" and \"polygon\"");
  try {
    if (plane) {
      const auto v = r.numbers(r.get("plane"), r.at("plane"), 4);
      s.request.blade = Blade::plane(Vec3(v[0], v[1], v[2]), v[3]);
    } else {
      const json& corners = r.list("polygon", "expected a list of [x, y, z] corners");
      std::vector<Vec3> points;
      for (std::size_t k = 0; k < corners.size(); ++k)
        points.push_back(r.vec3(corners[k], r.at("polygon") + "[" + std::to_string(k) + "]"));
      s.request.blade = Blade::fromPolygon(std::move(points));
    }
  } catch (const std::invalid_argument& e) {
    r.fail(r.at(plane ? "plane" : "polygon"), e.what());
  }
  if (r.has("remove_side")) s.request.removeSide = r.choice("remove_side", removeSideNames());
  if (r.has("validate")) s.request.checks = r.choice("validate", checkLevelNames());
  if (r.has("sliver_fraction")) s.request.sliverFraction = r.number("sliver_fraction", 0.0, 1.0);
  return s.request;
}

Material readMaterial(JsonObjectReader& r, Material material) {
  JsonObjectReader m = r.object("material");
  if (m.has("E")) material.youngsModulus = m.number("E");
  if (m.has("nu")) material.poissonRatio = m.number("nu");
  if (m.has("density")) material.density = m.number("density");
  m.finish();
  m.checked([&] { material.check(); });
  return material;
}

void readMethod(JsonObjectReader& r, Method& dg, std::optional<TetMethod>& tets) {
  if (r.has("method")) {
    const std::string name = r.string("method");
    if (const auto tet = parseName(tetMethodNames(), name)) {
      tets = tet;
    } else if (const auto method = parseName(methodNames(), name)) {
      dg = *method;
    } else {
      r.fail(r.at("method"), "'" + name + "' is not one of " + listNames(methodNames()) + ", " +
                                 listNames(tetMethodNames()));
    }
  }
  if (tets)
    for (const char* key : {"degree", "bz_penalty"})
      if (r.has(key))
        r.fail(r.at(key), std::string("is an option of the DG methods (ip, bz), not of ") +
                              toString(*tets) + "; leave it out");
}

namespace {

constexpr const char* kHint = "see the pipeline format in docs/guide.md";

/// A relative path inside the input's folder, ending in .vtu unless `folder`, with {stem} the
/// only substitution.
std::string outputPath(JsonObjectReader& r, const std::string& key, bool folder = false) {
  const std::string s = r.string(key);
  const fs::path p(s);
  if (s.empty() || p.is_absolute())
    r.fail(r.at(key), "expected a relative path (inside the input's output folder)");
  for (const fs::path& part : p)
    if (part == "..") r.fail(r.at(key), "'..' would leave the input's output folder");
  if (!folder && p.extension() != ".vtu") r.fail(r.at(key), "the output must be a .vtu file");
  for (std::size_t at = s.find('{'); at != std::string::npos; at = s.find('{', at + 1))
    if (s.compare(at, 6, "{stem}") != 0) r.fail(r.at(key), "the only substitution is {stem}");
  return s;
}

MeshStep meshStep(JsonObjectReader& r) {
  MeshStep s;
  const bool cell = r.has("cell"), cells = r.has("cells");
  if (cell == cells) r.fail(r.place(), "a mesh step needs exactly one of \"cell\" and \"cells\"");
  if (cell) s.options.cellSize = r.number("cell", 1e-300, 1e300);
  if (cells) s.options.cells = r.integer("cells", 1, 4096);
  if (r.has("repair")) s.options.repair = r.choice("repair", repairNames());
  if (r.has("merge_slivers")) s.options.sliverFraction = r.number("merge_slivers", 0.0, 1.0);
  if (r.has("dg_checks")) s.options.dgChecks = r.boolean("dg_checks");
  if (r.has("adaptive")) s.options.adaptive = r.boolean("adaptive");
  return s;
}

CutStep cutStep(JsonObjectReader& r) { return {readCutRequest(r)}; }

MergeStep mergeStep(JsonObjectReader& r) {
  MergeStep s;
  if (r.has("fraction")) s.request.fraction = r.number("fraction", 0.0, 1.0);
  if (r.has("validate")) s.request.checks = r.choice("validate", checkLevelNames());
  return s;
}

CheckStep checkStep(JsonObjectReader& r) {
  CheckStep s;
  if (r.has("degree")) s.options.physics.discretization.basis.degree = r.integer("degree");
  r.checked([&] { s.options.physics.discretization.check(); });
  return s;
}

/// The "adapt" key of a solve: true (the defaults), false, or an object of "by" ("error",
/// "stress"), "split" ("octants", "halves"), "target_error", "max_dofs", "max_rounds", "bulk",
/// "stress_fraction", "max_level".
std::optional<AdaptOptions> adaptOptions(JsonObjectReader& r) {
  const json& value = r.get("adapt");
  if (value.is_boolean()) return value.get<bool>() ? std::optional(AdaptOptions{}) : std::nullopt;
  JsonObjectReader o = r.object("adapt");
  AdaptOptions a;
  if (o.has("by")) a.criterion = o.choice("by", adaptCriterionNames());
  if (o.has("split")) a.split = o.choice("split", refineSplitNames());
  if (o.has("target_error")) a.targetError = o.number("target_error", 1e-300, 1e300);
  if (o.has("max_dofs")) a.maxDofs = static_cast<std::size_t>(o.number("max_dofs", 1.0, 1e15));
  if (o.has("max_rounds")) a.maxRounds = o.integer("max_rounds", 0, 20);
  if (o.has("bulk")) a.bulk = o.number("bulk", 1e-6, 1.0);
  if (o.has("stress_fraction")) a.stressFraction = o.number("stress_fraction", 1e-6, 1.0);
  if (o.has("max_level")) a.maxLevel = o.integer("max_level", 1, 8);
  o.finish();
  return a;
}

SolveStep solveStep(JsonObjectReader& r) {
  SolveStep s;
  SolveOptions& o = s.options;
  DiscretizationOptions& d = o.discretization;
  readMethod(r, d.method, o.tetMethod);
  if (r.has("bz_penalty")) d.bzPenalty = r.choice("bz_penalty", bzPenaltyNames());
  if (r.has("degree")) d.basis.degree = r.integer("degree");
  if (r.has("material")) o.material = readMaterial(r, o.material);
  if (r.has("gravity")) o.gravity = r.vec3(r.get("gravity"), r.at("gravity"));
  for (const char* key : {"clamp", "traction"}) {
    if (!r.has(key)) continue;
    const json& list = r.list(key, "expected a list of objects");
    for (std::size_t k = 0; k < list.size(); ++k) {
      JsonObjectReader item = r.element(list, r.at(key), k);
      const FaceSelector where = item.selection();
      if (std::string(key) == "clamp") {
        o.clamps.push_back(where);
      } else {
        o.tractions.push_back({where, item.vec3(item.get("traction"), item.at("traction"))});
      }
      item.finish();
    }
  }
  if (r.has("solver")) o.solver = r.choice("solver", solverNames());
  if (r.has("penalty")) d.penalty.rule = r.choice("penalty", penaltyNames());
  if (r.has("eta")) d.penalty.eta = r.number("eta");
  if (r.has("adapt")) o.adapt = adaptOptions(r);
  if (r.has("estimate")) o.estimate = r.boolean("estimate");
  if (r.has("output")) s.output = outputPath(r, "output");
  r.checked([&] { o.check(); });
  return s;
}

/// {"step": "export", "path": "{stem}_case", "format": "openfoam", "binary": false,
///  "patches": [{"name": "inlet", "x": 0}, ...]} (each patch a name and region keys).
ExportStep exportStep(JsonObjectReader& r) {
  ExportStep s;
  s.path = outputPath(r, "path", true);
  if (r.has("format")) r.choice("format", Names<int>{{"openfoam", 0}});
  if (r.has("binary")) s.options.binary = r.boolean("binary");
  if (r.has("patches")) {
    const json& list = r.list("patches", "expected a list of patches, each a name and a region");
    for (std::size_t k = 0; k < list.size(); ++k) {
      JsonObjectReader item = r.element(list, r.at("patches"), k);
      const std::string name = item.string("name");
      s.options.patches.push_back({name, item.selection()});
      item.finish();
    }
  }
  return s;
}

PipelineStep parseStep(JsonObjectReader& r) {
  static const Names<int> kinds{{"mesh", 0},  {"cut", 1},   {"merge", 2}, {"check", 3},
                                {"solve", 4}, {"write", 5}, {"export", 6}};
  switch (r.choice("step", kinds)) {
    case 0: return meshStep(r);
    case 1: return cutStep(r);
    case 2: return mergeStep(r);
    case 3: return checkStep(r);
    case 4: return solveStep(r);
    case 6: return exportStep(r);
    default: return WriteStep{outputPath(r, "path")};
  }
}

}  // namespace

Pipeline parsePipeline(const json& document, const std::string& file, const fs::path& base) {
  JsonObjectReader r(document, "pipeline", file, kHint);
  Pipeline p;
  p.file = file;
  if (r.has("description")) p.description = r.string("description");
  if (r.has("inputs")) {
    const json& inputs = r.list("inputs", "expected a list of file names");
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
    JsonObjectReader step = r.element(steps, "steps", k);
    p.steps.push_back(parseStep(step));
    step.finish();
    if (std::holds_alternative<MeshStep>(p.steps.back()) && k != 0)
      r.fail(step.place(), "the mesh step must be the first step");
  }
  r.finish();
  return p;
}

PipelineStep parsePipelineStep(const json& step, const std::string& caller,
                               const std::string& hint) {
  if (!step.is_object()) throw InputError(caller + ": expected an object of step keys");
  JsonObjectReader r(step, "", caller, hint);
  PipelineStep out = parseStep(r);
  r.finish();
  return out;
}

Pipeline readPipeline(const std::string& file) {
  return parsePipeline(readJsonDocument(file, "pipeline"), file, fs::path(file).parent_path());
}

// --- running one input ---------------------------------------------------------------------

namespace {

/// A step's failure for this input (the others go on).
struct StepFailure : Error {
  using Error::Error;
};

std::string substituteStem(const std::string& path, const std::string& stem) {
  std::string out = path;
  for (std::size_t at = out.find("{stem}"); at != std::string::npos;
       at = out.find("{stem}", at + stem.size()))
    out.replace(at, 6, stem);
  return out;
}

bool isVolumeMesh(const std::string& path) {
  const std::string ext = fs::path(path).extension().string();
  return ext == ".vtu" || ext == ".VTU";
}

/// Runs one input through the steps; every file goes into `folder`.
class InputRun {
 public:
  InputRun(const Pipeline& pipeline, std::string input, std::string stem, fs::path folder)
      : pipeline_(pipeline),
        input_(std::move(input)),
        stem_(std::move(stem)),
        folder_(std::move(folder)),
        degree_(pipeline.momentDegree()) {}

  /// Runs every step; throws on the first failure (the report keeps the steps done so far).
  void run() {
    std::size_t first = 0;
    const bool meshFirst =
        !pipeline_.steps.empty() && std::holds_alternative<MeshStep>(pipeline_.steps.front());
    if (isVolumeMesh(input_)) {
      const Stopwatch watch;
      if (!fs::exists(input_)) throw StepFailure(input_ + ": no such file");
      ReadReport read;
      model_.emplace(Model::read(input_, &read));
      // Every integral the steps need, once (meshed inputs get it from the mesh step).
      if (degree_ > 0) model_->moments(degree_);
      json step = toJson(read);
      step["step"] = "read";
      step["faces_integrated"] = model_->facesIntegrated();
      step["time_s"] = watch.seconds();
      steps_.push_back(step);
      log("read " + std::to_string(model_->mesh().numElements()) + " elements");
      if (meshFirst) first = 1;  // a simulation mesh needs no meshing
    } else if (!meshFirst) {
      throw StepFailure(input_ + ": a surface needs a mesh step first (or give a .vtu mesh)");
    }
    for (std::size_t k = first; k < pipeline_.steps.size(); ++k) {
      const PipelineStep& step = pipeline_.steps[k];
      const Stopwatch watch;
      json result{{"step", stepName(step)}, {"index", k}};
      std::string error;
      try {
        std::visit([&](const auto& s) { apply(s, result); }, step);
      } catch (const std::exception& e) {
        error = e.what();
      } catch (...) {
        error = "an unknown error";
      }
      result["time_s"] = watch.seconds();
      if (!error.empty()) result["error"] = error;
      steps_.push_back(result);
      if (!error.empty())
        throw StepFailure("step " + std::to_string(k) + " (" + stepName(step) + "): " + error);
    }
  }

  const json& steps() const { return steps_; }
  const std::string& log() const { return log_; }
  const Model* model() const { return model_ ? &*model_ : nullptr; }

 private:
  void log(const std::string& line) { log_ += "  " + line + "\n"; }
  Model& current() { return *model_; }

  void apply(const MeshStep& s, json& result) {
    const Stopwatch read;
    SurfaceReadInfo info;
    const TriangleSurface surface = readSurface(input_, &info);
    MeshOptions options = s.options;
    options.momentDegree = std::max(degree_, 2);
    MeshReport report;
    report.readSeconds = read.seconds();
    try {
      model_.emplace(Model::fromSurface(surface, options, report, input_));
    } catch (const InputError& e) {
      throw StepFailure(input_ + ": " + e.what());
    }
    result.update(toJson(report));
    result["input"]["warnings"] = info.warnings;
    for (const std::string& w : info.warnings) log("warning: " + w);
    result["faces_integrated"] = model_->facesIntegrated();
    if (!report.passed()) {
      const auto failures = report.failures();
      throw StepFailure("the new mesh failed its checks (" +
                        (failures.empty() ? std::string("see the report") : failures.front()) +
                        ")");
    }
    log("meshed: " + std::to_string(report.meshing.elements) + " elements, volume " +
        formatNumber(report.meshing.outputVolume));
  }

  void apply(const CutStep& s, json& result) { edit(current().cut(s.request), "cut", result); }

  void apply(const MergeStep& s, json& result) {
    edit(current().mergeSlivers(s.request), "merge", result);
  }

  void edit(const OperationReport& r, const char* what, json& result) {
    result["operations"] = json::array({toJson(r)});
    result["output"] = {{"elements", current().mesh().numElements()},
                        {"volume", current().volume()}};
    if (!r.check.passed)
      throw StepFailure(std::string("the ") + what + " failed its validation: " + r.check.failure);
    log(std::string(what) + ": " + std::to_string(r.elementsSplit) + " elements split, " +
        std::to_string(r.elementsRemoved) + " removed, " + std::to_string(r.sliversMerged) +
        " slivers merged, " + std::to_string(current().mesh().numElements()) + " elements");
  }

  void apply(const CheckStep& s, json& result) {
    const MeshCheck c = current().check(s.options);
    result["validation"] = toJson(c);
    if (!c.passed()) {
      const auto failures = c.failures();
      throw StepFailure(failures.empty() ? "a check failed" : failures.front());
    }
    log("check: valid, " + std::to_string(c.geometry ? c.geometry->components : 0) +
        " component(s), patch test error " +
        formatNumber(c.local ? c.local->maxPatchTestError : 0.0, 3));
  }

  void apply(const SolveStep& s, json& result) {
    const SolveReport r = current().solve(s.options);
    result.update(toJson(r));
    if (!s.output.empty()) {
      const std::string relative = substituteStem(s.output, stem_);
      const fs::path file = folder_ / relative;
      fs::create_directories(file.parent_path());
      current().write(file.string());
      result["output"] = relative;
    }
    log("solve: " + std::to_string(r.solve.dofs) + " DOFs, max |u| " +
        formatNumber(r.maxDisplacement));
  }

  void apply(const WriteStep& s, json& result) {
    const std::string relative = substituteStem(s.path, stem_);
    const fs::path file = folder_ / relative;
    fs::create_directories(file.parent_path());
    WriteOptions options;
    options.solution = false;  // the mesh only: a solution goes with a solve step's output
    current().write(file.string(), options);
    result["path"] = relative;
    result["elements"] = current().mesh().numElements();
    log("wrote " + relative);
  }

  void apply(const ExportStep& s, json& result) {
    const std::string relative = substituteStem(s.path, stem_);
    const fs::path folder = folder_ / relative;
    if (folder.has_parent_path()) fs::create_directories(folder.parent_path());
    const ExportReport r = current().exportOpenFoam(folder.string(), s.options);
    result.update(toJson(r));
    result["folder"] = relative;
    log("export: " + relative + ", " + std::to_string(r.foam.cells) + " cells, checkMesh " +
        (r.foam.quality.failedChecks().empty() ? "OK" : "would fail"));
  }

  const Pipeline& pipeline_;
  std::string input_, stem_;
  fs::path folder_;
  int degree_;
  std::optional<Model> model_;
  json steps_ = json::array();
  std::string log_;
};

}  // namespace

InputOutcome runPipelineInput(const Pipeline& pipeline, const std::string& input,
                              const std::string& stem, const fs::path& out) {
  const Stopwatch watch;
  InputOutcome o;
  o.input = input;
  o.stem = stem;
  const fs::path staging = out / ("." + stem + ".partial-" + std::to_string(::getpid()));
  const fs::path final = out / stem;
  std::error_code ec;
  fs::remove_all(staging, ec);
  fs::create_directories(staging, ec);
  if (ec) throw InputError("cannot create " + staging.string() + ": " + ec.message());
  InputRun run(pipeline, input, stem, staging);
  try {
    run.run();
    o.passed = true;
  } catch (const std::exception& e) {
    o.error = e.what();
  } catch (...) {
    o.error = "an unknown error";
  }
  if (const Model* model = run.model()) {
    o.elements = model->mesh().numElements();
    o.facesIntegrated = model->facesIntegrated();
    try {
      o.volume = model->volume();
    } catch (const std::exception&) {
    }
  }
  o.seconds = watch.seconds();
  o.log = run.log();
  o.report = {{"input", input},
              {"stem", stem},
              {"status", o.passed ? "ok" : "failed"},
              {"error", o.passed ? json(nullptr) : json(o.error)},
              {"elements", o.elements},
              {"volume", o.volume ? json(*o.volume) : json(nullptr)},
              {"faces_integrated", o.facesIntegrated},
              {"time_s", o.seconds},
              {"steps", run.steps()}};
  if (!o.passed) {  // nothing half-written: drop every output, keep the report
    fs::remove_all(staging, ec);
    fs::create_directories(staging, ec);
  }
  writeJsonFile(staging / "report.json", o.report);
  fs::remove_all(final, ec);
  fs::rename(staging, final, ec);
  if (ec)
    throw InputError("cannot move " + staging.string() + " to " + final.string() + ": " +
                     ec.message());
  return o;
}

// --- many inputs ---------------------------------------------------------------------------

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

namespace {
/// True if `path` is `folder` or lies inside it (after resolving both).
bool isWithin(const fs::path& path, const fs::path& folder) {
  const fs::path p = fs::weakly_canonical(fs::absolute(path));
  const fs::path f = fs::weakly_canonical(fs::absolute(folder));
  const auto [fEnd, pAt] = std::mismatch(f.begin(), f.end(), p.begin(), p.end());
  return fEnd == f.end();
}
}  // namespace

void refuseInputsInOutputs(const std::vector<std::string>& inputs,
                           const std::vector<std::string>& stems, const fs::path& out) {
  for (const std::string& input : inputs)
    for (const std::string& stem : stems)
      if (isWithin(input, out / stem))
        throw InputError("the input " + input + " lies in the output folder " +
                         (out / stem).string() + ", which the run replaces; choose another --out");
}

std::vector<InputOutcome> runBatch(const Pipeline& pipeline, const BatchOptions& options) {
  if (pipeline.inputs.empty())
    throw InputError(pipeline.file + ": no inputs; list them under \"inputs\" or give --inputs");
  const std::vector<std::string> stems = uniqueStems(pipeline.inputs);
  refuseInputsInOutputs(pipeline.inputs, stems, options.out);
  std::error_code ec;
  fs::create_directories(options.out, ec);
  if (ec) throw InputError("cannot create " + options.out.string() + ": " + ec.message());

  const std::size_t n = pipeline.inputs.size();
  std::vector<InputOutcome> outcomes(n);
  std::atomic<std::size_t> next{0};
  std::mutex done;
  const auto worker = [&] {
    for (std::size_t i = next++; i < n; i = next++) {
      InputOutcome outcome;
      try {
        outcome = runPipelineInput(pipeline, pipeline.inputs[i], stems[i], options.out);
      } catch (const std::exception& e) {  // the folder could not be written
        outcome.input = pipeline.inputs[i];
        outcome.stem = stems[i];
        outcome.error = e.what();
        outcome.report = {{"input", outcome.input}, {"status", "failed"}, {"error", outcome.error}};
      }
      const std::lock_guard lock(done);
      outcomes[i] = std::move(outcome);
      if (options.onDone) options.onDone(i, outcomes[i]);
    }
  };
  const int jobs = std::max(1, std::min<int>(options.jobs, static_cast<int>(n)));
  std::vector<std::thread> threads;
  for (int t = 1; t < jobs; ++t) threads.emplace_back(worker);
  worker();
  for (std::thread& t : threads) t.join();
  return outcomes;
}

json batchReport(const Pipeline& pipeline, const fs::path& out,
                 const std::vector<InputOutcome>& outcomes) {
  std::size_t failed = 0;
  json inputs = json::array();
  for (const InputOutcome& o : outcomes) {
    failed += !o.passed;
    inputs.push_back(o.report);
  }
  return {{"command", "run"}, {"pipeline", pipeline.file}, {"out", out.string()},
          {"inputs", inputs}, {"failed", failed},          {"passed", failed == 0}};
}

}  // namespace polydg
