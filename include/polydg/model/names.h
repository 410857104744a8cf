// The names users write for polydg's choices (on the command line, in pipelines and scenes, in
// Python and in every report), one table per kind: parsing and printing both read it.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "polydg/cut/cut.h"
#include "polydg/mesh/meshing.h"
#include "polydg/model/model.h"
#include "polydg/physics/dg/discretization.h"
#include "polydg/physics/fem/tet_method.h"
#include "polydg/physics/solvers/solver_options.h"

namespace polydg {

/// A choice's names and values, in the order help texts list them.
template <class E>
using Names = std::vector<std::pair<std::string, E>>;

const Names<Method>& methodNames();                    ///< ip, bz
const Names<TetMethod>& tetMethodNames();              ///< fem, fs-fem
const Names<BzPenalty>& bzPenaltyNames();              ///< fixed, super
const Names<SolverKind>& solverNames();                ///< auto, cholesky, cg
const Names<PenaltyRule>& penaltyNames();              ///< bound, doubling, fixed
const Names<RepairMode>& repairNames();                ///< none, fill, wrap
const Names<CheckLevel>& checkLevelNames();            ///< none, local, full
const Names<CgPreconditioner>& preconditionerNames();  ///< p-multigrid, block-jacobi
const Names<RefineSplit>& refineSplitNames();          ///< octants, halves
const Names<AdaptCriterion>& adaptCriterionNames();    ///< error, stress
/// Which side of a cut to delete: "+" (normal . x > d) is +1, "-" is -1, "none" is 0.
const Names<int>& removeSideNames();

/// The name of `value` ("?" if the table lacks it).
template <class E>
std::string nameOf(const Names<E>& names, E value) {
  for (const auto& [name, v] : names)
    if (v == value) return name;
  return "?";
}

/// The value named `text` (ASCII case ignored), or nothing.
template <class E>
std::optional<E> parseName(const Names<E>& names, std::string_view text) {
  auto lower = [](std::string_view s) {
    std::string out(s);
    for (char& c : out)
      if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
    return out;
  };
  const std::string key = lower(text);
  for (const auto& [name, v] : names)
    if (lower(name) == key) return v;
  return std::nullopt;
}

/// "ip, bz": the names, for messages.
template <class E>
std::string listNames(const Names<E>& names) {
  std::string out;
  for (const auto& [name, v] : names) out += (out.empty() ? "" : ", ") + name;
  return out;
}

inline std::string toString(Method m) { return nameOf(methodNames(), m); }
inline std::string toString(TetMethod m) { return nameOf(tetMethodNames(), m); }
inline std::string toString(BzPenalty b) { return nameOf(bzPenaltyNames(), b); }
inline std::string toString(SolverKind k) { return nameOf(solverNames(), k); }
inline std::string toString(PenaltyRule r) { return nameOf(penaltyNames(), r); }
inline std::string toString(RepairMode r) { return nameOf(repairNames(), r); }
inline std::string toString(CheckLevel l) { return nameOf(checkLevelNames(), l); }
inline std::string toString(CgPreconditioner p) { return nameOf(preconditionerNames(), p); }

}  // namespace polydg
