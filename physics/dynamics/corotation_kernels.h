// The dense kernels of the corotated stiffness, compiled for the CPU's vector instructions
// (util/simd_clones.h): a step at 87k DOFs spends a third of its time outside the solve in
// them (warping the step matrix's blocks, the elastic force).
#pragma once

namespace polydg {

/// out += s (R (x) I_n) B (R (x) I_n)^T for a 3n x 3n column-major block B and column-major
/// 3 x 3 rotation R (blocks in component-major order: row d n + a is component d, function a).
void addWarpedBlock(int n, const double* r, const double* b, double s, double* out);

/// y = B w for a 3n x 3n block B stored column-major, or row-major if !columnMajor.
void blockTimes(int n, const double* b, bool columnMajor, const double* w, double* y);

}  // namespace polydg
