// The stages of build_system() (formulation/system.cpp), in the order it runs them:
//   1. resolve_tree          the bodies and joints by name, the joint tree (system_tree.cpp)
//   2. merge_locked_joints   rigid composites, their inertia, frames, q0 (system_bodies.cpp)
//   3. add_joint_constraints tree joints -> coordinates and constraints (system_joints.cpp)
//   4. add_cut_constraints   loop cuts -> constraints (cut_types.cpp)    (system_cuts.cpp)
//   5. add_forces_and_sensors                                           (system_loads.cpp)
// Each stage reads the model (through the index of stage 1) and appends to the System. The
// model has passed check_model() (formulation/model_rules.h) before stage 1: the stages apply
// no rules of their own; what fail() remains guards lookups, and the limits of a load's compiled
// expressions (bodies read, variables), which need the built sensors. Internal to formulation/.
#pragma once

#include <map>
#include <string>
#include <utility>

#include "formulation/joint_tree.h"
#include "formulation/system.h"

namespace mbdae {

// The model with its names resolved (stage 1), read by the later stages.
struct ModelIndex {
  const Model& model;
  std::map<std::string, const BodySpec*> bodies;
  std::map<std::string, const JointSpec*> joint_of_child;
  JointTree tree;

  // The anchor of a tree joint in its parent's frame.
  Vec3 anchor_of(const JointSpec& j) const;
};

[[noreturn]] void fail(const SourceLocation& w, const std::string& field, const std::string& m);

// A body's frame and one of its points ("" or "origin", "com", a named point) in the host's
// local coordinates.
std::pair<const BodyFrame*, Vec3> point_of(const ModelIndex& index, const System& sys,
                                           const std::string& body, const std::string& point,
                                           const SourceLocation& w, const std::string& field);

ModelIndex resolve_tree(const Model& model);
void merge_locked_joints(const ModelIndex& index, System& sys);
void add_joint_constraints(const ModelIndex& index, System& sys);
void add_cut_constraints(const ModelIndex& index, System& sys);
void add_forces_and_sensors(const ModelIndex& index, System& sys);

}  // namespace mbdae
