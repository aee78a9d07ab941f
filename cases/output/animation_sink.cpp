#include "cases/output/animation_sink.h"

#include <sys/statvfs.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include "cases/scene/analysis_types.h"
#include "core/errors.h"
#include "core/output.h"
#include "formulation/euler_parameters.h"
#include "formulation/force_types.h"
#include "formulation/forces.h"
#include "formulation/mechanics.h"
#include "formulation/sensors.h"
#include "formulation/system.h"

namespace mbdae {

// A point fixed on a moving body (`host` >= 0, host centre-of-mass coordinates) or on ground
// (host -1, world coordinates).
struct PlanPoint {
  int host = -1;
  Vec3 local = Vec3::Zero();
};

// An original body of the model: its frame on its host, its points (0 = the frame origin).
struct PlanBody {
  std::string name;
  int host = -1;
  Mat3 axes = Mat3::Identity();  // body axes in host coordinates
  std::vector<std::string> point_names;
  std::vector<Vec3> points;  // host coordinates
};

struct PlanShape {
  int body = -1;  // PlanBody index
  std::vector<Vec3> vertices;  // host coordinates
  std::vector<std::vector<int>> faces;
};

struct AnimationPlan {
  std::vector<PlanBody> bodies;
  std::vector<std::string> joint_names, cut_names;
  std::vector<int> joint_body;  // the child's PlanBody index
  std::vector<PlanPoint> joints, cuts;
  std::vector<int> cut_body;
  std::vector<PlanShape> shapes;
  double axis_length = 0;
};

namespace {

constexpr const char* kFolder = "animation";
enum CellField { kPart, kBody, kIndex, kAxis, kForce, kForceMagnitude, kNumCellFields };
const std::vector<std::string> kCellFieldNames = {"part", "body", "index", "axis", "force", "force_magnitude"};

Vec3 world(const PlanPoint& p, const double* q) { return point_position(body_pose(q, p.host), p.local); }

Mat3 host_rotation(int host, const double* q) { return rotation(body_pose(q, host).p); }

int body_index(const AnimationPlan& plan, const std::string& name) {
  for (size_t b = 0; b < plan.bodies.size(); ++b)
    if (plan.bodies[b].name == name) return static_cast<int>(b);
  return -1;
}

// A named point of a model body ("origin", "com" or one of its points), as a PlanPoint.
PlanPoint resolve(const System& sys, const Model& model, const std::string& body, const std::string& point) {
  const BodyFrame& f = sys.frames.at(body);
  Vec3 s = Vec3::Zero();
  for (const auto& b : model.bodies)
    if (b.name == body) {
      if (point == "com") s = b.com;
      else if (b.points.count(point)) s = b.points.at(point);
    }
  return {f.body, f.local_point(s)};
}

// Shape vertices and faces in the body frame.
void box(const AnimationShape& s, PlanShape& out) {
  for (int k = 0; k < 8; ++k)
    out.vertices.push_back(s.center + 0.5 * Vec3((k & 1 ? 1 : -1) * s.size.x(), (k & 2 ? 1 : -1) * s.size.y(),
                                                 (k & 4 ? 1 : -1) * s.size.z()));
  out.faces = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
}

void cylinder(const AnimationShape& s, PlanShape& out) {
  const int n = 32;
  const Vec3 a = s.axis.normalized();
  const Vec3 u = a.unitOrthogonal(), w = a.cross(u);
  std::vector<int> bottom, top;
  for (int side = 0; side < 2; ++side)
    for (int k = 0; k < n; ++k) {
      const double phi = 2 * M_PI * k / n;
      out.vertices.push_back(s.center + (side ? 0.5 : -0.5) * s.length * a +
                             s.radius * (std::cos(phi) * u + std::sin(phi) * w));
    }
  for (int k = 0; k < n; ++k) {
    out.faces.push_back({k, (k + 1) % n, n + (k + 1) % n, n + k});
    bottom.push_back(n - 1 - k);
    top.push_back(n + k);
  }
  out.faces.push_back(bottom);
  out.faces.push_back(top);
}

void sphere(const AnimationShape& s, PlanShape& out) {
  const int rings = 8, n = 16;  // latitude bands, longitude segments
  out.vertices.push_back(s.center - s.radius * Vec3::UnitZ());
  for (int i = 1; i < rings; ++i) {
    const double theta = M_PI * i / rings - M_PI / 2;
    for (int k = 0; k < n; ++k) {
      const double phi = 2 * M_PI * k / n;
      out.vertices.push_back(s.center + s.radius * Vec3(std::cos(theta) * std::cos(phi),
                                                        std::cos(theta) * std::sin(phi), std::sin(theta)));
    }
  }
  out.vertices.push_back(s.center + s.radius * Vec3::UnitZ());
  const int top = static_cast<int>(out.vertices.size()) - 1;
  auto at = [&](int ring, int k) { return 1 + (ring - 1) * n + (k % n); };
  for (int k = 0; k < n; ++k) {
    out.faces.push_back({0, at(1, k + 1), at(1, k)});
    for (int i = 1; i + 1 < rings; ++i) out.faces.push_back({at(i, k), at(i, k + 1), at(i + 1, k + 1), at(i + 1, k)});
    out.faces.push_back({at(rings - 1, k), at(rings - 1, k + 1), top});
  }
}

AnimationPlan make_plan(const System& sys, const Scene& scene) {
  const Model& model = scene.model;
  AnimationPlan plan;
  for (const auto& b : model.bodies) {
    const BodyFrame& f = sys.frames.at(b.name);
    PlanBody pb{b.name, f.body, f.rotation, {"origin"}, {f.local_point(Vec3::Zero())}};
    for (const auto& [name, s] : b.points) {
      pb.point_names.push_back(name);
      pb.points.push_back(f.local_point(s));
    }
    plan.bodies.push_back(pb);
  }
  for (const auto& j : model.joints) {
    plan.joint_names.push_back(j.name);
    plan.joint_body.push_back(body_index(plan, j.child));
    plan.joints.push_back(resolve(sys, model, j.child, "origin"));  // the child frame sits on the anchor
  }
  for (const auto& c : model.cuts) {
    plan.cut_names.push_back(c.name);
    plan.cut_body.push_back(body_index(plan, c.body1));
    plan.cuts.push_back(resolve(sys, model, c.body1, c.point1));
  }
  for (const auto& s : scene.animation.shapes) {
    PlanShape ps;
    ps.body = body_index(plan, s.body);
    if (ps.body < 0) throw std::runtime_error(s.where.file + ":" + std::to_string(s.where.line) +
                                              ": animation shape on '" + s.body + "', which is not a body");
    if (s.type == AnimationShape::Type::kBox) box(s, ps);
    else if (s.type == AnimationShape::Type::kCylinder) cylinder(s, ps);
    else sphere(s, ps);
    const BodyFrame& f = sys.frames.at(s.body);
    for (auto& v : ps.vertices) v = f.local_point(v);
    plan.shapes.push_back(std::move(ps));
  }
  return plan;
}

// A tenth of the extent of the body points at the first frame (1 m if they all coincide).
double automatic_axis_length(const AnimationPlan& plan, const double* q) {
  Eigen::AlignedBox3d box;
  for (const auto& b : plan.bodies)
    for (const auto& s : b.points) box.extend(world({b.host, s}, q));
  const double d = box.isEmpty() ? 0.0 : box.diagonal().norm();
  return d > 0 ? 0.1 * d : 1.0;
}

// Appends points and cells to the frame being drawn.
struct Painter {
  VtkPolyData& data;
  int add_point(const Vec3& x, const Vec3& vector = Vec3::Zero()) {
    for (int k = 0; k < 3; ++k) data.points.push_back(x[k]);
    for (int k = 0; k < 3; ++k) data.point_fields[0].values.push_back(vector[k]);
    return static_cast<int>(data.num_points()) - 1;
  }
  void cell(VtkCells& c, std::initializer_list<int> ids, AnimationPart part, int body, int index, int axis = -1,
            double force = 0) {
    for (int id : ids) c.connectivity.push_back(id);
    close(c, part, body, index, axis, force);
  }
  void close(VtkCells& c, AnimationPart part, int body, int index, int axis = -1, double force = 0) {
    c.offsets.push_back(static_cast<int64_t>(c.connectivity.size()));
    const double values[kNumCellFields] = {static_cast<double>(part), double(body), double(index), double(axis),
                                           force, std::fabs(force)};
    for (int f = 0; f < kNumCellFields; ++f) c.fields[f].push_back(values[f]);
  }
};

void draw_bodies(const AnimationPlan& plan, const double* q, Painter& pt) {
  for (size_t b = 0; b < plan.bodies.size(); ++b) {
    const PlanBody& body = plan.bodies[b];
    const int bi = static_cast<int>(b);
    const Vec3 origin = world({body.host, body.points[0]}, q);
    const int o = pt.add_point(origin);
    pt.cell(pt.data.verts, {o}, AnimationPart::kBodyPoint, bi, 0);
    for (size_t k = 1; k < body.points.size(); ++k) {  // a line from the frame origin to each point
      const int id = pt.add_point(world({body.host, body.points[k]}, q));
      pt.cell(pt.data.verts, {id}, AnimationPart::kBodyPoint, bi, static_cast<int>(k));
      pt.cell(pt.data.lines, {o, id}, AnimationPart::kBodyLine, bi, static_cast<int>(k));
    }
    const Mat3 axes = host_rotation(body.host, q) * body.axes;
    for (int a = 0; a < 3; ++a) {
      const int tip = pt.add_point(origin + plan.axis_length * axes.col(a));
      pt.cell(pt.data.lines, {o, tip}, AnimationPart::kAxis, bi, 0, a);
    }
  }
}

void draw_constraints(const AnimationPlan& plan, const double* q, Painter& pt) {
  for (size_t j = 0; j < plan.joints.size(); ++j)
    pt.cell(pt.data.verts, {pt.add_point(world(plan.joints[j], q))}, AnimationPart::kJoint, plan.joint_body[j],
            static_cast<int>(j));
  for (size_t c = 0; c < plan.cuts.size(); ++c)
    pt.cell(pt.data.verts, {pt.add_point(world(plan.cuts[c], q))}, AnimationPart::kCut, plan.cut_body[c],
            static_cast<int>(c));
}

// Each force as its row's glyph (formulation/force_types.h): spring-dampers, bushings and user
// laws as lines carrying their force; point and contact forces as vectors (point field
// force_vector) at their points; torques and loads on joint coordinates not at all.
void draw_forces(const System& sys, const double* q, const double* v, const std::vector<char>& modes, double t,
                 Painter& pt) {
  for (size_t k = 0; k < sys.forces.size(); ++k) {
    const Force& f = sys.forces[k];
    const ForceGlyph glyph = force_type(f.type).glyph;
    if (glyph == ForceGlyph::kNone) continue;
    LoadInput in;
    const bool evaluate = v != nullptr;  // null: only the frame's layout is wanted (its size)
    if (evaluate && f.has_expression()) in = load_input(sys, f, modes, q, v, t, false);
    const LocalState x = gather(q, f.bi, f.bj), xd = evaluate ? gather(v, f.bi, f.bj) : LocalState{};
    const double value = evaluate ? force_magnitude(f, x, xd, t, modes[k], &in) : 0.0;
    const Vec3 xi = world({f.bi, f.si}, q);
    const int index = static_cast<int>(k);
    if (glyph == ForceGlyph::kVector || glyph == ForceGlyph::kWheel) {
      // The world force is the translational part of its generalized force on its body.
      Vec14 generalized = Vec14::Zero();
      if (evaluate) force_eval(f, x, xd, t, modes[k], generalized, nullptr, nullptr, &in);
      const Vec3 vec = glyph == ForceGlyph::kVector ? Vec3(generalized.head<3>()) : Vec3(0, 0, value);
      pt.cell(pt.data.verts, {pt.add_point(xi, vec)}, AnimationPart::kForceVector, -1, index, -1, value);
      if (glyph == ForceGlyph::kWheel) {
        const Vec3 below(xi.x(), xi.y(), f.ground.value(t));
        const int a = pt.add_point(below - f.radius * Vec3::UnitX()), b = pt.add_point(below + f.radius * Vec3::UnitX());
        pt.cell(pt.data.lines, {a, b}, AnimationPart::kGround, -1, index);
      }
    } else {
      const int i = pt.add_point(xi), j = pt.add_point(world({f.bj, f.sj}, q));
      pt.cell(pt.data.lines, {i, j}, AnimationPart::kForceLine, -1, index, -1, value);
    }
  }
}

void draw_shapes(const AnimationPlan& plan, const double* q, Painter& pt) {
  for (const PlanShape& s : plan.shapes) {
    const int first = static_cast<int>(pt.data.num_points());
    const int host = plan.bodies[s.body].host;
    for (const Vec3& v : s.vertices) pt.add_point(world({host, v}, q));
    for (size_t k = 0; k < s.faces.size(); ++k) {
      for (int id : s.faces[k]) pt.data.polys.connectivity.push_back(first + id);
      pt.close(pt.data.polys, AnimationPart::kShape, s.body, static_cast<int>(k));
    }
  }
}

const std::vector<std::string> kPartNames = {"axis", "body_line", "body_point", "joint", "cut",
                                             "force_line", "force_vector", "shape", "ground"};

nlohmann::ordered_json legend(const AnimationPlan& plan, const System& sys) {
  nlohmann::ordered_json j;
  for (size_t k = 0; k < kPartNames.size(); ++k) j["parts"][std::to_string(k)] = kPartNames[k];
  j["cell_fields"] = kCellFieldNames;
  j["point_fields"] = {"force_vector"};
  j["axis_length"] = plan.axis_length;
  for (const auto& b : plan.bodies) j["bodies"].push_back({{"name", b.name}, {"points", b.point_names}});
  j["joints"] = plan.joint_names;
  j["cuts"] = plan.cut_names;
  j["forces"] = nlohmann::ordered_json::array();
  for (const auto& f : sys.forces) j["forces"].push_back(f.name);
  return j;
}

// An empty frame with its fields, and the names the codes stand for as field data.
void setup_polydata(VtkPolyData& d, const AnimationPlan& plan, const System& sys) {
  d.point_fields = {VtkField{"force_vector", 3, {}}};
  d.cell_fields = kCellFieldNames;
  for (VtkCells* c : {&d.verts, &d.lines, &d.polys}) c->fields.assign(kNumCellFields, {});
  VtkStrings bodies{"body_names", {}}, forces{"force_names", {}};
  for (const auto& b : plan.bodies) bodies.values.push_back(b.name);
  for (const auto& f : sys.forces) forces.values.push_back(f.name);
  d.field_data = {{"part_names", kPartNames}, bodies, {"joint_names", plan.joint_names}, {"cut_names", plan.cut_names},
                  forces};
}

// A frame's points and cells at the state (q, v); v null: the layout only (forces not evaluated).
void draw(const AnimationPlan& plan, const System& sys, const double* q, const double* v,
          const std::vector<char>& modes, double input_time, VtkPolyData& data) {
  data.clear();
  Painter pt{data};
  draw_bodies(plan, q, pt);
  draw_constraints(plan, q, pt);
  draw_forces(sys, q, v, modes, input_time, pt);
  draw_shapes(plan, q, pt);
}

// A name written by the animation: frame_ and six or more digits, .vtp (or its .tmp).
bool is_frame_file(const std::string& name) {
  size_t k = 6;
  if (name.rfind("frame_", 0) != 0) return false;
  while (k < name.size() && name[k] >= '0' && name[k] <= '9') ++k;
  const std::string rest = name.substr(k);
  return k >= 12 && (rest == ".vtp" || rest == ".vtp.tmp");
}

// True for a .pvd that mbdae wrote: a collection whose data sets are all animation/frame_*.vtp.
bool is_our_pvd(const std::filesystem::path& path) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec || size > (64u << 20)) return false;  // 1e5 frames take 10 MB
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return false;
  std::string text(size, '\0');
  text.resize(std::fread(text.data(), 1, text.size(), f));
  std::fclose(f);
  if (text.find("<VTKFile type=\"Collection\"") == std::string::npos) return false;
  for (size_t at = text.find("file=\""); at != std::string::npos; at = text.find("file=\"", at + 1)) {
    const size_t end = text.find('"', at + 6);
    if (end == std::string::npos) return false;
    const std::string file = text.substr(at + 6, end - at - 6);
    if (file.rfind(std::string(kFolder) + "/", 0) != 0 || !is_frame_file(file.substr(std::strlen(kFolder) + 1)))
      return false;
  }
  return true;
}

// Makes DIR/animation and removes the files of an earlier run from it.
void prepare_folder(const std::string& dir) {
  remove_animation_files(dir);
  std::filesystem::create_directories(std::filesystem::path(dir) / kFolder);
}

}  // namespace

void remove_animation_files(const std::string& dir) {
  namespace fs = std::filesystem;
  const fs::path folder = fs::path(dir) / kFolder, pvd = fs::path(dir) / "animation.pvd";
  std::error_code ec;
  if (fs::is_regular_file(pvd, ec) && is_our_pvd(pvd)) fs::remove(pvd);
  if (fs::is_regular_file(fs::path(dir) / "animation.pvd.tmp", ec)) fs::remove(fs::path(dir) / "animation.pvd.tmp");
  if (!fs::is_directory(folder, ec)) return;
  for (const auto& e : fs::directory_iterator(folder)) {
    const std::string name = e.path().filename().string();
    if (e.is_regular_file() && (is_frame_file(name) || name == "legend.json" || name == "legend.json.partial"))
      fs::remove(e.path());
  }
  fs::remove(folder, ec);  // only when empty: a folder holding other files stays
}

AnimationSink::AnimationSink(const Scene& scene, std::string dir, double frame_rate)
    : scene_(scene), dir_(std::move(dir)), spec_(scene.animation) {
  if (frame_rate > 0) spec_.frame_rate = frame_rate;
}

AnimationSink::~AnimationSink() = default;

void AnimationSink::start(std::unique_ptr<System> system, double t0, double t_end) {
  system_ = std::move(system);
  const System& sys = *system_;
  plan_ = std::make_unique<AnimationPlan>(make_plan(sys, scene_));
  setup_polydata(data_, *plan_, sys);
  prepare_folder(dir_);
  pvd_.open(dir_ + "/animation.pvd");
  const double span = std::min(t_end, spec_.end) - std::max(t0, spec_.start);
  frame_step_ = 1.0 / spec_.frame_rate;
  if (span > 0 && span / frame_step_ + 1 > spec_.max_frames) frame_step_ = span / (spec_.max_frames - 1);
  next_time_ = -std::numeric_limits<double>::infinity();
  entries_.clear();
  last_q_.assign(sys.nq(), 0.0);
  last_v_.assign(sys.nq(), 0.0);
  last_modes_.assign(sys.forces.size(), 0);
}

void AnimationSink::begin(const RunInfo& info) {
  start(std::make_unique<System>(*info.system), info.step->t0, info.step->t_end);
}

void AnimationSink::sample(const Sample& s) {
  if (!plan_ || s.t < spec_.start - 1e-9 * frame_step_ || s.t > spec_.end + 1e-9 * frame_step_) return;
  if (s.t >= next_time_ - 1e-9 * frame_step_) {
    write_frame(s.t, s.q, s.v, *s.modes, s.input_time);
    // The next frame time on the grid t_first + k frame_step, after t.
    const double first = entries_.front().time;
    next_time_ = first + (std::floor((s.t - first) / frame_step_ + 1e-9) + 1) * frame_step_;
    last_pending_ = false;
    return;
  }
  std::copy(s.q, s.q + last_q_.size(), last_q_.begin());
  std::copy(s.v, s.v + last_v_.size(), last_v_.begin());
  std::copy(s.modes->begin(), s.modes->end(), last_modes_.begin());
  last_t_ = s.t;
  last_input_time_ = s.input_time;
  last_pending_ = true;
}

void AnimationSink::write_frame(double t, const double* q, const double* v, const std::vector<char>& modes,
                                double input_time) {
  if (entries_.empty()) {
    plan_->axis_length = spec_.axis_length > 0 ? spec_.axis_length : automatic_axis_length(*plan_, q);
    write_json_file(dir_ + "/" + kFolder + "/legend.json", legend(*plan_, *system_));
  }
  draw(*plan_, *system_, q, v, modes, input_time, data_);
  char name[64];
  std::snprintf(name, sizeof name, "%s/frame_%06zu.vtp", kFolder, entries_.size());
  write_vtp(dir_ + "/" + name, data_, spec_.format, &scratch_);
  entries_.push_back({t, name});
  pvd_.add(entries_.back());  // the collection is whole after every frame
}

// A scene without integration (assembly, equilibrium) is drawn once, at its final configuration.
void AnimationSink::write_static_frame(const Result& result) {
  // The run's final model (solved force parameters included), else the scene's as built.
  auto system = std::make_unique<System>(result.system ? *result.system : build_system(scene_.model));
  const System& sys = *system;
  if (result.q.size() != static_cast<size_t>(sys.nq())) return;
  const double t = scene_.steps.empty() ? 0.0 : scene_.steps.back().t0;
  start(std::move(system), t, t);
  const std::vector<double> v(sys.nq(), 0.0);
  write_frame(t, result.q.data(), v.data(), initial_modes(sys, result.q.data(), t), t);
}

void AnimationSink::end(const Result& result) {
  try {
    if (!plan_) {
      write_static_frame(result);
    } else if (last_pending_) {
      write_frame(last_t_, last_q_.data(), last_v_.data(), last_modes_, last_input_time_);
      last_pending_ = false;
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mbdae: animation: %s\n", e.what());
  }
  pvd_.close();
}

}  // namespace mbdae

namespace mbdae {

namespace {

// The most frames a run of `scene` writes: per integrating step, one per frame step over the
// window (max_frames at most) and the step's last sample; one for a scene without integration.
long planned_frames(const Scene& scene, const AnimationSpec& spec, bool* by_max_frames) {
  long most = 1;
  *by_max_frames = false;
  for (const auto& st : scene.steps) {
    if (!integrates(st)) continue;
    const double span = std::min(st.t_end, spec.end) - std::max(st.t0, spec.start);
    if (!(span >= 0)) continue;
    const double by_rate = std::floor(span * spec.frame_rate * (1 + 1e-9)) + 1;
    const long frames = static_cast<long>(std::min<double>(spec.max_frames, by_rate)) + 1;
    if (frames > most) {
      most = frames;
      *by_max_frames = spec.max_frames < by_rate;
    }
  }
  return most;
}

std::string megabytes(double bytes) {
  char buf[40];
  if (bytes >= 1e12 - 5e8) std::snprintf(buf, sizeof buf, "%.3g TB", bytes / 1e12);
  else if (bytes >= 1e9) std::snprintf(buf, sizeof buf, "%.3g GB", bytes / 1e9);
  else if (bytes >= 1e6) std::snprintf(buf, sizeof buf, "%.3g MB", bytes / 1e6);
  else std::snprintf(buf, sizeof buf, "%.3g kB", bytes / 1e3);
  return buf;
}

// Free bytes for an unprivileged writer on the file system of `dir` (or of its nearest existing
// parent, as the folder may not exist yet); -1 if unknown.
double free_bytes(const std::string& dir) {
  std::filesystem::path p = std::filesystem::absolute(dir.empty() ? "." : dir);
  std::error_code ec;
  while (!std::filesystem::exists(p, ec) && p.has_parent_path() && p != p.parent_path()) p = p.parent_path();
  struct statvfs st;
  // No blocks at all (/proc, /sys): not a place for files; claiming the folder says why.
  if (::statvfs(p.c_str(), &st) != 0 || st.f_blocks == 0) return -1;
  return static_cast<double>(st.f_bavail) * static_cast<double>(st.f_frsize);
}

}  // namespace

void check_animation_size(const Scene& scene, const std::string& dir, double frame_rate) {
  AnimationSpec spec = scene.animation;
  if (frame_rate > 0) spec.frame_rate = frame_rate;
  const System sys = build_system(scene.model);
  const AnimationPlan plan = make_plan(sys, scene);
  VtkPolyData data;
  setup_polydata(data, plan, sys);
  draw(plan, sys, sys.q0.data(), nullptr, std::vector<char>(sys.forces.size(), 0), 0.0, data);
  bool by_max_frames = false;
  const long frames = planned_frames(scene, spec, &by_max_frames);
  const double frame = static_cast<double>(vtp_size_bound(data, spec.format));
  const double total = frames * (frame + 160.0) + 65536;  // frames, their .pvd lines, legend.json
  const std::string what = "the animation may take up to " + megabytes(total) + " (" + std::to_string(frames) +
                           " frames of up to " + megabytes(frame) + ")";
  if (total > spec.disk_budget_mb * 1e6) {
    // Blame what sets the frame count: max_frames, else the frame rate (the scene's or the option's).
    SourceLocation at = by_max_frames ? spec.max_frames_at : spec.frame_rate_at;
    if (at.line <= 0) at = spec.section.line > 0 ? spec.section : SourceLocation{scene.file, 0};
    std::string field = by_max_frames ? "max_frames" : "frame_rate";
    if (!by_max_frames && frame_rate > 0) at = {scene.file, 0}, field = "--animation-rate";
    throw ModelError(at.file, at.line, field,
                     what + ", more than its disk budget of " + megabytes(spec.disk_budget_mb * 1e6) +
                         " (animation.disk_budget_mb): lower max_frames or frame_rate, narrow the window "
                         "(start, end), or raise disk_budget_mb");
  }
  const double free = free_bytes(dir);
  if (free >= 0 && total > free)
    throw OutputError("output folder '" + dir + "': " + what + ", more than the " + megabytes(free) +
                      " free on its file system: free some space, or lower animation.max_frames or frame_rate");
}

}  // namespace mbdae
