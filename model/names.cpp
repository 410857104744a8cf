#include "polydg/model/names.h"

namespace polydg {

const Names<Method>& methodNames() {
  static const Names<Method> names{{"ip", Method::IP}, {"bz", Method::BZ}};
  return names;
}

const Names<TetMethod>& tetMethodNames() {
  static const Names<TetMethod> names{{"fem", TetMethod::Fem}, {"fs-fem", TetMethod::FsFem}};
  return names;
}

const Names<BzPenalty>& bzPenaltyNames() {
  static const Names<BzPenalty> names{{"fixed", BzPenalty::Fixed}, {"super", BzPenalty::Super}};
  return names;
}

const Names<RefineSplit>& refineSplitNames() {
  static const Names<RefineSplit> names{{"octants", RefineSplit::Octants},
                                        {"halves", RefineSplit::Halves}};
  return names;
}

const Names<AdaptCriterion>& adaptCriterionNames() {
  static const Names<AdaptCriterion> names{{"error", AdaptCriterion::Error},
                                           {"stress", AdaptCriterion::Stress}};
  return names;
}

const Names<SolverKind>& solverNames() {
  static const Names<SolverKind> names{{"auto", SolverKind::Auto},
                                       {"cholesky", SolverKind::Cholesky},
                                       {"cg", SolverKind::ConjugateGradient}};
  return names;
}

const Names<PenaltyRule>& penaltyNames() {
  static const Names<PenaltyRule> names{{"bound", PenaltyRule::TraceBound},
                                        {"doubling", PenaltyRule::Doubling},
                                        {"fixed", PenaltyRule::Fixed}};
  return names;
}

const Names<RepairMode>& repairNames() {
  static const Names<RepairMode> names{
      {"none", RepairMode::None}, {"fill", RepairMode::Fill}, {"wrap", RepairMode::Wrap}};
  return names;
}

const Names<CheckLevel>& checkLevelNames() {
  static const Names<CheckLevel> names{
      {"none", CheckLevel::None}, {"local", CheckLevel::Local}, {"full", CheckLevel::Full}};
  return names;
}

const Names<CgPreconditioner>& preconditionerNames() {
  static const Names<CgPreconditioner> names{{"p-multigrid", CgPreconditioner::PMultigrid},
                                             {"block-jacobi", CgPreconditioner::BlockJacobi}};
  return names;
}

const Names<int>& removeSideNames() {
  static const Names<int> names{{"+", 1}, {"-", -1}, {"none", 0}};
  return names;
}

}  // namespace polydg
