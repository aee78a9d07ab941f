// An output sink (cases/mbdae.h) that writes the run as a ParaView time series: one VTK XML
// PolyData file per frame, DIR/animation/frame_NNNNNN.vtp, the collection DIR/animation.pvd with
// their times, and DIR/animation/legend.json naming what the codes in the files stand for (the
// names are also the field data of every frame: part_names, body_names, joint_names, cut_names,
// force_names). Binary (zlib-compressed appended data) unless the scene asks for ASCII.
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

// Checks before a run that its animation into `dir` fits: the frames it may write (max_frames, or
// fewer from the frame rate and the time span) times an upper bound of a frame's size
// (vtp_size_bound of the first frame) must be within the scene's disk_budget_mb (ModelError
// naming the field, exit code 2) and the free space of dir's file system (statvfs; OutputError,
// exit code 4). `frame_rate` > 0 overrides the scene's. docs/animation.md ("Size").
void check_animation_size(const Scene& scene, const std::string& dir, double frame_rate = 0);

// Removes what an earlier run's animation left in `dir`: animation.pvd (when it is mbdae's: a
// collection of animation/frame_NNNNNN.vtp), animation/frame_NNNNNN.vtp, animation/legend.json,
// their temporary files (.tmp, .partial), and animation/ when that leaves it empty. Other files
// stay.
void remove_animation_files(const std::string& dir);

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
  PvdAppender pvd_;  // DIR/animation.pvd, one line per frame
  VtkPolyData data_;
  VtkScratch scratch_;
  // The last sample not written as a frame (written at the end, so the run's end is shown).
  std::vector<double> last_q_, last_v_;
  std::vector<char> last_modes_;
  double last_t_ = 0, last_input_time_ = 0;
  bool last_pending_ = false;
};

}  // namespace mbdae
