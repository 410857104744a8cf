// An isotropic, homogeneous linear elastic material: Young's modulus, Poisson's ratio and
// density, and the Lame parameters derived from them.
#pragma once

#include <stdexcept>

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
  /// Throws std::invalid_argument unless E > 0 and -1 < nu < 0.5 and density >= 0.
  void check() const {
    if (!(youngsModulus > 0.0)) throw std::invalid_argument("Young's modulus must be positive");
    if (!(poissonRatio > -1.0 && poissonRatio < 0.5))
      throw std::invalid_argument("Poisson's ratio must lie in (-1, 0.5)");
    if (!(density >= 0.0)) throw std::invalid_argument("density must be non-negative");
  }
};

}  // namespace polydg
