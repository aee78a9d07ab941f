// An output sink (cases/mbdae.h) that writes the run as a ParaView time series: one VTK XML
// PolyData file per frame, DIR/animation/frame_NNNNNN.vtp, the collection DIR/animation.pvd with
// their times, and DIR/animation/legend.json naming what the codes in the files stand for.
// Each frame draws every body's frame (origin and axes), its named points and the lines joining
// them, joints and loop cuts as points, force elements as lines with their force, point and
// contact forces as vectors, and the scene's shapes as polygons (docs/animation.md).
//
//   mbdae::AnimationSink anim(scene, "out");
//   mbdae::Result r = mbdae::run(scene, options, {&anim});
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "cases/mbdae.h"
#include "core/vtk_xml.h"

namespace mbdae {

struct AnimationPlan;  // what is drawn, resolved once against the System (animation_sink.cpp)

// The `part` codes of the cells (cell field "part"), as listed in legend.json.
enum class AnimationPart {
  kAxis = 0, kBodyLine = 1, kBodyPoint = 2, kJoint = 3, kCut = 4, kForceLine = 5, kForceVector = 6, kShape = 7,
  kGround = 8  // the ground under a wheel contact: a line of the wheel's diameter at the ground height
};

class AnimationSink : public Sink {
 public:
  // `scene` must outlive the sink; `frame_rate` > 0 overrides the scene's.
  AnimationSink(const Scene& scene, std::string dir, double frame_rate = 0);
  ~AnimationSink() override;
  void begin(const RunInfo& info) override;
  void sample(const Sample& s) override;
  void end(const Result& result) override;
  int frames() const { return static_cast<int>(entries_.size()); }

 private:
  void write_frame(double t, const double* q, const double* v, const std::vector<char>& modes, double input_time);
  void write_collection();
  void start(std::unique_ptr<System> system, double t0, double t_end);
  void write_static_frame(const Result& result);

  const Scene& scene_;
  std::string dir_;
  AnimationSpec spec_;
  // A copy of the run's System as begin() saw it (with parameters solved by an equilibrium): the
  // run's own is gone when end() draws the last sample. For a scene without integration, the
  // System built from the scene in end().
  std::unique_ptr<System> system_;
  std::unique_ptr<AnimationPlan> plan_;
  double frame_step_ = 0, next_time_ = 0;
  std::vector<PvdEntry> entries_;
  VtkPolyData data_;
  // The last sample not written as a frame (written at the end, so the run's end is shown).
  std::vector<double> last_q_, last_v_;
  std::vector<char> last_modes_;
  double last_t_ = 0, last_input_time_ = 0;
  bool last_pending_ = false;
};

}  // namespace mbdae
