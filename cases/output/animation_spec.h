// The scene's `animation` section (docs/animation.md): when and how densely the run is written as
// a ParaView time series, and the simple shapes drawn on bodies. A model file may give it too
// (shapes); the scene's fields then override the model's.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "core/vtk_xml.h"
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

// Frames at most: 1e5 frames of the suspension are 0.4 GB binary, 1.3 GB ASCII (docs/animation.md).
inline constexpr int kMaxAnimationFrames = 100000;

struct AnimationSpec {
  bool write = false;       // write the animation without --animation
  double frame_rate = 60;   // frames per second of simulated time
  int max_frames = 2000;    // cap: the frame step grows to keep the frame count under it
  double disk_budget_mb = 1000;  // the frames' size bound may not exceed it (megabytes, 1e6 bytes)
  VtkFormat format = VtkFormat::kBinary;  // `format: binary` (zlib-compressed) or `ascii`
  SourceLocation section, frame_rate_at, max_frames_at, disk_budget_at;  // line 0: not given
  double start = -std::numeric_limits<double>::infinity();  // window of simulated time
  double end = std::numeric_limits<double>::infinity();
  double axis_length = 0;   // drawn body axes [m]; 0: a tenth of the mechanism's extent
  std::vector<AnimationShape> shapes;
};

}  // namespace mbdae
