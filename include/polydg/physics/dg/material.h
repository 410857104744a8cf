// An isotropic, homogeneous linear elastic material: Young's modulus, Poisson's ratio and
// density, and the Lame parameters derived from them.
#pragma once

#include "polydg/util/error.h"

namespace polydg {

/// Isotropic Hookean material. Units are consistent and arbitrary (stress = force / area).
struct Material {
  double youngsModulus = 1.0;  ///< E > 0
  double poissonRatio = 0.3;   ///< -1 < nu < 0.5
  double density = 1.0;        ///< mass per volume, used with gravity

  /// Shear modulus mu = E / (2 (1 + nu)).
  double mu() const { return youngsModulus / (2.0 * (1.0 + poissonRatio)); }
  /// First Lame parameter lambda = E nu / ((1 + nu)(1 - 2 nu)); grows without bound as
  /// nu -> 0.5.
  double lambda() const {
    return youngsModulus * poissonRatio / ((1.0 + poissonRatio) * (1.0 - 2.0 * poissonRatio));
  }
  /// The one check of a material: throws InvalidOption (keys "E", "nu", "density") unless
  /// 0 < E < 1e300, -0.999999 <= nu <= 0.499999999 (lambda finite and representable as nu
  /// nears 1/2) and 0 <= density < 1e300.
  void check() const {
    if (!(youngsModulus > 0.0 && youngsModulus < 1e300))
      throw InvalidOption("E", "Young's modulus must be a positive number below 1e300");
    if (!(poissonRatio >= -0.999999 && poissonRatio <= 0.499999999))
      throw InvalidOption("nu", "Poisson's ratio must lie in (-1, 0.5), at most 0.499999999");
    if (!(density >= 0.0 && density < 1e300))
      throw InvalidOption("density", "the density must be a number >= 0 and below 1e300");
  }
};

}  // namespace polydg
