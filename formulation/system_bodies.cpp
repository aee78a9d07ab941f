// Stage 2 of build_system(): bodies joined by merged (locked or welded) tree joints become one
// rigid composite (mass, centre of mass and inertia summed with the parallel-axis theorem, in
// the host's frame); the frame of every original body on its host; the initial guess q0 from the
// joint coordinates' initial values; one Euler-parameter norm constraint per moving body.
#include "formulation/system_build.h"

namespace mbdae {
namespace {

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

struct Pose {
  Mat3 rot = Mat3::Identity();
  Vec3 pos = Vec3::Zero();
};

// World pose of every body frame at the initial coordinates, and each body's pose in its host.
struct Poses {
  std::map<std::string, Pose> world, in_host;
  std::vector<std::string> hosts;  // moving hosts, from ground outwards
};

Poses initial_poses(const ModelIndex& index) {
  const Model& model = index.model;
  Poses out;
  out.world[kGround] = Pose{};
  out.in_host[kGround] = Pose{};
  for (const JointSpec* j : index.tree.order) {
    std::vector<double> values;
    for (const auto& e : j->chain) values.push_back(model.coordinates.at(e.coordinate).initial);
    Mat3 r;
    Vec3 t;
    chain_pose(j->chain, values, r, t);
    const Vec3 anchor = index.anchor_of(*j);
    const Pose& wp = out.world[j->parent];
    out.world[j->child] = Pose{wp.rot * r, wp.pos + wp.rot * (anchor + t)};
    if (index.tree.host.at(j->child) != j->child) {
      const Pose& ph = out.in_host[j->parent];
      out.in_host[j->child] = Pose{ph.rot * r, ph.pos + ph.rot * (anchor + t)};
    } else {
      out.in_host[j->child] = Pose{};
      out.hosts.push_back(j->child);
    }
  }
  return out;
}

// Where each moving host is: its index in sys.bodies and its centre of mass in its own frame.
struct Hosts {
  std::map<std::string, int> index;
  std::map<std::string, Vec3> com;
};

// Composite mass properties of each moving host, in its own frame, and its initial coordinates
// (centre of mass and Euler parameters of the host frame).
Hosts add_composite_bodies(const ModelIndex& index, Poses& poses, System& sys) {
  Hosts hosts;
  auto& in_host = poses.in_host;
  // Members of each host, gathered once (a loop over all bodies per host is quadratic).
  std::map<std::string, std::vector<const BodySpec*>> members;
  for (const auto& b : index.model.bodies) members[index.tree.host.at(b.name)].push_back(&b);
  for (const auto& h : poses.hosts) {
    double m = 0;
    Vec3 mc = Vec3::Zero();
    for (const BodySpec* b : members[h]) {
      const Pose& p = in_host[b->name];
      m += b->mass;
      mc += b->mass * (p.rot * b->com + p.pos);
    }
    const Vec3 com = m > 0 ? Vec3(mc / m) : Vec3(in_host[h].rot * index.bodies.at(h)->com + in_host[h].pos);
    Mat3 inertia = Mat3::Zero();
    SystemBody sb;
    sb.name = h;
    for (const BodySpec* b : members[h]) {
      const Pose& p = in_host[b->name];
      const Vec3 d = p.rot * b->com + p.pos - com;
      inertia += p.rot * b->inertia * p.rot.transpose() +
                 b->mass * (d.dot(d) * Mat3::Identity() - d * d.transpose());
      if (b->name != h) sb.merged.push_back(b->name);
    }
    sb.mass = m;
    sb.inertia = inertia;
    hosts.index[h] = static_cast<int>(sys.bodies.size());
    hosts.com[h] = com;
    sys.bodies.push_back(sb);
    const Pose& w = poses.world[h];
    const Vec3 r = w.pos + w.rot * com;
    const Vec4 p = euler_parameters_from_rotation(w.rot);
    for (int k = 0; k < 3; ++k) sys.q0.push_back(r[k]);
    for (int k = 0; k < 4; ++k) sys.q0.push_back(p[k]);
  }
  return hosts;
}

}  // namespace

void merge_locked_joints(const ModelIndex& index, System& sys) {
  Poses poses = initial_poses(index);
  Hosts hosts = add_composite_bodies(index, poses, sys);
  // Frames of all original bodies.
  sys.frames[kGround] = BodyFrame{};
  for (const auto& b : index.model.bodies) {
    const std::string& h = index.tree.host.at(b.name);
    BodyFrame f;
    const Pose& p = poses.in_host[b.name];
    if (h == kGround) {
      f.body = -1;
      f.rotation = poses.world[b.name].rot;
      f.offset = poses.world[b.name].pos;
    } else {
      f.body = hosts.index[h];
      f.rotation = p.rot;
      f.offset = p.pos - hosts.com[h];
    }
    sys.frames[b.name] = f;
  }
  for (int b = 0; b < sys.num_bodies(); ++b) {
    Constraint c;
    c.type = Constraint::Type::kNorm;
    c.owner = Constraint::Owner::kNorm;
    c.owner_name = sys.bodies[b].name;
    c.bi = b;
    c.label = "body " + sys.bodies[b].name + ": Euler parameter norm";
    sys.constraints.push_back(c);
  }
}

}  // namespace mbdae
