// Stage 3 of build_system(): each tree joint's coordinates (functions of the two bodies' poses),
// and, for a joint that is not merged, the Cartesian constraints that leave free exactly the
// motions of its chain, plus a coordinate constraint per locked or driven coordinate.
#include <algorithm>
#include <set>

#include "formulation/system_build.h"

namespace mbdae {
namespace {

const char* kAxisName = "xyz";

int third_axis(int a, int b) { return 3 - a - b; }

// The joint coordinates of a chain, appended to sys.coordinates.
void add_chain_coordinates(const ModelIndex& index, const JointSpec& j, const ChainParts& parts,
                           const CoordinateFunction& base, bool merged, System& sys) {
  int rot_seen = 0;
  for (const auto& e : j.chain) {
    JointCoordinate jc;
    jc.name = e.coordinate;
    jc.joint = j.name;
    jc.spec = index.model.coordinates.at(e.coordinate);
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
    sys.coordinates.push_back(jc);
  }
}

// The constraints of a joint that is not merged: rotations about the chain's axes and
// translations along them stay free.
void add_chain_constraints(const JointSpec& j, const ChainParts& parts, const CoordinateFunction& f,
                           System& sys) {
  const int bp = f.body_parent, bc = f.body_child;
  auto label = [&](const std::string& what) {
    return "joint " + j.name + " (" + chain_text(j.chain) + "): " + what;
  };
  const auto& ax = parts.rot;
  auto dot1 = [&](int m, int n) {
    Constraint c;
    c.type = Constraint::Type::kDot1;
    c.bi = bp;
    c.bj = bc;
    c.ai = f.frame_parent.col(m);
    c.aj = f.frame_child.col(n);
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
  if (parts.trans.empty()) {
    Constraint c;
    c.type = Constraint::Type::kPoint;
    c.bi = bc;
    c.si = f.origin;
    c.bj = bp;
    c.sj = f.anchor;
    c.label = label("origin at anchor");
    sys.constraints.push_back(c);
    return;
  }
  for (int m = 0; m < 3; ++m) {
    if (std::find(parts.trans.begin(), parts.trans.end(), m) != parts.trans.end()) continue;
    Constraint c;
    c.type = Constraint::Type::kDot2;
    if (parts.rotations_first) {
      // Offset measured in the child frame: (A_c e_m).(anchor - origin) = 0.
      c.bi = bc;
      c.ai = f.frame_child.col(m);
      c.si = f.origin;
      c.bj = bp;
      c.sj = f.anchor;
    } else {
      c.bi = bp;
      c.ai = f.frame_parent.col(m);
      c.si = f.anchor;
      c.bj = bc;
      c.sj = f.origin;
    }
    c.label = label(std::string("no offset along ") + kAxisName[m]);
    sys.constraints.push_back(c);
  }
}

}  // namespace

void add_joint_constraints(const ModelIndex& index, System& sys) {
  for (const JointSpec* jp : index.tree.order) {
    const JointSpec& j = *jp;
    const BodyFrame& fp = sys.frames[j.parent];
    const BodyFrame& fc = sys.frames[j.child];
    const bool merged = index.tree.host.at(j.child) == index.tree.host.at(j.parent);
    const ChainParts parts = split_chain(j.chain);
    CoordinateFunction base;
    base.body_parent = fp.body;
    base.body_child = fc.body;
    base.frame_parent = fp.rotation;
    base.frame_child = fc.rotation;
    base.anchor = fp.local_point(index.anchor_of(j));
    base.origin = fc.local_point(Vec3::Zero());
    add_chain_coordinates(index, j, parts, base, merged, sys);
    if (merged) continue;
    const size_t first = sys.constraints.size();
    add_chain_constraints(j, parts, base, sys);
    for (size_t k = first; k < sys.constraints.size(); ++k) {
      sys.constraints[k].owner = Constraint::Owner::kJoint;
      sys.constraints[k].owner_name = j.name;
    }
  }
  // Locked and driven coordinates of joints that were not merged.
  for (int k = 0; k < static_cast<int>(sys.coordinates.size()); ++k) {
    const JointCoordinate& jc = sys.coordinates[k];
    if (jc.merged || jc.spec.mode == CoordinateSpec::Mode::kFree) continue;
    Constraint c = hold_constraint(sys, k, jc.spec.initial);
    if (jc.spec.mode == CoordinateSpec::Mode::kDriven) {
      c.owner = Constraint::Owner::kDrive;
      c.target = jc.spec.drive;
      c.label = "drive " + jc.name + " = " + jc.spec.drive.describe();
    } else {
      c.owner = Constraint::Owner::kLock;
      c.label = "lock " + jc.name;
    }
    sys.constraints.push_back(c);
  }
}

}  // namespace mbdae
