// The five-point suspension end to end: every analysis of the spec run from its scene file and
// checked against the independent reference of verification/reference (carrier-pose
// coordinates, distance equations, virtual work), which shares no code with the engine.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "cases/mbdae.h"
#include "cases/scene/scene.h"
#include "core/errors.h"
#include "verification/reference/suspension_reference.h"

namespace mbdae {
namespace {

namespace ref = mbdae::reference;
using json = nlohmann::ordered_json;

std::string scene_path(const std::string& name) {
  return std::string(MBDAE_SOURCE_DIR) + "/cases/five_point_suspension/" + name;
}

Result run(const std::string& name, double rtol = 0, double atol = 0, const std::string& formulation = "") {
  RunOptions o;
  o.formulation = formulation;
  o.verbose = false;
  o.progress = false;
  o.rtol = rtol;
  o.atol = atol;
  Result r = mbdae::run(load_scene(scene_path(name)), o);
  EXPECT_EQ(r.exit_code, 0) << r.summary.dump(2);
  return r;
}

int column(const Result& r, const std::string& name) {
  auto it = std::find(r.columns.begin(), r.columns.end(), name);
  EXPECT_NE(it, r.columns.end()) << name;
  return static_cast<int>(it - r.columns.begin());
}

const json& step_of(const Result& r, const std::string& type, int nth = 0) {
  for (const auto& s : r.summary["steps"])
    if (s["type"] == type && nth-- == 0) return s;
  static json none;
  ADD_FAILURE() << "no step " << type;
  return none;
}

TEST(Suspension, AssemblyFromTheSpecGuessMatchesTheReference) {
  const Result r = run("equilibrium.yaml");
  const json& a = step_of(r, "assembly");
  EXPECT_LE(a["max_constraint_violation"].get<double>(), 1e-12);
  const json& s = a["sensors"];
  // The spec: wheel centre close to (0, 0.768, 0.278), toe close to 0.
  EXPECT_NEAR(s["wheel_x"].get<double>(), 0.0, 1e-3);
  EXPECT_NEAR(s["wheel_y"].get<double>(), 0.768, 1e-3);
  EXPECT_NEAR(s["wheel_z"].get<double>(), 0.278, 1e-3);
  EXPECT_NEAR(s["toe"].get<double>(), 0.0, 2e-3);
  // The independent reference, to 1e-9.
  const ref::SuspensionData data = ref::spec_data();
  const ref::CarrierPose pose = ref::design_pose(data);
  const ref::WheelOutputs w = ref::wheel_outputs(data, pose);
  EXPECT_NEAR(s["wheel_x"].get<double>(), w.centre.x(), 1e-9);
  EXPECT_NEAR(s["wheel_y"].get<double>(), w.centre.y(), 1e-9);
  EXPECT_NEAR(s["wheel_z"].get<double>(), w.centre.z(), 1e-9);
  EXPECT_NEAR(s["camber"].get<double>(), w.camber, 1e-9);
  EXPECT_NEAR(s["toe"].get<double>(), w.toe, 1e-9);
  const std::array<double, 14> q = ref::joint_coordinates(data, pose);
  for (int i = 2; i <= 14; ++i)
    EXPECT_NEAR(a["coordinates"]["q" + std::to_string(i)].get<double>(), q[i - 1], 1e-9) << "q" << i;
  // q8's guessed sign was wrong: the assembly must have flipped it.
  EXPECT_LT(a["coordinates"]["q8"].get<double>(), 0.0);
}

TEST(Suspension, KinematicSweepMatchesTheReferenceGeometry) {
  const Result r = run("kinematics.yaml");
  const json& k = step_of(r, "kinematics");
  EXPECT_LT(k["statistics"]["max_position_violation_steps"].get<double>(), 1e-10);
  EXPECT_EQ(r.columns, (std::vector<std::string>{"t", "q4", "wheel_x", "wheel_y", "wheel_z", "camber", "toe"}));
  const ref::SuspensionData data = ref::spec_data();
  ref::CarrierPose pose = ref::design_pose(data);
  double q4_prev = data.q4_design;
  // 46 samples over both stages (every 0.05 s of the 2 s drive), reached by continuation.
  int checked = 0;
  for (size_t i = 0; i < r.rows(); i += 50) {
    const std::vector<double> row = r.row(i);
    const double q4 = row[column(r, "q4")];
    pose = ref::continue_pose(data, pose, q4_prev, q4);
    q4_prev = q4;
    const ref::WheelOutputs w = ref::wheel_outputs(data, pose);
    EXPECT_NEAR(row[column(r, "wheel_x")], w.centre.x(), 1e-9) << "q4 = " << q4;
    EXPECT_NEAR(row[column(r, "wheel_y")], w.centre.y(), 1e-9) << "q4 = " << q4;
    EXPECT_NEAR(row[column(r, "wheel_z")], w.centre.z(), 1e-9) << "q4 = " << q4;
    EXPECT_NEAR(row[column(r, "camber")], w.camber, 1e-9) << "q4 = " << q4;
    EXPECT_NEAR(row[column(r, "toe")], w.toe, 1e-9) << "q4 = " << q4;
    ++checked;
  }
  EXPECT_GE(checked, 20);
  // The sweep covers +-0.20 m of wheel travel around the design height.
  double zmin = 1e9, zmax = -1e9;
  for (const std::vector<double>& row : r.row_major()) {
    zmin = std::min(zmin, row[column(r, "wheel_z")]);
    zmax = std::max(zmax, row[column(r, "wheel_z")]);
  }
  const double z0 = r.data[column(r, "wheel_z")].front();
  EXPECT_LT(zmin, z0 - 0.20);
  EXPECT_GT(zmax, z0 + 0.20);
}

TEST(Suspension, SpringFreeLengthMatchesVirtualWork) {
  const Result r = run("equilibrium.yaml");
  const ref::SuspensionData data = ref::spec_data();
  const double z0_ref = ref::spring_free_length(data, data.q4_design);
  EXPECT_NEAR(r.summary["spring_free_length"].get<double>(), z0_ref, 1e-9);
  // The released coordinate carries no reaction, the wheel spin none either.
  const json& e = step_of(r, "equilibrium");
  EXPECT_NEAR(e["hold_reactions"]["q4"].get<double>(), 0.0, 1e-8);
  EXPECT_NEAR(e["hold_reactions"]["q15"].get<double>(), 0.0, 1e-8);
}

TEST(Suspension, ChassisFreeEquilibriumMatchesTheReference) {
  // The poster scene's two equilibria, without its 20 s integration.
  Scene scene = load_scene(scene_path("dynamics_poster.yaml"));
  scene.steps.pop_back();
  RunOptions o;
  o.verbose = false;
  const Result r = mbdae::run(scene, o);
  ASSERT_EQ(r.exit_code, 0);
  const ref::SuspensionData data = ref::spec_data();
  const double z0 = ref::spring_free_length(data, data.q4_design);
  EXPECT_NEAR(r.summary["spring_free_length"].get<double>(), z0, 1e-9);
  const ref::VehicleEquilibrium eq = ref::solve_vehicle_equilibrium(data, z0);
  const json& c = step_of(r, "equilibrium", 1)["coordinates"];
  EXPECT_NEAR(c["q1"].get<double>(), eq.q1, 1e-9);
  EXPECT_NEAR(c["q4"].get<double>(), eq.q4, 1e-9);
}

TEST(Suspension, GroundStepNothingMovesBeforeTheStepAndEventsAreLocated) {
  const Result r = run("dynamics_step.yaml");
  const json& d = step_of(r, "dynamics");
  EXPECT_EQ(r.columns, (std::vector<std::string>{"t", "wheel_z", "wheel_vz", "wheel_az"}));
  for (auto& [name, change] : d["max_change_before"]["sensors"].items())
    EXPECT_LT(change.get<double>(), 1e-12) << name;
  ASSERT_EQ(d["breakpoint_times"].size(), 1u);
  EXPECT_DOUBLE_EQ(d["breakpoint_times"][0].get<double>(), 0.2);
  // The wheel leaves the ground at the step and lands again: lift-off and landing events
  // alternate, and at each the tyre compression is zero.
  EXPECT_GE(d["event_times"].size(), 2u);
  const int z = column(r, "wheel_z"), az = column(r, "wheel_az");
  // Free fall right after the step: the wheel's acceleration is that of the whole unsprung
  // assembly under gravity and the spring (downwards, larger than g is possible with the spring).
  for (const std::vector<double>& row : r.row_major()) {
    if (row[0] > 0.2005 && row[0] < 0.21) {
      EXPECT_LT(row[az], -9.0) << row[0];
    }
  }
  // Before the step the wheel is at rest at its equilibrium height.
  EXPECT_NEAR(r.data[z].front(), 0.277971383717455, 1e-9);
}

// Max |a - b| of a column over the rows both runs share (same output times).
double max_difference(const Result& a, const Result& b, const std::string& name) {
  const int ca = column(a, name), cb = column(b, name);
  EXPECT_EQ(a.rows(), b.rows());
  double m = 0;
  for (size_t i = 0; i < std::min(a.rows(), b.rows()); ++i)
    m = std::max(m, std::fabs(a.data[ca][i] - b.data[cb][i]));
  return m;
}

// Tolerance ladder tau = 1e-6, 1e-8, 1e-10 with rtol = tau and atol = 1e-6 tau, i.e. a purely
// relative error test: the step size is set by Euler parameters of the rods, some of which pass
// through zero, where any absolute tolerance above that would take over; see docs/results.md.
TEST(Suspension, GroundStepConvergesWithTheTolerance) {
  // Tolerance proportionality of the positions-only error test (formulation index3-positions,
  // the default before issue 13). The default index3 (error per unit step) is 20 to 100 times
  // more accurate at the same tolerance and reaches index 3's accuracy floor (about 1.3e-9 m)
  // from rtol 1e-8 on, so its ratio is checked as the promise below instead.
  const Result r6 = run("dynamics_step.yaml", 1e-6, 1e-12, "index3-positions");
  const Result r8 = run("dynamics_step.yaml", 1e-8, 1e-14, "index3-positions");
  // The reference: index2-ggl, whose error at 1e-10 (1.5e-10 m, docs/work-precision.md) is below
  // index 3's rounding floor with error per unit step (about 1.3e-9 m from rtol 1e-9 on).
  const Result r10 = run("dynamics_step.yaml", 1e-10, 1e-16, "index2-ggl");
  const double e6 = max_difference(r6, r10, "wheel_z"), e8 = max_difference(r8, r10, "wheel_z");
  RecordProperty("wheel_z_difference_1e-6_1e-10", std::to_string(e6));
  RecordProperty("wheel_z_difference_1e-8_1e-10", std::to_string(e8));
  // Tolerance proportionality: a factor 100 in tolerance buys a factor of about 100 (more than
  // 50 asserted: event location and order changes blur it).
  EXPECT_GT(e6 / e8, 50.0);
  EXPECT_LT(e8, 1e-7);
  // The default index3 at rtol 1e-6 keeps the promise of 10 rtol of wheel_z's scale (0.28 m).
  const Result d6 = run("dynamics_step.yaml", 1e-6, 1e-12);
  const double e6_default = max_difference(d6, r10, "wheel_z");
  RecordProperty("wheel_z_difference_index3_1e-6", std::to_string(e6_default));
  EXPECT_LT(e6_default, 10 * 1e-6 * 0.28);
  // The scene's default tolerances (rtol 1e-8, atol 1e-14) give wheel_z within 1e-6 m of the
  // tightest run.
  const Result rd = run("dynamics_step.yaml");
  EXPECT_LT(max_difference(rd, r10, "wheel_z"), 1e-6);
  // Events converge too: the same count, times within 1e-6 s.
  const json& ev10 = step_of(r10, "dynamics")["event_times"];
  const json& ev8 = step_of(r8, "dynamics")["event_times"];
  ASSERT_EQ(ev8.size(), ev10.size());
  for (size_t i = 0; i < ev8.size(); ++i) EXPECT_NEAR(ev8[i].get<double>(), ev10[i].get<double>(), 1e-6);
}

// Dynamics II at a loose tolerance (index2-ggl, rtol 1e-4, the model's default atol). The state
// at a tyre-contact event (made consistent at the root time) can lie a local error on the other
// side of the switch: before the root functions were shifted there
// (MultibodyDae::set_switch_offsets) the wheel was set free 5.5e-6 m below the ground at 14.66 s,
// never saw the contact function cross zero again, and fell 140 m with status ok. Compared with
// the scene's own run (index3, rtol 1e-7): measured 7.2e-4 m with the per-step error test,
// asserted below 100 rtol of wheel_z's scale (0.28 m). Since issue 21 index2-ggl tests its error
// per unit of the run's span: it takes 5 times the steps of the per-step test (29788) and keeps
// the promise (1.4e-7 and 4.5e-7 of the scales against an index2-ggl rtol 1e-11 reference,
// docs/work-precision.md); the bound is unchanged.
TEST(Suspension, LooseToleranceKeepsTheWheelOnTheGround) {
  const Scene tight = load_scene(scene_path("dynamics_poster.yaml"));
  Scene loose = tight;
  for (AnalysisStep& s : loose.steps) {
    s.rtol = 1e-4;
    s.atol = 0;  // derived from the model's length scale
    s.formulation = "index2-ggl";
  }
  RunOptions o;
  o.verbose = false;
  o.progress = false;
  const Result a = mbdae::run(loose, o), b = mbdae::run(tight, o);
  ASSERT_EQ(a.exit_code, 0);
  ASSERT_EQ(b.exit_code, 0);
  const double e = max_difference(a, b, "wheel_z");
  RecordProperty("wheel_z_difference", std::to_string(e));
  EXPECT_LT(e, 100 * 1e-4 * 0.28);
  const std::vector<double>& z = a.column("wheel_z");
  EXPECT_GT(*std::min_element(z.begin(), z.end()), 0.2);
}

// The source's "ball cut 5" repeats the tree joint rod 5 - carrier: its three equations are
// flagged as redundant by name (fail policy), or removed (default) with the same assembly.
TEST(Suspension, BallCut5IsFlaggedAsRedundant) {
  const std::string path = std::string(MBDAE_SOURCE_DIR) + "/verification/suspension/scenes/ball_cut_5.yaml";
  Scene scene = load_scene(path);
  RunOptions o;
  o.verbose = false;
  o.progress = false;
  try {
    mbdae::run(scene, o);
    ADD_FAILURE() << "redundancy not reported";
  } catch (const ModelError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("3 redundant constraint equations"), std::string::npos) << m;
    for (const char* c : {"x", "y", "z"})
      EXPECT_NE(m.find(std::string("cut ball5: coincident points [") + c + "]"), std::string::npos) << m;
  }
  scene.redundant_constraints = "remove";
  const Result r = mbdae::run(scene, o);
  ASSERT_EQ(r.exit_code, 0);
  EXPECT_EQ(r.summary["redundant_constraints"]["redundant"].size(), 3u);
  const ref::SuspensionData data = ref::spec_data();
  const ref::WheelOutputs w = ref::wheel_outputs(data, ref::design_pose(data));
  EXPECT_NEAR(step_of(r, "assembly")["sensors"]["wheel_z"].get<double>(), w.centre.z(), 1e-9);
}

// The three formulations on dynamics I and on the first 3 s of dynamics II, each at rtol 1e-8
// (atol 1e-14), against index3 at rtol 1e-10 (atol 1e-16): the bound is what the tolerance
// promises for wheel_z here (the index-3 ladder test: about 4e-8 m at rtol 1e-8), with a margin
// of 10 (measured: index2-ggl 6e-9 m, index1 4e-9 m on dynamics I).
TEST(Suspension, FormulationsReproduceIndex3) {
  for (const char* scene_name : {"dynamics_step.yaml", "dynamics_poster.yaml"}) {
    Scene scene = load_scene(scene_path(scene_name));
    scene.steps.back().t_end = std::min(scene.steps.back().t_end, 3.0);
    auto run_with = [&](const std::string& formulation, double rtol, double atol) {
      RunOptions o;
      o.verbose = false;
      o.progress = false;
      o.rtol = rtol;
      o.atol = atol;
      o.formulation = formulation;
      Result r = mbdae::run(scene, o);
      EXPECT_EQ(r.exit_code, 0) << formulation << " " << r.summary.value("message", "");
      return r;
    };
    const Result ref = run_with("index3", 1e-10, 1e-16);
    for (const char* f : {"index2-ggl", "index1"}) {
      const Result r = run_with(f, 1e-8, 1e-14);
      const double e = max_difference(r, ref, "wheel_z");
      RecordProperty(std::string(scene_name) + "_" + f, std::to_string(e));
      EXPECT_LT(e, 4e-7) << scene_name << " " << f;
    }
  }
}

// Damper and tyre removed: kinetic + potential energy (gravity and spring) stays constant.
TEST(Suspension, FreeOscillationConservesEnergy) {
  RunOptions o;
  o.verbose = false;
  o.progress = false;
  const Result r = mbdae::run(
      load_scene(std::string(MBDAE_SOURCE_DIR) + "/verification/suspension/scenes/free_oscillation.yaml"), o);
  ASSERT_EQ(r.exit_code, 0) << r.summary.dump(2);
  const int total = column(r, "total"), kinetic = column(r, "kinetic"), z = column(r, "wheel_z");
  double drift = 0, kmax = 0, zmin = 1e9, zmax = -1e9;
  for (const std::vector<double>& row : r.row_major()) {
    drift = std::max(drift, std::fabs(row[total] - r.data[total].front()));
    kmax = std::max(kmax, row[kinetic]);
    zmin = std::min(zmin, row[z]);
    zmax = std::max(zmax, row[z]);
  }
  EXPECT_GT(zmax - zmin, 0.05);  // a real oscillation: several centimetres of wheel travel
  RecordProperty("relative_energy_drift", std::to_string(drift / kmax));
  EXPECT_LT(drift / kmax, 1e-7);  // relative to the largest kinetic energy (15 J)
}

}  // namespace
}  // namespace mbdae
