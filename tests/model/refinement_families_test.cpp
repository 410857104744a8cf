// RefinementFamilies: which elements a simulation's adaptivity refines, and which families of
// children it merges back, by the scene's thresholds.
#include "model/refinement_families.h"

#include <gtest/gtest.h>

namespace polydg {
namespace {

ElementFields stresses(const std::vector<double>& values) {
  ElementFields f;
  f.principalStress = ElementData<double>(values.size());
  f.principalDirection = ElementData<Vec3>(values.size(), Vec3(1, 0, 0));
  for (std::size_t e = 0; e < values.size(); ++e) f.principalStress[ElementId(e)] = values[e];
  return f;
}

/// Three elements; 0 and 2 refined into halves: new elements 0, 1 from old 0, 2 from old 1,
/// 3, 4 from old 2.
RefinementFamilies twoFamilies() {
  RefinementFamilies families(3);
  ElementLineage lineage;
  lineage.changed = {{0, {ElementId(0)}},
                     {1, {ElementId(0)}},
                     {2, {ElementId(1)}},
                     {3, {ElementId(2)}},
                     {4, {ElementId(2)}}};
  families.afterRefinement(lineage, 5, {0, 2});
  return families;
}

TEST(RefinementFamilies, RefinesAboveTheThresholdBelowTheLevelLimit) {
  SceneAdapt adapt;
  adapt.stress = 10.0;
  adapt.maxLevel = 1;
  const RefinementFamilies fresh(3);
  const RefineRequest first = fresh.refinement(stresses({11, -12, 9}), adapt);
  ASSERT_EQ(first.elements.size(), 2u);  // the sign does not matter, the magnitude does
  EXPECT_EQ(first.elements[0], ElementId(0));
  EXPECT_EQ(first.elements[1], ElementId(1));
  // The children are at level 1 = maxLevel: not refined again; element 2 (level 0) is.
  const RefineRequest again = twoFamilies().refinement(stresses({50, 50, 50, 50, 50}), adapt);
  ASSERT_EQ(again.elements.size(), 1u);
  EXPECT_EQ(again.elements[0], ElementId(2));
}

TEST(RefinementFamilies, MergesAFamilyOnlyWhenAllItsStressesFallBelowCoarsenTimesStress) {
  SceneAdapt adapt;
  adapt.stress = 10.0;
  adapt.coarsen = 0.5;
  const RefinementFamilies families = twoFamilies();
  // Family {0, 1}: 4.9 and -4.9, below 5; family {3, 4}: 6 lies between 5 and 10: kept.
  // Element 2 belongs to no family.
  const CoarsenRequest request = families.coarsening(stresses({4.9, -4.9, 0, 1, 6}), adapt);
  ASSERT_EQ(request.groups.size(), 1u);
  EXPECT_EQ(request.groups[0], (std::vector<ElementId>{ElementId(0), ElementId(1)}));
  EXPECT_EQ(families.coarsening(stresses({5, 0, 0, 0, 0}), adapt).groups.size(), 1u);  // >= 5
  adapt.coarsen = 0.0;                                                                 // never
  EXPECT_TRUE(families.coarsening(stresses({0, 0, 0, 0, 0}), adapt).groups.empty());
}

TEST(RefinementFamilies, AMergedFamilyReturnsToItsParentAndAPartlyCutFamilyStays) {
  SceneAdapt adapt;
  adapt.stress = 10.0;
  adapt.coarsen = 0.5;
  RefinementFamilies families = twoFamilies();
  // Merge {0, 1} back: new element 0 from {0, 1}, the others renumbered down by one.
  ElementLineage merge;
  merge.changed = {{0, {ElementId(0), ElementId(1)}},
                   {1, {ElementId(2)}},
                   {2, {ElementId(3)}},
                   {3, {ElementId(4)}}};
  families.afterCoarsening(merge, 4);
  const CoarsenRequest after = families.coarsening(stresses({0, 0, 0, 0}), adapt);
  ASSERT_EQ(after.groups.size(), 1u);  // only {3, 4}, now {2, 3}; the merged one is level 0
  EXPECT_EQ(after.groups[0], (std::vector<ElementId>{ElementId(2), ElementId(3)}));
  // A cut removes child 3: its family is no longer whole and is not merged.
  ElementLineage cut;
  cut.changed = {{0, {ElementId(0)}}, {1, {ElementId(1)}}, {2, {ElementId(2)}}};
  families.afterCut(cut, 3);
  EXPECT_TRUE(families.coarsening(stresses({0, 0, 0}), adapt).groups.empty());
}

}  // namespace
}  // namespace polydg
