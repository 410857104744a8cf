#include "polydg/model/scene.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "model/json_reader.h"
#include "polydg/model/names.h"
#include "polydg/model/pipeline.h"
#include "polydg/util/error.h"

namespace polydg {

using nlohmann::json;

namespace {

constexpr const char* kHint = "see the scene format in docs/guide.md";
constexpr double kHuge = 1e300;
constexpr int kMaxSteps = 100000000;

}  // namespace

const Names<Integrator>& integratorNames() {
  static const Names<Integrator> names{{"euler", Integrator::BackwardEuler},
                                       {"bdf2", Integrator::Bdf2},
                                       {"newmark", Integrator::Newmark}};
  return names;
}

namespace {

void checkFinite(const Vec3& v, const std::string& key) {
  if (!v.allFinite()) throw InvalidOption(key, "must be three finite numbers");
}

void checkAtLeast(double value, double lo, const std::string& key, const std::string& what) {
  if (!(value >= lo && value < kHuge)) throw InvalidOption(key, what);
}

std::string indexed(const char* list, std::size_t k, const char* key) {
  return std::string(list) + "[" + std::to_string(k) + "]." + key;
}

/// The keys of the embedded surface and of collisions: "embed", "obstacles", "contact".
void readContact(JsonObjectReader& r, Scene& s) {
  if (r.has("embed")) {
    const json& e = r.get("embed");
    if (e.is_boolean()) {
      s.embed.enabled = e.get<bool>();
    } else if (e.is_string() && !e.get<std::string>().empty()) {
      s.embed.enabled = true;
      s.embed.file = e.get<std::string>();
    } else {
      r.fail("embed", "expected a surface file or true (the surface the mesh was sliced from)");
    }
  }
  if (r.has("obstacles")) {
    const json& list = r.list("obstacles", "expected a list of obstacles");
    for (std::size_t k = 0; k < list.size(); ++k) {
      JsonObjectReader item = r.element(list, "obstacles", k);
      SceneObstacle o;
      const bool below = item.has("below"), mesh = item.has("mesh");
      if (below == mesh)
        item.fail(item.place(), "an obstacle needs exactly one of \"below\" and \"mesh\"");
      if (below) {
        const std::vector<double> v = item.numbers(item.get("below"), item.at("below"), 4);
        try {
          o.below = Plane::make(Vec3(v[0], v[1], v[2]), v[3]);
        } catch (const std::invalid_argument& e) {
          item.fail(item.at("below"), e.what());
        }
      } else {
        o.mesh = item.string("mesh");
        if (item.has("voxel")) o.voxel = item.number("voxel");
      }
      if (item.has("velocity")) o.velocity = item.vec3(item.get("velocity"), item.at("velocity"));
      item.finish();
      s.obstacles.push_back(o);
    }
  }
  if (r.has("contact")) {
    JsonObjectReader c = r.object("contact");
    if (c.has("stiffness")) s.contact.stiffness = c.number("stiffness");
    if (c.has("friction")) s.contact.friction = c.number("friction");
    if (c.has("slip_speed")) s.contact.slipSpeed = c.number("slip_speed");
    if (c.has("points")) s.contact.points = c.choice("points", contactPointNames());
    c.finish();
    if (s.obstacles.empty()) r.fail("contact", "there are no \"obstacles\" to touch");
  }
}

/// The edits and contact of a DG body, which the tet methods do not have.
void refuseOnTets(const Scene& s) {
  auto refuse = [&](const char* key, const char* what) {
    throw InvalidOption(key, std::string(what) + " is for the DG methods (ip, bz), not " +
                                 toString(*s.tetMethod) + "; leave it out or use a DG method");
  };
  if (!s.cuts.empty()) refuse("cuts", "cutting while the body moves");
  if (s.embed.enabled) refuse("embed", "an embedded surface");
  if (!s.obstacles.empty()) refuse("obstacles", "contact with obstacles");
  if (s.adapt.enabled) refuse("adapt", "refinement by stress");
  if (s.discretization.basis.degree != BasisOptions{}.degree)
    refuse("degree", "a polynomial degree");
}

}  // namespace

void checkScene(const Scene& s) {
  try {
    s.material.check();
  } catch (const InvalidOption& e) {
    throw InvalidOption("material." + e.key, e.problem);
  }
  s.discretization.check();
  if (!(s.dt > 0.0 && s.dt < kHuge))
    throw InvalidOption("dt", "the time step must be a positive number");
  if (s.steps < 1 || s.steps > kMaxSteps)
    throw InvalidOption("steps", "must be a whole number of steps from 1 to 1e8");
  checkFinite(s.gravity, "gravity");
  checkAtLeast(s.damping.mass, 0.0, "damping.mass", "must be a number >= 0");
  checkAtLeast(s.damping.stiffness, 0.0, "damping.stiffness", "must be a number >= 0");
  for (std::size_t k = 0; k < s.loads.size(); ++k) {
    checkFinite(s.loads[k].traction, indexed("loads", k, "traction"));
    if (!(s.loads[k].until >= 0.0))
      throw InvalidOption(indexed("loads", k, "until"), "must be a time >= 0");
  }
  checkFinite(s.velocity, "initial.velocity");
  checkFinite(s.angularVelocity, "initial.angular_velocity");
  if (s.outputEvery < 1)
    throw InvalidOption("output.every", "must be a whole number of steps >= 1");
  const double end = s.steps * s.dt;
  for (std::size_t k = 0; k < s.cuts.size(); ++k) {
    const double time = s.cuts[k].time;
    if (!(time >= 0.0)) throw InvalidOption(indexed("cuts", k, "time"), "must be a time >= 0");
    if (time > end * (1 + 1e-12))
      throw InvalidOption(indexed("cuts", k, "time"),
                          "after the end of the simulation (t = " + std::to_string(end) +
                              "); it would never happen");
    if (k > 0 && time < s.cuts[k - 1].time)
      throw InvalidOption(indexed("cuts", k, "time"), "the cuts must be in time order");
  }
  for (std::size_t k = 0; k < s.obstacles.size(); ++k) {
    checkFinite(s.obstacles[k].velocity, indexed("obstacles", k, "velocity"));
    checkAtLeast(s.obstacles[k].voxel, 0.0, indexed("obstacles", k, "voxel"),
                 "must be a positive length (or 0: chosen from the sizes)");
  }
  checkAtLeast(s.contact.stiffness, 0.0, "contact.stiffness", "must be a positive number");
  checkAtLeast(s.contact.friction, 0.0, "contact.friction", "must be a number >= 0");
  checkAtLeast(s.contact.slipSpeed, 0.0, "contact.slip_speed", "must be a positive speed");
  if (s.tetMethod) refuseOnTets(s);
  if (s.adapt.enabled) {
    if (!(s.adapt.stress > 0.0 && s.adapt.stress < kHuge))
      throw InvalidOption("adapt.stress", "must be a positive stress");
    if (s.adapt.every < 1)
      throw InvalidOption("adapt.every", "must be a whole number of steps >= 1");
    if (s.adapt.maxLevel < 1 || s.adapt.maxLevel > 8)
      throw InvalidOption("adapt.max_level", "must be 1 to 8");
    if (!(s.adapt.coarsen >= 0.0 && s.adapt.coarsen <= 1.0))
      throw InvalidOption("adapt.coarsen", "must be a fraction in [0, 1]");
  }
}

Scene parseScene(const json& document, const std::string& file) {
  JsonObjectReader r(document, "", file, kHint);
  Scene s;
  s.material = readMaterial(r, s.material);  // "material" is required
  readMethod(r, s.discretization.method, s.tetMethod);
  if (r.has("bz_penalty")) s.discretization.bzPenalty = r.choice("bz_penalty", bzPenaltyNames());
  if (r.has("degree")) s.discretization.basis.degree = r.integer("degree");
  if (r.has("corotational")) s.corotational = r.boolean("corotational");
  if (r.has("integrator")) s.integrator = r.choice("integrator", integratorNames());
  if (r.has("solver")) s.solver = r.choice("solver", solverNames());
  s.dt = r.number("dt");
  const bool duration = r.has("duration"), steps = r.has("steps");
  if (duration == steps) r.fail("", "give exactly one of \"duration\" and \"steps\"");
  if (steps) {
    s.steps = r.integer("steps");
  } else if (s.dt > 0.0) {  // else checkScene() refuses dt
    const double d = r.number("duration");
    const double n = std::round(d / s.dt);
    if (!(n >= 1 && n <= kMaxSteps) || std::abs(n * s.dt - d) > 1e-9 * d)
      r.fail("duration", "must be a whole number (1 to 1e8) of time steps dt (" +
                             std::to_string(d / s.dt) + " steps); or give \"steps\"");
    s.steps = static_cast<int>(n);
  }
  if (r.has("gravity")) s.gravity = r.vec3(r.get("gravity"), "gravity");
  if (r.has("damping")) {
    JsonObjectReader d = r.object("damping");
    if (d.has("mass")) s.damping.mass = d.number("mass");
    if (d.has("stiffness")) s.damping.stiffness = d.number("stiffness");
    d.finish();
  }
  if (r.has("fixed")) {
    const json& list = r.list("fixed", "expected a list of regions ([] for a free body)");
    for (std::size_t k = 0; k < list.size(); ++k) {
      JsonObjectReader item = r.element(list, "fixed", k);
      s.fixed.push_back(item.selection());
      item.finish();
    }
  }
  if (r.has("loads")) {
    const json& list = r.list("loads", "expected a list of tractions");
    for (std::size_t k = 0; k < list.size(); ++k) {
      JsonObjectReader item = r.element(list, "loads", k);
      TimedTraction t;
      t.traction = item.vec3(item.get("traction"), item.at("traction"));
      JsonObjectReader on = item.object("on");
      t.where = on.selection();
      on.finish();
      if (item.has("until")) t.until = item.number("until");
      item.finish();
      s.loads.push_back(t);
    }
  }
  if (r.has("initial")) {
    JsonObjectReader i = r.object("initial");
    if (i.has("velocity")) s.velocity = i.vec3(i.get("velocity"), i.at("velocity"));
    if (i.has("angular_velocity"))
      s.angularVelocity = i.vec3(i.get("angular_velocity"), i.at("angular_velocity"));
    i.finish();
  }
  if (r.has("output")) {
    JsonObjectReader o = r.object("output");
    if (o.has("every")) s.outputEvery = o.integer("every");
    o.finish();
  }
  if (r.has("cuts")) {
    const json& list = r.list("cuts", "expected a list of cuts");
    for (std::size_t k = 0; k < list.size(); ++k) {
      JsonObjectReader item = r.element(list, "cuts", k);
      TimedCut c;
      c.time = item.number("time");
      c.request = readCutRequest(item);
      item.finish();
      s.cuts.push_back(c);
    }
    std::stable_sort(s.cuts.begin(), s.cuts.end(),
                     [](const TimedCut& a, const TimedCut& b) { return a.time < b.time; });
  }
  readContact(r, s);
  if (r.has("adapt")) {
    JsonObjectReader a = r.object("adapt");
    s.adapt.enabled = true;
    s.adapt.stress = a.number("stress");
    if (a.has("split")) s.adapt.split = a.choice("split", refineSplitNames());
    if (a.has("every")) s.adapt.every = a.integer("every");
    if (a.has("max_level")) s.adapt.maxLevel = a.integer("max_level");
    if (a.has("coarsen")) s.adapt.coarsen = a.number("coarsen");
    a.finish();
  }
  r.finish();
  r.checked([&] { checkScene(s); });
  return s;
}

const Names<ContactPoints>& contactPointNames() {
  static const Names<ContactPoints> names{{"surface", ContactPoints::Surface},
                                          {"nodes", ContactPoints::Nodes}};
  return names;
}

Scene readScene(const std::string& file) {
  Scene s = parseScene(readJsonDocument(file, "scene"), file);
  // Files a scene names are relative to the scene's folder.
  const std::filesystem::path folder = std::filesystem::path(file).parent_path();
  auto resolve = [&](std::string& name) {
    if (!name.empty() && std::filesystem::path(name).is_relative()) name = (folder / name).string();
  };
  resolve(s.embed.file);
  for (SceneObstacle& o : s.obstacles) resolve(o.mesh);
  return s;
}

}  // namespace polydg
