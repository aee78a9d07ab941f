// The cut-type table (cut_types.h) and each type's equations. Weld and prismatic cuts align
// two cut frames, one on each body (z along axis1 / axis2, x along ref1 / ref2 made
// perpendicular to the axis), with the three orientation equations of constraints.h, which hold
// exactly that relative rotation.
#include "formulation/cut_types.h"

#include <cmath>

#include "formulation/euler_parameters.h"

namespace mbdae {

void CutEquations::add(Constraint c, const std::string& what) const {
  c.owner = Constraint::Owner::kCut;
  c.owner_name = cut.name;
  c.label = "cut " + cut.name + ": " + what;
  sys.constraints.push_back(c);
}

namespace {

// The cut frame on one side, in its body's frame: z along `axis`, x along `ref` without its
// component along the axis; a zero `ref` takes the body axis most perpendicular to `axis`.
Mat3 cut_frame(const Vec3& axis, const Vec3& ref) {
  const Vec3 z = axis.normalized();
  Vec3 r = ref;
  if (r.isZero()) {
    int k = 0;
    for (int m = 1; m < 3; ++m)
      if (std::fabs(z[m]) < std::fabs(z[k]) - 1e-12) k = m;
    r = Vec3::Unit(k);
  }
  const Vec3 x = r - r.dot(z) * z;  // not along z: check_model's cut_reference_across_axis()
  Mat3 f;
  f.col(0) = x.normalized();
  f.col(2) = z;
  f.col(1) = z.cross(f.col(0));
  return f;
}

Constraint cut_constraint(Constraint::Type type, const CutSides& s) {
  Constraint c;
  c.type = type;
  c.bi = s.f1->body;
  c.si = s.s1;
  c.bj = s.f2->body;
  c.sj = s.s2;
  return c;
}

// The three equations that hold cut frame 1 on cut frame 2.
void add_frame_alignment(const CutSpec& cut, const CutSides& s, const CutEquations& out) {
  const Mat3 c1 = s.f1->rotation * cut_frame(cut.axis1, cut.ref1);
  const Mat3 c2 = s.f2->rotation * cut_frame(cut.axis2, cut.ref2);
  Vec4 w[3];
  orientation_rows(euler_parameters_from_rotation(c1), euler_parameters_from_rotation(c2), w);
  for (int k = 0; k < 3; ++k) {
    Constraint c = cut_constraint(Constraint::Type::kOrientation, s);
    c.w = w[k];
    out.add(c, std::string("frames aligned about ") + "xyz"[k]);
  }
}

// Body 1's axis, body 2's axis, in their hosts' local coordinates.
Vec3 axis1(const CutSpec& cut, const CutSides& s) { return s.f1->local_vector(cut.axis1.normalized()); }
Vec3 axis2(const CutSpec& cut, const CutSides& s) { return s.f2->local_vector(cut.axis2.normalized()); }

void dot1(const CutSides& s, const Vec3& u, const Vec3& w, const std::string& what, const CutEquations& out) {
  Constraint c = cut_constraint(Constraint::Type::kDot1, s);
  c.ai = u;
  c.aj = w;
  out.add(c, what);
}

void ball(const CutSpec&, const CutSides& s, const CutEquations& out) {
  out.add(cut_constraint(Constraint::Type::kPoint, s), "coincident points");
}

void revolute(const CutSpec& cut, const CutSides& s, const CutEquations& out) {
  const Vec3 a1 = axis1(cut, s), a2 = axis2(cut, s);
  const Vec3 n1 = a2.unitOrthogonal(), n2 = a2.cross(n1);  // unit vectors of body 2 across its axis
  out.add(cut_constraint(Constraint::Type::kPoint, s), "coincident points");
  dot1(s, a1, n1, "axis1 _|_ n1", out);
  dot1(s, a1, n2, "axis1 _|_ n2", out);
}

void universal(const CutSpec& cut, const CutSides& s, const CutEquations& out) {
  out.add(cut_constraint(Constraint::Type::kPoint, s), "coincident points");
  dot1(s, axis1(cut, s), axis2(cut, s), "axis1 _|_ axis2", out);
}

void weld(const CutSpec& cut, const CutSides& s, const CutEquations& out) {
  out.add(cut_constraint(Constraint::Type::kPoint, s), "coincident points");
  add_frame_alignment(cut, s, out);
}

// Point 2 on body 1's axis line a1: no offset along the two directions across it.
void no_offset_across_axis(const Vec3& a1, const CutSides& s, const CutEquations& out) {
  const Vec3 m1 = a1.unitOrthogonal(), m2 = a1.cross(m1);
  for (const Vec3& m : {m1, m2}) {
    Constraint c = cut_constraint(Constraint::Type::kDot2, s);
    c.ai = m;
    out.add(c, "no offset across the axis");
  }
}

void prismatic(const CutSpec& cut, const CutSides& s, const CutEquations& out) {
  add_frame_alignment(cut, s, out);
  no_offset_across_axis(axis1(cut, s), s, out);
}

// Rotation about and translation along a common axis: the axes parallel (as the revolute) and
// point 2 on body 1's axis line (no offset across it, as the prismatic).
void cylindrical(const CutSpec& cut, const CutSides& s, const CutEquations& out) {
  const Vec3 a1 = axis1(cut, s), a2 = axis2(cut, s);
  const Vec3 n1 = a2.unitOrthogonal(), n2 = a2.cross(n1);
  dot1(s, a1, n1, "axis1 _|_ n1", out);
  dot1(s, a1, n2, "axis1 _|_ n2", out);
  no_offset_across_axis(a1, s, out);
}

void distance(const CutSpec& cut, const CutSides& s, const CutEquations& out) {
  Constraint c = cut_constraint(Constraint::Type::kDistance, s);
  c.distance = cut.distance;
  out.add(c, "distance");
}

}  // namespace

const std::vector<CutType>& cut_types() {
  using T = CutSpec::Type;
  static const std::vector<CutType> rows = {
      {"ball", T::kBall, {}, false, ball},
      {"revolute", T::kRevolute, {"axis1", "axis2"}, false, revolute},
      {"universal", T::kUniversal, {"axis1", "axis2"}, false, universal},
      {"prismatic", T::kPrismatic, {"axis1", "axis2", "ref1", "ref2"}, true, prismatic},
      {"weld", T::kWeld, {"axis1", "axis2", "ref1", "ref2"}, true, weld},
      {"distance", T::kDistance, {"distance"}, false, distance},
      {"cylindrical", T::kCylindrical, {"axis1", "axis2"}, false, cylindrical},
  };
  return rows;
}

const CutType& cut_type(CutSpec::Type type) {
  for (const CutType& row : cut_types())
    if (row.type == type) return row;
  return cut_types().front();  // every enum value has a row (cut_types_test)
}

const CutType* find_cut_type(const std::string& name) {
  for (const CutType& row : cut_types())
    if (name == row.name) return &row;
  return nullptr;
}

std::string cut_type_names() {
  std::string s;
  for (const CutType& row : cut_types()) s += (s.empty() ? "" : ", ") + std::string(row.name);
  return s;
}

}  // namespace mbdae
