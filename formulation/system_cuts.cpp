// Stage 4 of build_system(): each loop cut becomes the equations of its type
// (formulation/cut_types.h) between the two bodies' points and frames.
#include "formulation/cut_types.h"
#include "formulation/system_build.h"

namespace mbdae {

void add_cut_constraints(const ModelIndex& index, System& sys) {
  for (const auto& cut : index.model.cuts) {
    const auto p1 = point_of(index, sys, cut.body1, cut.point1, cut.where, "body1");
    const auto p2 = point_of(index, sys, cut.body2, cut.point2, cut.where, "body2");
    const CutSides sides{p1.first, p2.first, p1.second, p2.second};
    cut_type(cut.type).equations(cut, sides, CutEquations{cut, sys});
  }
}

}  // namespace mbdae
