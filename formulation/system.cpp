#include "formulation/system.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <set>

#include "core/errors.h"
#include "formulation/forces.h"

namespace mbdae {
namespace {

const char* kAxisName = "xyz";

[[noreturn]] void fail(const SourceLocation& w, const std::string& field, const std::string& m) {
  throw ModelError(w.file, w.line, field, m);
}

std::string chain_text(const std::vector<ElementaryJoint>& chain) {
  std::string s;
  for (const auto& e : chain) {
    if (!s.empty()) s += ' ';
    s += (e.rotation ? 'R' : 'T');
    s += static_cast<char>('1' + e.axis);
  }
  return s.empty() ? "weld" : s;
}

// Pose of a chain's child frame in its parent frame for the given coordinate values.
void chain_pose(const std::vector<ElementaryJoint>& chain, const std::vector<double>& values,
                Mat3& rot, Vec3& pos) {
  rot = Mat3::Identity();
  pos = Vec3::Zero();
  for (size_t k = 0; k < chain.size(); ++k) {
    if (chain[k].rotation)
      rot = rot * axis_rotation(chain[k].axis, values[k]);
    else
      pos += rot.col(chain[k].axis) * values[k];
  }
}

// Splits a chain into its translations and rotations; rejects interleaving.
struct ChainParts {
  std::vector<int> rot, trans;  // axes
  bool rotations_first = false;
};
ChainParts split_chain(const JointSpec& j) {
  ChainParts parts;
  int switches = 0;
  for (size_t k = 0; k < j.chain.size(); ++k) {
    if (k > 0 && j.chain[k].rotation != j.chain[k - 1].rotation) ++switches;
    (j.chain[k].rotation ? parts.rot : parts.trans).push_back(j.chain[k].axis);
  }
  if (switches > 1)
    fail(j.where, "chain",
         "joint '" + j.name + "' chain " + chain_text(j.chain) +
             " interleaves rotations and translations; split it with an intermediate body");
  parts.rotations_first = !j.chain.empty() && j.chain.front().rotation;
  auto distinct = [&](const std::vector<int>& axes, const char* what) {
    std::set<int> s(axes.begin(), axes.end());
    if (s.size() != axes.size())
      fail(j.where, "chain",
           "joint '" + j.name + "' chain " + chain_text(j.chain) + " repeats a " + what +
               " axis (proper Euler sequences are not supported)");
  };
  distinct(parts.rot, "rotation");
  distinct(parts.trans, "translation");
  return parts;
}

int third_axis(int a, int b) { return 3 - a - b; }


// Bodies whose state sensor `s` reads (ground and merged coordinates read none).
void sensor_bodies(const System& sys, const Sensor& s, std::vector<int>& out) {
  switch (s.type) {
    case SensorSpec::Type::kCoordinate:
    case SensorSpec::Type::kCoordinateRate: {
      const JointCoordinate& jc = sys.coordinates[s.target];
      if (jc.merged) return;
      out.push_back(jc.function.body_parent);
      out.push_back(jc.function.body_child);
      return;
    }
    case SensorSpec::Type::kForceLength:
    case SensorSpec::Type::kForceValue:
      out.push_back(sys.forces[s.target].bi);
      out.push_back(sys.forces[s.target].bj);
      return;
    default: out.push_back(s.body); return;
  }
}

// Compiles a load's expression components: variables t, its parameters, and sensors of the
// kinds whose gradient is known (sensors.cpp, sensor_gradient).
void resolve_load_expressions(const ForceSpec& fs, const System& sys, const std::vector<char>& is_expression_load,
                              Force& f) {
  if (fs.expression[0].empty() && fs.expression[1].empty() && fs.expression[2].empty()) return;
  const int np = static_cast<int>(f.parameter_names.size());
  for (const auto& pname : f.parameter_names)
    if (Expression::is_reserved(pname))
      fail(fs.where, "parameters." + pname, "'" + pname + "' is reserved in expressions (" + Expression::reserved_list() + ")");
  auto lookup = [&](const std::string& n) -> int {
    if (n == "t") return 0;
    for (int k = 0; k < np; ++k)
      if (f.parameter_names[k] == n) return 1 + k;
    int s = -1;
    for (size_t k = 0; k < sys.sensors.size(); ++k)
      if (sys.sensors[k].name == n) s = static_cast<int>(k);
    if (s < 0) return -1;
    using T = SensorSpec::Type;
    const Sensor& sensor = sys.sensors[s];
    const T type = sensor.type;
    if (type == T::kAcceleration || type == T::kExpression || type == T::kKineticEnergy ||
        type == T::kPotentialEnergy)
      throw ExpressionError("sensor '" + n + "' cannot drive a load (loads read position, velocity, axis, "
                            "coordinate, coordinate_rate, force_length and force_value sensors)", 0);
    if ((type == T::kForceLength || type == T::kForceValue) &&
        is_expression_load[sensor.target])
      throw ExpressionError("sensor '" + n + "' measures a load given by an expression (loads may not depend on each other)", 0);
    auto it = std::find(f.inputs.begin(), f.inputs.end(), s);
    if (it == f.inputs.end()) f.inputs.push_back(s);
    return 1 + np + static_cast<int>(std::find(f.inputs.begin(), f.inputs.end(), s) - f.inputs.begin());
  };
  for (int c = 0; c < 3; ++c) {
    if (fs.expression[c].empty()) continue;
    const char* field = fs.type == ForceSpec::Type::kTorque ? "torque" : c == 0 ? "fx" : c == 1 ? "fy" : "fz";
    try {
      f.expression[c] = Expression::compile(fs.expression[c], lookup);
    } catch (const ExpressionError& e) {
      fail(fs.where, field, std::string(e.what()) + " (names are t, the force's parameters and sensors)");
    }
  }
  for (int s : f.inputs) sensor_bodies(sys, sys.sensors[s], f.reads);
  f.reads.erase(std::remove(f.reads.begin(), f.reads.end(), -1), f.reads.end());
  std::sort(f.reads.begin(), f.reads.end());
  f.reads.erase(std::unique(f.reads.begin(), f.reads.end()), f.reads.end());
  if (static_cast<int>(f.reads.size()) > kMaxLoadReads)
    fail(fs.where, "type", "the load's expressions read " + std::to_string(f.reads.size()) + " bodies (at most " +
                               std::to_string(kMaxLoadReads) + ")");
  if (1 + np + static_cast<int>(f.inputs.size()) > kMaxLoadVariables)
    fail(fs.where, "parameters", "the load's expressions use more than " + std::to_string(kMaxLoadVariables) +
                                     " parameters and sensors");
}
}  // namespace

int System::num_constraint_rows() const {
  int n = 0;
  for (const auto& c : constraints) n += c.rows();
  return n;
}

int System::coordinate_index(const std::string& name) const {
  for (size_t k = 0; k < coordinates.size(); ++k)
    if (coordinates[k].name == name) return static_cast<int>(k);
  return -1;
}

int System::force_index(const std::string& name) const {
  for (size_t k = 0; k < forces.size(); ++k)
    if (forces[k].name == name) return static_cast<int>(k);
  return -1;
}

std::vector<double> System::breakpoints() const {
  std::vector<double> t;
  auto add = [&](const TimeFunction& f) {
    for (double b : f.breakpoints()) t.push_back(b);
  };
  for (const auto& c : constraints)
    if (c.type == Constraint::Type::kCoordinate) add(c.target);
  for (const auto& f : forces) {
    add(f.fx);
    add(f.fy);
    add(f.fz);
    add(f.ground);
  }
  std::sort(t.begin(), t.end());
  t.erase(std::unique(t.begin(), t.end()), t.end());
  return t;
}

Constraint hold_constraint(const System& sys, int k, double value) {
  const JointCoordinate& jc = sys.coordinates[k];
  Constraint c;
  c.type = Constraint::Type::kCoordinate;
  c.coord = jc.function;
  c.bi = jc.function.body_parent;
  c.bj = jc.function.body_child;
  c.target = TimeFunction::constant(value);
  c.label = "hold " + jc.name;
  return c;
}

double coordinate_value(const System& sys, int k, const double* q) {
  const JointCoordinate& jc = sys.coordinates[k];
  if (jc.merged) return jc.value_if_merged;
  const LocalState s = gather(q, jc.function.body_parent, jc.function.body_child);
  return coordinate_jet(jc.function, s).value;
}

double coordinate_rate(const System& sys, int k, const double* q, const double* v) {
  const JointCoordinate& jc = sys.coordinates[k];
  if (jc.merged) return 0.0;
  const LocalState s = gather(q, jc.function.body_parent, jc.function.body_child);
  return coordinate_jet(jc.function, s).grad.dot(
      gather_local(v, jc.function.body_parent, jc.function.body_child));
}

System build_system(const Model& model) {
  System sys;
  sys.name = model.name;
  sys.gravity = model.gravity;

  // --- Bodies and the joint tree -------------------------------------------------------------
  std::map<std::string, const BodySpec*> body_by_name;
  for (const auto& b : model.bodies) {
    if (b.name == kGround) fail(b.where, "name", "'ground' is reserved");
    if (!body_by_name.emplace(b.name, &b).second)
      fail(b.where, "name", "body '" + b.name + "' is defined twice");
  }
  std::map<std::string, const JointSpec*> joint_of_child;
  for (const auto& j : model.joints) {
    if (j.parent != kGround && !body_by_name.count(j.parent))
      fail(j.where, "parent", "joint '" + j.name + "': no body named '" + j.parent + "'");
    if (!body_by_name.count(j.child))
      fail(j.where, "child", "joint '" + j.name + "': no body named '" + j.child + "'");
    if (!joint_of_child.emplace(j.child, &j).second)
      fail(j.where, "child", "body '" + j.child + "' is the child of two tree joints; make one a cut");
    for (const auto& e : j.chain)
      if (!model.coordinates.count(e.coordinate))
        fail(j.where, "coordinates", "joint '" + j.name + "': coordinate '" + e.coordinate + "' has no entry");
  }
  // Order bodies from ground outwards; detect loops and bodies with no path to ground.
  std::vector<const JointSpec*> order;
  std::set<std::string> placed = {kGround};
  {
    // Breadth-first from ground over the joints by parent (linear in the number of joints).
    std::map<std::string, std::vector<const JointSpec*>> by_parent;
    for (const auto& j : model.joints) by_parent[j.parent].push_back(&j);
    std::vector<std::string> frontier = {kGround};
    while (!frontier.empty()) {
      std::vector<std::string> next;
      for (const auto& parent : frontier)
        for (const JointSpec* j : by_parent[parent])
          if (placed.insert(j->child).second) {
            order.push_back(j);
            next.push_back(j->child);
          }
      frontier.swap(next);
    }
  }
  for (const auto& b : model.bodies)
    if (!placed.count(b.name)) {
      const JointSpec* j = joint_of_child.count(b.name) ? joint_of_child[b.name] : nullptr;
      if (j)
        fail(j->where, "parent", "body '" + b.name + "' has no path to ground (the joint tree has a loop)");
      fail(b.where, "name", "body '" + b.name + "' has no joint to a parent (no path to ground)");
    }

  auto coordinate_values = [&](const JointSpec& j) {
    std::vector<double> v;
    for (const auto& e : j.chain) v.push_back(model.coordinates.at(e.coordinate).initial);
    return v;
  };
  auto anchor_of = [&](const JointSpec& j) -> Vec3 {
    if (j.anchor_point.empty()) return j.anchor;
    const auto& pts = j.parent == kGround ? model.ground_points : body_by_name[j.parent]->points;
    auto it = pts.find(j.anchor_point);
    if (it == pts.end())
      fail(j.where, "anchor", "body '" + j.parent + "' has no point '" + j.anchor_point + "'");
    return it->second;
  };

  // World pose of every body frame at the initial guess, and merging of locked joints.
  struct Pose {
    Mat3 rot = Mat3::Identity();
    Vec3 pos = Vec3::Zero();
  };
  std::map<std::string, Pose> world;
  world[kGround] = Pose{};
  std::map<std::string, std::string> host_of = {{kGround, kGround}};
  std::map<std::string, Pose> in_host;  // body frame in its host's frame
  in_host[kGround] = Pose{};
  std::vector<std::string> hosts;  // moving hosts in order
  for (const JointSpec* j : order) {
    Mat3 r;
    Vec3 t;
    chain_pose(j->chain, coordinate_values(*j), r, t);
    const Vec3 anchor = anchor_of(*j);
    const Pose& wp = world[j->parent];
    world[j->child] = Pose{wp.rot * r, wp.pos + wp.rot * (anchor + t)};
    bool merge = true;
    for (const auto& e : j->chain)
      if (model.coordinates.at(e.coordinate).mode != CoordinateSpec::Mode::kLocked) merge = false;
    if (merge) {
      const std::string& h = host_of[j->parent];
      host_of[j->child] = h;
      const Pose& ph = in_host[j->parent];
      in_host[j->child] = Pose{ph.rot * r, ph.pos + ph.rot * (anchor + t)};
    } else {
      host_of[j->child] = j->child;
      in_host[j->child] = Pose{};
      hosts.push_back(j->child);
    }
  }

  // Composite mass properties of each moving host, in its own frame.
  std::map<std::string, int> host_index;
  std::map<std::string, Vec3> host_com;
  // Members of each host, gathered once (a loop over all bodies per host is quadratic).
  std::map<std::string, std::vector<const BodySpec*>> members;
  for (const auto& b : model.bodies) members[host_of[b.name]].push_back(&b);
  for (const auto& h : hosts) {
    double m = 0;
    Vec3 mc = Vec3::Zero();
    for (const BodySpec* bp : members[h])
      if (const BodySpec& b = *bp; true) {
        const Pose& p = in_host[b.name];
        m += b.mass;
        mc += b.mass * (p.rot * b.com + p.pos);
      }
    const Vec3 com = m > 0 ? Vec3(mc / m) : Vec3(in_host[h].rot * body_by_name[h]->com + in_host[h].pos);
    Mat3 inertia = Mat3::Zero();
    SystemBody sb;
    sb.name = h;
    for (const BodySpec* bp : members[h])
      if (const BodySpec& b = *bp; true) {
        const Pose& p = in_host[b.name];
        const Vec3 d = p.rot * b.com + p.pos - com;
        inertia += p.rot * b.inertia * p.rot.transpose() +
                   b.mass * (d.dot(d) * Mat3::Identity() - d * d.transpose());
        if (b.name != h) sb.merged.push_back(b.name);
      }
    sb.mass = m;
    sb.inertia = inertia;
    host_index[h] = static_cast<int>(sys.bodies.size());
    host_com[h] = com;
    sys.bodies.push_back(sb);
    // Initial coordinates: centre of mass and Euler parameters of the host frame.
    const Pose& w = world[h];
    const Vec3 r = w.pos + w.rot * com;
    const Vec4 p = euler_parameters_from_rotation(w.rot);
    for (int k = 0; k < 3; ++k) sys.q0.push_back(r[k]);
    for (int k = 0; k < 4; ++k) sys.q0.push_back(p[k]);
  }
  // Frames of all original bodies.
  sys.frames[kGround] = BodyFrame{};
  for (const auto& b : model.bodies) {
    const std::string& h = host_of[b.name];
    BodyFrame f;
    const Pose& p = in_host[b.name];
    if (h == kGround) {
      f.body = -1;
      f.rotation = world[b.name].rot;
      f.offset = world[b.name].pos;
    } else {
      f.body = host_index[h];
      f.rotation = p.rot;
      f.offset = p.pos - host_com[h];
    }
    sys.frames[b.name] = f;
  }
  for (int b = 0; b < sys.num_bodies(); ++b) {
    Constraint c;
    c.type = Constraint::Type::kNorm;
    c.bi = b;
    c.label = "body " + sys.bodies[b].name + ": Euler parameter norm";
    sys.constraints.push_back(c);
  }

  // --- Tree joints -> Cartesian constraints -------------------------------------------------
  std::set<std::string> coordinate_names;
  for (const JointSpec* jp : order) {
    const JointSpec& j = *jp;
    const BodyFrame& fp = sys.frames[j.parent];
    const BodyFrame& fc = sys.frames[j.child];
    const Vec3 anchor = fp.local_point(anchor_of(j));
    const Vec3 origin = fc.local_point(Vec3::Zero());
    const bool merged = host_of[j.child] == host_of[j.parent];
    const ChainParts parts = split_chain(j);
    // Coordinate functions of this chain.
    CoordinateFunction base;
    base.body_parent = fp.body;
    base.body_child = fc.body;
    base.frame_parent = fp.rotation;
    base.frame_child = fc.rotation;
    base.anchor = anchor;
    base.origin = origin;
    int rot_seen = 0;
    for (const auto& e : j.chain) {
      JointCoordinate jc;
      jc.name = e.coordinate;
      jc.joint = j.name;
      jc.spec = model.coordinates.at(e.coordinate);
      jc.merged = merged;
      jc.value_if_merged = jc.spec.initial;
      CoordinateFunction f = base;
      if (e.rotation) {
        f.rotation = true;
        const auto& ax = parts.rot;
        if (ax.size() == 1) {
          f.ax[0] = ax[0];
          f.ax[1] = (ax[0] + 1) % 3;
          f.ax[2] = (ax[0] + 2) % 3;
          f.index = 0;
        } else if (ax.size() == 2) {
          f.ax[0] = ax[0];
          f.ax[1] = third_axis(ax[0], ax[1]);
          f.ax[2] = ax[1];
          f.index = rot_seen == 0 ? 0 : 2;
        } else {
          f.ax[0] = ax[0];
          f.ax[1] = ax[1];
          f.ax[2] = ax[2];
          f.index = rot_seen;
        }
        ++rot_seen;
      } else {
        f.rotation = false;
        f.axis = e.axis;
        f.child_frame = parts.rotations_first;
      }
      jc.function = f;
      if (!coordinate_names.insert(jc.name).second)
        fail(j.where, "coordinates", "coordinate '" + jc.name + "' is used by two joints");
      sys.coordinates.push_back(jc);
    }
    if (merged) continue;

    const int bp = fp.body, bc = fc.body;
    auto label = [&](const std::string& what) {
      return "joint " + j.name + " (" + chain_text(j.chain) + "): " + what;
    };
    // Orientation: rotations about the listed axes stay free.
    const auto& ax = parts.rot;
    auto dot1 = [&](int m, int n) {
      Constraint c;
      c.type = Constraint::Type::kDot1;
      c.bi = bp;
      c.bj = bc;
      c.ai = fp.rotation.col(m);
      c.aj = fc.rotation.col(n);
      c.label = label(std::string("parent ") + kAxisName[m] + " _|_ child " + kAxisName[n]);
      sys.constraints.push_back(c);
    };
    if (ax.empty()) {
      dot1(0, 1);
      dot1(1, 2);
      dot1(2, 0);
    } else if (ax.size() == 1) {
      dot1((ax[0] + 1) % 3, ax[0]);
      dot1((ax[0] + 2) % 3, ax[0]);
    } else if (ax.size() == 2) {
      dot1(ax[0], ax[1]);
    }
    // Position: translations along the listed axes stay free.
    if (parts.trans.empty()) {
      Constraint c;
      c.type = Constraint::Type::kPoint;
      c.bi = bc;
      c.si = origin;
      c.bj = bp;
      c.sj = anchor;
      c.label = label("origin at anchor");
      sys.constraints.push_back(c);
    } else {
      for (int m = 0; m < 3; ++m) {
        if (std::find(parts.trans.begin(), parts.trans.end(), m) != parts.trans.end()) continue;
        Constraint c;
        c.type = Constraint::Type::kDot2;
        if (parts.rotations_first) {
          // Offset measured in the child frame: (A_c e_m).(anchor - origin) = 0.
          c.bi = bc;
          c.ai = fc.rotation.col(m);
          c.si = origin;
          c.bj = bp;
          c.sj = anchor;
        } else {
          c.bi = bp;
          c.ai = fp.rotation.col(m);
          c.si = anchor;
          c.bj = bc;
          c.sj = origin;
        }
        c.label = label(std::string("no offset along ") + kAxisName[m]);
        sys.constraints.push_back(c);
      }
    }
  }
  // Locked and driven coordinates of joints that were not merged.
  for (int k = 0; k < static_cast<int>(sys.coordinates.size()); ++k) {
    const JointCoordinate& jc = sys.coordinates[k];
    if (jc.merged || jc.spec.mode == CoordinateSpec::Mode::kFree) continue;
    Constraint c = hold_constraint(sys, k, jc.spec.initial);
    if (jc.spec.mode == CoordinateSpec::Mode::kDriven) {
      c.target = jc.spec.drive;
      c.label = "drive " + jc.name + " = " + jc.spec.drive.describe();
    } else {
      c.label = "lock " + jc.name;
    }
    sys.constraints.push_back(c);
  }
  for (const auto& [name, cs] : model.coordinates) {
    if (!coordinate_names.count(name))
      fail(cs.where, name, "coordinate '" + name + "' belongs to no joint");
  }

  // --- Cuts ----------------------------------------------------------------------------------
  auto point_of = [&](const std::string& body, const std::string& point, const SourceLocation& w,
                      const std::string& field) -> std::pair<const BodyFrame*, Vec3> {
    auto it = sys.frames.find(body);
    if (it == sys.frames.end()) fail(w, field, "no body named '" + body + "'");
    if (point.empty() || point == "origin") return {&it->second, it->second.local_point(Vec3::Zero())};
    if (body == kGround) {
      auto gp = model.ground_points.find(point);
      if (gp == model.ground_points.end()) fail(w, field, "ground has no point '" + point + "'");
      return {&it->second, gp->second};
    }
    const BodySpec* b = body_by_name[body];
    if (point == "com") return {&it->second, it->second.local_point(b->com)};
    auto pt = b->points.find(point);
    if (pt == b->points.end()) fail(w, field, "body '" + body + "' has no point '" + point + "'");
    return {&it->second, it->second.local_point(pt->second)};
  };
  for (const auto& cut : model.cuts) {
    // (pairs unpacked by hand: lambdas below capture them, which clang 14 refuses for
    // structured bindings)
    const auto p1 = point_of(cut.body1, cut.point1, cut.where, "body1");
    const auto p2 = point_of(cut.body2, cut.point2, cut.where, "body2");
    const BodyFrame* f1 = p1.first;
    const BodyFrame* f2 = p2.first;
    const Vec3 s1 = p1.second, s2 = p2.second;
    if (f1->body == f2->body)
      fail(cut.where, "body2", "cut '" + cut.name + "' joins two parts of the same rigid body");
    auto add = [&](Constraint c, const std::string& what) {
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

  // --- Forces --------------------------------------------------------------------------------
  for (const auto& fs : model.forces) {
    Force f;
    f.type = fs.type;
    f.name = fs.name;
    // A point given as [x, y, z] in the body frame, or by name.
    auto located = [&](const std::string& body, const std::string& name, bool at_xyz, const Vec3& xyz,
                       const SourceLocation& w, const std::string& field) {
      auto p = point_of(body, at_xyz ? "" : name, w, field);
      if (at_xyz) p.second = p.first->local_point(xyz);
      return p;
    };
    const bool on_coordinate = fs.type == ForceSpec::Type::kJointSpringDamper;  // no body point
    auto [b1, p1] = located(on_coordinate ? kGround : fs.body1, fs.point1, fs.at_xyz1, fs.xyz1, fs.where, "body1");
    f.bi = b1->body;
    f.si = p1;
    if (fs.type == ForceSpec::Type::kSpringDamper || fs.type == ForceSpec::Type::kUser ||
        fs.type == ForceSpec::Type::kBushing) {
      auto [b2, p2] = located(fs.body2, fs.point2, fs.at_xyz2, fs.xyz2, fs.where, "body2");
      f.bj = b2->body;
      f.sj = p2;
      f.frame_j = b2->rotation;
    }
    f.frame_i = b1->rotation;
    f.body_frame = fs.body_frame;
    f.stiffness = fs.stiffness;
    f.damping = fs.damping;
    f.free_length = fs.free_length;
    f.fx = fs.fx;
    f.fy = fs.fy;
    f.fz = fs.fz;
    f.ground = fs.ground;
    f.radius = fs.radius;
    f.axis = b1->local_vector(fs.axis.normalized());
    if (fs.type == ForceSpec::Type::kWheelContact && f.bi < 0)
      fail(fs.where, "body1", "wheel contact on a body merged into ground");
    if (fs.type == ForceSpec::Type::kTorque && !fs.body_frame) f.axis = fs.axis.normalized();
    f.kt = fs.translational_stiffness;
    f.ct = fs.translational_damping;
    f.kr = fs.rotational_stiffness;
    f.cr = fs.rotational_damping;
    if (fs.type == ForceSpec::Type::kBushing && f.bi == f.bj)
      fail(fs.where, "body2", "bushing '" + fs.name + "' joins two parts of the same rigid body");
    if (fs.type == ForceSpec::Type::kJointSpringDamper) {
      const int k = sys.coordinate_index(fs.coordinate);
      if (k < 0) fail(fs.where, "coordinate", "no joint coordinate named '" + fs.coordinate + "'");
      if (sys.coordinates[k].merged)
        fail(fs.where, "coordinate", "coordinate '" + fs.coordinate + "' belongs to a locked joint");
      f.coordinate = sys.coordinates[k].function;
      f.bi = f.coordinate.body_parent;
      f.bj = f.coordinate.body_child;
    }
    for (const auto& [pname, value] : fs.parameters)
      if (fs.type != ForceSpec::Type::kUser) {
        f.parameter_names.push_back(pname);
        f.parameters.push_back(value);
      }
    if (fs.type == ForceSpec::Type::kUser) {
      f.law = find_force_law(fs.law);
      if (!f.law) fail(fs.where, "law", "no force law named '" + fs.law + "' is registered");
      for (const auto& pname : f.law->parameter_names) {
        auto it = fs.parameters.find(pname);
        if (it == fs.parameters.end())
          fail(fs.where, "parameters", "force law '" + fs.law + "' needs parameter '" + pname + "'");
        f.parameters.push_back(it->second);
      }
    }
    if (sys.force_index(f.name) >= 0) fail(fs.where, "name", "force '" + f.name + "' is defined twice");
    sys.forces.push_back(f);
  }

  // --- Sensors -------------------------------------------------------------------------------
  for (const auto& ss : model.sensors) {
    Sensor s;
    s.type = ss.type;
    s.name = ss.name;
    if (Expression::is_reserved(s.name))
      fail(ss.where, "name", "'" + s.name + "' is reserved in expressions (" + Expression::reserved_list() + ")");
    s.component = ss.component;
    switch (ss.type) {
      case SensorSpec::Type::kPosition:
      case SensorSpec::Type::kVelocity:
      case SensorSpec::Type::kAcceleration: {
        auto [b, p] = point_of(ss.body, ss.at_xyz ? "" : ss.point, ss.where, "body");
        s.body = b->body;
        s.point = ss.at_xyz ? b->local_point(ss.xyz) : p;
        break;
      }
      case SensorSpec::Type::kAxis: {
        auto it = sys.frames.find(ss.body);
        if (it == sys.frames.end()) fail(ss.where, "body", "no body named '" + ss.body + "'");
        s.body = it->second.body;
        s.axis = it->second.local_vector(ss.axis);
        break;
      }
      case SensorSpec::Type::kCoordinate:
      case SensorSpec::Type::kCoordinateRate:
        s.target = sys.coordinate_index(ss.target);
        if (s.target < 0) fail(ss.where, "coordinate", "no coordinate named '" + ss.target + "'");
        s.unwrap = ss.type == SensorSpec::Type::kCoordinate && !ss.wrap && sys.coordinates[s.target].function.rotation;
        s.reference = sys.coordinates[s.target].spec.initial;
        break;
      case SensorSpec::Type::kForceLength:
      case SensorSpec::Type::kForceValue:
        s.target = sys.force_index(ss.target);
        if (s.target < 0) fail(ss.where, "force", "no force named '" + ss.target + "'");
        break;
      case SensorSpec::Type::kKineticEnergy:
      case SensorSpec::Type::kPotentialEnergy:
        break;  // whole-system quantities: nothing to resolve
      case SensorSpec::Type::kExpression: {
        const int self = static_cast<int>(sys.sensors.size());
        try {
          s.expression = Expression::compile(ss.expression, [&](const std::string& n) {
            for (int k = 0; k < self; ++k)
              if (sys.sensors[k].name == n) return k;
            return -1;
          });
        } catch (const ExpressionError& e) {
          fail(ss.where, "expression", std::string(e.what()) + " (names must be sensors listed before)");
        }
        break;
      }
    }
    for (const auto& other : sys.sensors)
      if (other.name == s.name) fail(ss.where, "name", "sensor '" + s.name + "' is defined twice");
    sys.sensors.push_back(s);
  }

  // --- Load expressions (after the sensors they read) --------------------------------------
  std::vector<char> is_expression_load;
  for (const auto& fs : model.forces)
    is_expression_load.push_back(!fs.expression[0].empty() || !fs.expression[1].empty() || !fs.expression[2].empty());
  for (size_t k = 0; k < model.forces.size(); ++k)
    resolve_load_expressions(model.forces[k], sys, is_expression_load, sys.forces[k]);
  return sys;
}

}  // namespace mbdae
