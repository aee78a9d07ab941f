// The cut types, one row each (issue 22): a cut type is its row here, its equations in
// cut_types.cpp and its enum value in CutSpec (formulation/model.h). The loader reads the names
// and fields from the rows, the model rules the need of reference directions, and the build
// (system_cuts.cpp) the equations.
#pragma once

#include <string>
#include <vector>

#include "formulation/constraints.h"
#include "formulation/model.h"
#include "formulation/system.h"

namespace mbdae {

// The two sides of a cut: each body's frame and the cut point (host-local coordinates).
struct CutSides {
  const BodyFrame* f1;
  const BodyFrame* f2;
  Vec3 s1, s2;
};

// Receives a cut's equations: a constraint and what it holds ("coincident points").
struct CutEquations {
  const CutSpec& cut;
  System& sys;
  void add(Constraint c, const std::string& what) const;
};

struct CutType {
  const char* name;   // in the scene's `type` field
  CutSpec::Type type;
  std::vector<std::string> fields;  // the fields besides name, type, body1, point1, body2, point2
  // Weld and prismatic: cut frames on both bodies (z along axis1 / axis2, x along ref1 / ref2
  // made perpendicular to the axis); a reference along its axis is refused (check_model).
  bool frames;
  void (*equations)(const CutSpec& cut, const CutSides& sides, const CutEquations& out);
};

const std::vector<CutType>& cut_types();
const CutType& cut_type(CutSpec::Type type);
const CutType* find_cut_type(const std::string& name);  // null if none
std::string cut_type_names();                             // "ball, revolute, ...", for messages

}  // namespace mbdae
