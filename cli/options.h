// The polydg command line's option values: one parser per value kind ("nx,ny,nz,d" planes,
// "x,y,z" vectors, boxes, "AXIS=VALUE" planes, region and traction forms, choices from the
// model's name tables) and the validators every numeric option carries, so that a non-finite
// or out-of-range value is refused with one line naming the option.
#pragma once

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "polydg/model/model.h"
#include "polydg/model/names.h"

namespace polydg::cli {

/// Finite numbers only ("nan" and "inf" parse as doubles): add to every floating-point option.
extern const CLI::Validator kFinite;
/// Finite and > 0, finite and >= 0.
extern const CLI::Validator kPositive;
extern const CLI::Validator kNonNegative;
/// Finite in [lo, hi].
CLI::Validator finiteRange(double lo, double hi);
/// A finite number that the library's own check of the option accepts: `rule` sets the value
/// on the option's struct and calls its check() (which throws InvalidOption), so the command
/// line refuses exactly what the library refuses, in the library's words.
CLI::Validator libraryRule(std::function<void(double)> rule);
/// The rules of the material's and the discretization's options, for --E, --nu, --density,
/// --degree and --eta.
extern const CLI::Validator kYoungsModulus, kPoissonRatio, kDensity, kDegree, kPenalty;

/// Comma-separated finite numbers; throws CLI::ValidationError naming `option` unless there
/// are exactly `count` of them.
std::vector<double> parseNumbers(const std::string& text, std::size_t count,
                                 const std::string& option);
Vec3 parseVector(const std::string& text, const std::string& option);  ///< "x,y,z"
Plane parsePlane(const std::string& text, const std::string& option);  ///< "nx,ny,nz,d"
Box3 parseBox(const std::string& text, const std::string& option);     ///< "x0,y0,z0,x1,y1,z1"
/// "x=0.5": the plane x = 0.5 (axis x, y or z).
Plane parseAxisPlane(const std::string& text, const std::string& option);
/// A region in one word, the clamps' forms with the form before a colon: "x=0.5" (the faces in
/// that plane), "plane:NX,NY,NZ,D", "below:NX,NY,NZ,D", "box:X0,Y0,Z0,X1,Y1,Z1".
FaceSelector parseRegion(const std::string& text, const std::string& option);
/// "x1,y1,z1;x2,y2,z2;...": a convex planar polygon blade.
Blade parsePolygon(const std::string& text, const std::string& option);

/// Adds --NAME as a choice from `names`, stored in `target` (an E or an optional E); help lists
/// the names and `shown` as the default.
template <class E, class Target>
CLI::Option* addChoice(CLI::App& cmd, const std::string& flag, Target& target,
                       const Names<E>& names, const std::string& help, E shown) {
  std::vector<std::string> keys;
  for (const auto& [name, value] : names) keys.push_back(name);
  return cmd
      .add_option_function<std::string>(
          flag,
          [&target, &names, flag](const std::string& s) {
            const auto v = parseName(names, s);
            if (!v)
              throw CLI::ValidationError(flag, "'" + s + "' is not one of " + listNames(names));
            target = *v;
          },
          help + " (" + listNames(names) + "; default " + nameOf(names, shown) + ")")
      ->type_name(CLI::detail::join(keys, "|"));
}

template <class E>
CLI::Option* addChoice(CLI::App& cmd, const std::string& flag, E& target, const Names<E>& names,
                       const std::string& help) {
  return addChoice(cmd, flag, target, names, help, target);
}

/// Adds the boundary-region options of a load: --PREFIX AXIS=VALUE, --PREFIX-plane
/// NX,NY,NZ,D, --PREFIX-below NX,NY,NZ,D and --PREFIX-box X0,Y0,Z0,X1,Y1,Z1 (each repeatable),
/// appending each region to `regions` in the order given.
void addRegionOptions(CLI::App& cmd, const std::string& prefix, std::vector<FaceSelector>& regions,
                      const std::string& what);

/// Adds the traction options: --traction AXIS=VALUE:TX,TY,TZ, --traction-plane
/// NX,NY,NZ,D:TX,TY,TZ, --traction-below NX,NY,NZ,D:TX,TY,TZ, --traction-box
/// X0,Y0,Z0,X1,Y1,Z1:TX,TY,TZ.
void addTractionOptions(CLI::App& cmd, std::vector<TractionLoad>& tractions);

/// True for files read as simulation meshes (VTU) rather than surfaces.
bool isVolumeMeshPath(const std::string& path);

}  // namespace polydg::cli
