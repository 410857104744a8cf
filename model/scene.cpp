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

constexpr const char* kHint = "see the scene format in README.md";
constexpr double kHuge = 1e300;

}  // namespace

const Names<Integrator>& integratorNames() {
  static const Names<Integrator> names{{"euler", Integrator::BackwardEuler},
                                       {"bdf2", Integrator::Bdf2},
                                       {"newmark", Integrator::Newmark}};
  return names;
}

Scene parseScene(const json& document, const std::string& file) {
  JsonObjectReader r(document, "", file, kHint);
  Scene s;
  s.material = readMaterial(r, s.material);  // "material" is required
  try {
    s.material.check();
  } catch (const std::invalid_argument& e) {
    r.fail("material", e.what());
  }
  if (r.has("method")) s.method = r.choice("method", methodNames());
  if (r.has("bz_penalty")) {
    s.bzPenalty = r.choice("bz_penalty", bzPenaltyNames());
    if (s.bzPenalty != BzPenalty::Fixed && s.method != Method::BZ)
      r.fail("bz_penalty", "is for the BZ method: add \"method\": \"bz\"");
  }
  if (r.has("degree")) s.degree = r.integer("degree", 1, 3);
  if (r.has("corotational")) s.corotational = r.boolean("corotational");
  if (r.has("integrator")) s.integrator = r.choice("integrator", integratorNames());
  if (r.has("solver")) s.solver = r.choice("solver", solverNames());
  s.dt = r.number("dt", 1e-300, kHuge);
  const bool duration = r.has("duration"), steps = r.has("steps");
  if (duration == steps) r.fail("", "give exactly one of \"duration\" and \"steps\"");
  if (steps) {
    s.steps = r.integer("steps", 1, 100000000);
  } else {
    const double d = r.number("duration", 1e-300, kHuge);
    const double n = std::round(d / s.dt);
    if (n < 1 || n > 1e8 || std::abs(n * s.dt - d) > 1e-9 * d)
      r.fail("duration", "must be a whole number (1 to 1e8) of time steps dt (" +
                             std::to_string(d / s.dt) + " steps); or give \"steps\"");
    s.steps = static_cast<int>(n);
  }
  if (r.has("gravity")) s.gravity = r.vec3(r.get("gravity"), "gravity");
  if (r.has("damping")) {
    JsonObjectReader d = r.object("damping");
    if (d.has("mass")) s.massDamping = d.number("mass", 0.0, kHuge);
    if (d.has("stiffness")) s.stiffnessDamping = d.number("stiffness", 0.0, kHuge);
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
      if (item.has("until")) t.until = item.number("until", 0.0, kHuge);
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
    if (o.has("every")) s.outputEvery = o.integer("every", 1, 100000000);
    o.finish();
  }
  const double end = s.steps * s.dt;
  if (r.has("cuts")) {
    const json& list = r.list("cuts", "expected a list of cuts");
    for (std::size_t k = 0; k < list.size(); ++k) {
      JsonObjectReader item = r.element(list, "cuts", k);
      TimedCut c;
      c.time = item.number("time", 0.0, kHuge);
      if (c.time > end * (1 + 1e-12))
        item.fail(item.at("time"), "after the end of the simulation (t = " + std::to_string(end) +
                                       "); it would never happen");
      c.request = readCutRequest(item);
      item.finish();
      s.cuts.push_back(c);
    }
    std::stable_sort(s.cuts.begin(), s.cuts.end(),
                     [](const TimedCut& a, const TimedCut& b) { return a.time < b.time; });
  }
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
        if (item.has("voxel")) o.voxel = item.number("voxel", 1e-300, kHuge);
      }
      if (item.has("velocity")) o.velocity = item.vec3(item.get("velocity"), item.at("velocity"));
      item.finish();
      s.obstacles.push_back(o);
    }
  }
  if (r.has("adapt")) {
    JsonObjectReader a = r.object("adapt");
    s.adapt.enabled = true;
    s.adapt.stress = a.number("stress", 1e-300, kHuge);
    if (a.has("split")) s.adapt.split = a.choice("split", refineSplitNames());
    if (a.has("every")) s.adapt.every = a.integer("every", 1, 100000000);
    if (a.has("max_level")) s.adapt.maxLevel = a.integer("max_level", 1, 8);
    if (a.has("coarsen")) s.adapt.coarsen = a.number("coarsen", 0.0, 1.0);
    a.finish();
  }
  if (r.has("contact")) {
    JsonObjectReader c = r.object("contact");
    if (c.has("stiffness")) s.contact.stiffness = c.number("stiffness", 1e-300, kHuge);
    if (c.has("friction")) s.contact.friction = c.number("friction", 0.0, kHuge);
    if (c.has("slip_speed")) s.contact.slipSpeed = c.number("slip_speed", 1e-300, kHuge);
    if (c.has("points")) s.contact.points = c.choice("points", contactPointNames());
    c.finish();
    if (s.obstacles.empty()) r.fail("contact", "there are no \"obstacles\" to touch");
  }
  r.finish();
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
