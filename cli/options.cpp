#include "cli/options.h"

#include <cctype>
#include <cmath>
#include <filesystem>
#include <sstream>

namespace polydg::cli {

namespace {

/// The finite double `item` is, or nothing.
std::optional<double> finiteNumber(const std::string& item) {
  std::size_t used = 0;
  double v = 0.0;
  try {
    v = std::stod(item, &used);
  } catch (const std::exception&) {
    return std::nullopt;
  }
  while (used < item.size() && std::isspace(static_cast<unsigned char>(item[used]))) ++used;
  if (used == 0 || used != item.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

CLI::Validator numberCheck(const std::string& name, const std::function<bool(double)>& ok,
                           const std::string& expected) {
  return CLI::Validator(
      [ok, expected](std::string& text) -> std::string {
        const auto v = finiteNumber(text);
        if (!v || !ok(*v)) return "'" + text + "' is not " + expected;
        return {};
      },
      "", name);
}

}  // namespace

const CLI::Validator kFinite = numberCheck(
    "FINITE", [](double) { return true; }, "a finite number");
const CLI::Validator kPositive = numberCheck(
    "POSITIVE", [](double x) { return x > 0.0; }, "a finite number > 0");
const CLI::Validator kNonNegative = numberCheck(
    "NONNEGATIVE", [](double x) { return x >= 0.0; }, "a finite number >= 0");

CLI::Validator libraryRule(std::function<void(double)> rule) {
  return CLI::Validator(
      [rule](std::string& text) -> std::string {
        const auto v = finiteNumber(text);
        if (!v) return "'" + text + "' is not a finite number";
        try {
          rule(*v);
        } catch (const InvalidOption& e) {
          return e.problem;
        }
        return {};
      },
      "", "NUMBER");
}

namespace {

/// Material::check() of a material with `field` set to the value.
CLI::Validator materialRule(double Material::*field) {
  return libraryRule([field](double value) {
    Material m;
    m.*field = value;
    m.check();
  });
}

}  // namespace

const CLI::Validator kYoungsModulus = materialRule(&Material::youngsModulus);
const CLI::Validator kPoissonRatio = materialRule(&Material::poissonRatio);
const CLI::Validator kDensity = materialRule(&Material::density);
const CLI::Validator kDegree = libraryRule([](double p) {
  DiscretizationOptions d;
  d.basis.degree = p >= 0 && p <= 1e6 ? static_cast<int>(p) : -1;
  d.check();
});
const CLI::Validator kPenalty = libraryRule([](double eta) {
  DiscretizationOptions d;
  d.penalty.eta = eta;
  d.check();
});

CLI::Validator finiteRange(double lo, double hi) {
  std::ostringstream s;
  s << "a finite number in [" << lo << ", " << hi << "]";
  return numberCheck(
      "RANGE", [lo, hi](double x) { return x >= lo && x <= hi; }, s.str());
}

std::vector<double> parseNumbers(const std::string& text, std::size_t count,
                                 const std::string& option) {
  std::vector<double> values;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    const auto v = finiteNumber(item);
    if (!v) throw CLI::ValidationError(option, "'" + item + "' is not a finite number");
    values.push_back(*v);
  }
  if (values.size() != count)
    throw CLI::ValidationError(option, "expected " + std::to_string(count) +
                                           " comma-separated numbers, got " +
                                           std::to_string(values.size()));
  return values;
}

Vec3 parseVector(const std::string& text, const std::string& option) {
  const auto v = parseNumbers(text, 3, option);
  return {v[0], v[1], v[2]};
}

Plane parsePlane(const std::string& text, const std::string& option) {
  const auto v = parseNumbers(text, 4, option);
  try {
    return Plane::make(Vec3(v[0], v[1], v[2]), v[3]);
  } catch (const std::invalid_argument& e) {
    throw CLI::ValidationError(option, e.what());
  }
}

Box3 parseBox(const std::string& text, const std::string& option) {
  const auto v = parseNumbers(text, 6, option);
  const Box3 box(Vec3(v[0], v[1], v[2]), Vec3(v[3], v[4], v[5]));
  try {
    return FaceSelector::inBox(box).box;
  } catch (const std::invalid_argument& e) {
    throw CLI::ValidationError(option, e.what());
  }
}

Plane parseAxisPlane(const std::string& text, const std::string& option) {
  const auto eq = text.find('=');
  if (eq != 1 || text.size() < 3)
    throw CLI::ValidationError(option, "expected AXIS=VALUE with AXIS one of x, y, z");
  const char a = static_cast<char>(std::tolower(static_cast<unsigned char>(text[0])));
  if (a < 'x' || a > 'z') throw CLI::ValidationError(option, "the axis must be x, y or z");
  const auto v = finiteNumber(text.substr(2));
  if (!v) throw CLI::ValidationError(option, "'" + text.substr(2) + "' is not a finite number");
  return Plane::axisAligned(a - 'x', *v);
}

Blade parsePolygon(const std::string& text, const std::string& option) {
  std::vector<Vec3> corners;
  std::stringstream in(text);
  std::string corner;
  while (std::getline(in, corner, ';')) corners.push_back(parseVector(corner, option));
  try {
    return Blade::fromPolygon(std::move(corners));
  } catch (const std::invalid_argument& e) {
    throw CLI::ValidationError(option, e.what());
  }
}

namespace {

/// The region forms and their parsers: the suffix of the option and how to read its value.
struct RegionForm {
  const char* suffix;
  const char* typeName;
  const char* help;
  FaceSelector (*parse)(const std::string& text, const std::string& option);
};

const RegionForm kRegionForms[] = {
    {"", "AXIS=VALUE", "the boundary faces in the plane AXIS=VALUE",
     [](const std::string& t, const std::string& o) {
       return FaceSelector::inPlane(parseAxisPlane(t, o));
     }},
    {"-plane", "NX,NY,NZ,D", "the boundary faces in the plane NX x + NY y + NZ z = D",
     [](const std::string& t, const std::string& o) {
       return FaceSelector::inPlane(parsePlane(t, o));
     }},
    {"-below", "NX,NY,NZ,D", "the boundary faces with NX x + NY y + NZ z <= D",
     [](const std::string& t, const std::string& o) {
       return FaceSelector::below(parsePlane(t, o));
     }},
    {"-box", "X0,Y0,Z0,X1,Y1,Z1", "the boundary faces inside the box",
     [](const std::string& t, const std::string& o) {
       return FaceSelector::inBox(parseBox(t, o));
     }},
};

}  // namespace

FaceSelector parseRegion(const std::string& text, const std::string& option) {
  const auto colon = text.find(':');
  if (colon == std::string::npos) return kRegionForms[0].parse(text, option);
  const std::string suffix = "-" + text.substr(0, colon);
  for (const RegionForm& form : kRegionForms)
    if (suffix == form.suffix) return form.parse(text.substr(colon + 1), option);
  throw CLI::ValidationError(option, "'" + text.substr(0, colon) +
                                         "' is not a region; use x=V, plane:NX,NY,NZ,D, "
                                         "below:NX,NY,NZ,D or box:X0,Y0,Z0,X1,Y1,Z1");
}

void addRegionOptions(CLI::App& cmd, const std::string& prefix, std::vector<FaceSelector>& regions,
                      const std::string& what) {
  for (const RegionForm& form : kRegionForms) {
    const std::string flag = "--" + prefix + form.suffix;
    cmd.add_option_function<std::vector<std::string>>(
           flag,
           [&regions, flag, parse = form.parse](const std::vector<std::string>& values) {
             for (const std::string& v : values) regions.push_back(parse(v, flag));
           },
           what + " " + form.help + "; repeatable")
        ->type_name(form.typeName)
        ->allow_extra_args(false);
  }
}

void addTractionOptions(CLI::App& cmd, std::vector<TractionLoad>& tractions) {
  for (const RegionForm& form : kRegionForms) {
    const std::string flag = std::string("--traction") + form.suffix;
    cmd.add_option_function<std::vector<std::string>>(
           flag,
           [&tractions, flag, parse = form.parse](const std::vector<std::string>& values) {
             for (const std::string& v : values) {
               const auto colon = v.rfind(':');
               if (colon == std::string::npos)
                 throw CLI::ValidationError(flag, "expected REGION:TX,TY,TZ");
               tractions.push_back(
                   {parse(v.substr(0, colon), flag), parseVector(v.substr(colon + 1), flag)});
             }
           },
           std::string("a traction (force per area) TX,TY,TZ on ") + form.help + "; repeatable")
        ->type_name(std::string(form.typeName) + ":TX,TY,TZ")
        ->allow_extra_args(false);
  }
}

bool isVolumeMeshPath(const std::string& path) {
  const auto ext = std::filesystem::path(path).extension().string();
  return ext == ".vtu" || ext == ".VTU";
}

}  // namespace polydg::cli
