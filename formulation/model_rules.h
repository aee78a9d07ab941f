// The rules of a valid model, in one place (issue 22): the loader (cases/scene/scene_validation,
// which adds the rules of the scene around the model: outputs and analysis steps, and places each
// problem at its field's line), `mbdae check`, and build_system (which refuses a model at its
// first problem) all apply them. References between bodies, points, joints, coordinates, cuts,
// forces and sensors; the joint tree (loops, bodies without a path to ground, bodies welded
// together); load and sensor expressions. The chain and tree rules themselves (which chains are
// refused, the tree order, which joints merge bodies) are formulation/joint_tree.h's.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "formulation/joint_tree.h"
#include "formulation/model.h"

namespace mbdae {

// One problem of a model: the item (its SourceLocation), the field that locates the line within
// it (it may carry an index, "coordinates[1]"), and the field as shown in the message (without
// the index, or `shown` when given).
struct ModelIssue {
  SourceLocation item;
  std::string field;
  std::string message;
  std::string shown;
  std::string shown_field() const;
};

// The names a model defines, for the rules of the scene around it (outputs, analysis steps).
// Pointers into the checked Model, valid while it lives.
struct ModelNames {
  std::map<std::string, const BodySpec*> bodies;
  std::map<std::string, const JointSpec*> joint_of_child;       // the tree joint of each body
  std::map<std::string, const JointSpec*> joint_of_coordinate;  // coordinates used by joints
  std::map<std::string, const ForceSpec*> forces;
  std::map<std::string, size_t> sensor_index;  // first sensor of each name
  JointTree tree;  // order, bodies with a path to ground, merged bodies
};

// Every problem of `m`, in the order of the model's sections; `names` (if given) receives the
// names it defines.
std::vector<ModelIssue> check_model(const Model& m, ModelNames* names = nullptr);

// "; did you mean 'x'?" if one of `candidates` is within a small edit distance of `name`.
std::string did_you_mean(const std::string& name, const std::vector<std::string>& candidates);

}  // namespace mbdae
