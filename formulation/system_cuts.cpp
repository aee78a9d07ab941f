// Stage 4 of build_system(): each loop cut becomes the constraints of its type between the two
// bodies' points and frames. Weld and prismatic cuts align two cut frames, one on each body
// (z along axis1 / axis2, x along ref1 / ref2 made perpendicular to the axis), with the three
// orientation equations of constraints.h, which hold exactly that relative rotation.
#include <cmath>

#include "formulation/system_build.h"

namespace mbdae {
namespace {

// The two sides of a cut: each body's frame and the cut point (host-local coordinates).
struct CutSides {
  const BodyFrame* f1;
  const BodyFrame* f2;
  Vec3 s1, s2;
};

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
template <class Add>
void add_frame_alignment(const CutSpec& cut, const CutSides& s, Add add) {
  const Mat3 c1 = s.f1->rotation * cut_frame(cut.axis1, cut.ref1);
  const Mat3 c2 = s.f2->rotation * cut_frame(cut.axis2, cut.ref2);
  Vec4 w[3];
  orientation_rows(euler_parameters_from_rotation(c1), euler_parameters_from_rotation(c2), w);
  for (int k = 0; k < 3; ++k) {
    Constraint c = cut_constraint(Constraint::Type::kOrientation, s);
    c.w = w[k];
    add(c, std::string("frames aligned about ") + "xyz"[k]);
  }
}

}  // namespace

void add_cut_constraints(const ModelIndex& index, System& sys) {
  for (const auto& cut : index.model.cuts) {
    const auto p1 = point_of(index, sys, cut.body1, cut.point1, cut.where, "body1");
    const auto p2 = point_of(index, sys, cut.body2, cut.point2, cut.where, "body2");
    const CutSides s{p1.first, p2.first, p1.second, p2.second};
    auto add = [&](Constraint c, const std::string& what) {
      c.owner = Constraint::Owner::kCut;
      c.owner_name = cut.name;
      c.label = "cut " + cut.name + ": " + what;
      sys.constraints.push_back(c);
    };
    const Vec3 a1 = s.f1->local_vector(cut.axis1.normalized());
    const Vec3 a2 = s.f2->local_vector(cut.axis2.normalized());
    auto dot1 = [&](const Vec3& u, const Vec3& w, const std::string& what) {
      Constraint c = cut_constraint(Constraint::Type::kDot1, s);
      c.ai = u;
      c.aj = w;
      add(c, what);
    };
    const Constraint pt = cut_constraint(Constraint::Type::kPoint, s);
    switch (cut.type) {
      case CutSpec::Type::kBall: add(pt, "coincident points"); break;
      case CutSpec::Type::kRevolute: {
        // Two unit vectors of body 2 perpendicular to its axis.
        const Vec3 n1 = a2.unitOrthogonal(), n2 = a2.cross(n1);
        add(pt, "coincident points");
        dot1(a1, n1, "axis1 _|_ n1");
        dot1(a1, n2, "axis1 _|_ n2");
        break;
      }
      case CutSpec::Type::kUniversal:
        add(pt, "coincident points");
        dot1(a1, a2, "axis1 _|_ axis2");
        break;
      case CutSpec::Type::kWeld:
        add(pt, "coincident points");
        add_frame_alignment(cut, s, add);
        break;
      case CutSpec::Type::kPrismatic: {
        add_frame_alignment(cut, s, add);
        const Vec3 m1 = a1.unitOrthogonal(), m2 = a1.cross(m1);
        for (const Vec3& m : {m1, m2}) {
          Constraint c = cut_constraint(Constraint::Type::kDot2, s);
          c.ai = m;
          add(c, "no offset across the axis");
        }
        break;
      }
      case CutSpec::Type::kDistance: {
        Constraint c = cut_constraint(Constraint::Type::kDistance, s);
        c.distance = cut.distance;
        add(c, "distance");
        break;
      }
    }
  }
}

}  // namespace mbdae
