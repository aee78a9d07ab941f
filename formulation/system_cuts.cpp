// Stage 4 of build_system(): each loop cut becomes the constraints of its type between the two
// bodies' points and frames.
#include "formulation/system_build.h"

namespace mbdae {

void add_cut_constraints(const ModelIndex& index, System& sys) {
  const Model& model = index.model;
  for (const auto& cut : model.cuts) {
    // (pairs unpacked by hand: lambdas below capture them, which clang 14 refuses for
    // structured bindings)
    const auto p1 = point_of(index, sys, cut.body1, cut.point1, cut.where, "body1");
    const auto p2 = point_of(index, sys, cut.body2, cut.point2, cut.where, "body2");
    const BodyFrame* f1 = p1.first;
    const BodyFrame* f2 = p2.first;
    const Vec3 s1 = p1.second, s2 = p2.second;
    if (f1->body == f2->body)
      fail(cut.where, "body2", "cut '" + cut.name + "' joins two parts of the same rigid body");
    auto add = [&](Constraint c, const std::string& what) {
      c.owner = Constraint::Owner::kCut;
      c.owner_name = cut.name;
      c.label = "cut " + cut.name + ": " + what;
      sys.constraints.push_back(c);
    };
    Constraint pt;
    pt.type = Constraint::Type::kPoint;
    pt.bi = f1->body;
    pt.si = s1;
    pt.bj = f2->body;
    pt.sj = s2;
    const Vec3 a1 = f1->local_vector(cut.axis1.normalized()), a2 = f2->local_vector(cut.axis2.normalized());
    // Two unit vectors of body 2 perpendicular to its axis.
    Vec3 n1 = a2.unitOrthogonal(), n2 = a2.cross(n1);
    auto dot1 = [&](const Vec3& u, const Vec3& w, const std::string& what) {
      Constraint c;
      c.type = Constraint::Type::kDot1;
      c.bi = f1->body;
      c.ai = u;
      c.bj = f2->body;
      c.aj = w;
      add(c, what);
    };
    switch (cut.type) {
      case CutSpec::Type::kBall: add(pt, "coincident points"); break;
      case CutSpec::Type::kRevolute:
        add(pt, "coincident points");
        dot1(a1, n1, "axis1 _|_ n1");
        dot1(a1, n2, "axis1 _|_ n2");
        break;
      case CutSpec::Type::kUniversal:
        add(pt, "coincident points");
        dot1(a1, a2, "axis1 _|_ axis2");
        break;
      case CutSpec::Type::kWeld: {
        add(pt, "coincident points");
        const Mat3 r1 = f1->rotation, r2 = f2->rotation;
        dot1(r1.col(0), r2.col(1), "x1 _|_ y2");
        dot1(r1.col(1), r2.col(2), "y1 _|_ z2");
        dot1(r1.col(2), r2.col(0), "z1 _|_ x2");
        break;
      }
      case CutSpec::Type::kPrismatic: {
        const Mat3 r1 = f1->rotation, r2 = f2->rotation;
        dot1(r1.col(0), r2.col(1), "x1 _|_ y2");
        dot1(r1.col(1), r2.col(2), "y1 _|_ z2");
        dot1(r1.col(2), r2.col(0), "z1 _|_ x2");
        const Vec3 m1 = a1.unitOrthogonal(), m2 = a1.cross(m1);
        for (const Vec3& m : {m1, m2}) {
          Constraint c;
          c.type = Constraint::Type::kDot2;
          c.bi = f1->body;
          c.ai = m;
          c.si = s1;
          c.bj = f2->body;
          c.sj = s2;
          add(c, "no offset across the axis");
        }
        break;
      }
      case CutSpec::Type::kDistance: {
        Constraint c;
        c.type = Constraint::Type::kDistance;
        c.bi = f1->body;
        c.si = s1;
        c.bj = f2->body;
        c.sj = s2;
        c.distance = cut.distance;
        add(c, "distance");
        break;
      }
    }
  }
}

}  // namespace mbdae
