// The scene's `animation` section (docs/animation.md): when and how densely the run is written as
// a ParaView time series, and the simple shapes drawn on bodies. A model file may give it too
// (shapes); the scene's fields then override the model's.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "formulation/model.h"

namespace mbdae {

// A shape drawn rigidly on a body, in the body frame: a box of `size` (edge lengths along the
// body axes), a cylinder of `radius` and `length` along `axis`, or a sphere of `radius`.
struct AnimationShape {
  enum class Type { kBox, kCylinder, kSphere };
  std::string body;
  Type type = Type::kBox;
  Vec3 center = Vec3::Zero();
  Vec3 axis = Vec3::UnitZ();
  Vec3 size = Vec3::Zero();
  double radius = 0, length = 0;
  SourceLocation where;
};

struct AnimationSpec {
  bool write = false;       // write the animation without --animation
  double frame_rate = 60;   // frames per second of simulated time
  int max_frames = 2000;    // cap: the frame step grows to keep the frame count under it
  double start = -std::numeric_limits<double>::infinity();  // window of simulated time
  double end = std::numeric_limits<double>::infinity();
  double axis_length = 0;   // drawn body axes [m]; 0: a tenth of the mechanism's extent
  std::vector<AnimationShape> shapes;
};

}  // namespace mbdae
