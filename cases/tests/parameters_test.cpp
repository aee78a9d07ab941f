// mbdae::parameters (the paths `mbdae params` lists) and list indices in parameter paths: every
// listed path is one set_parameter accepts, its value is the one in the file, list elements are
// paths, the scene's item hides the model's; output_columns equals what a run writes.
#include <gtest/gtest.h>

#include <map>
#include <string>

#include "cases/mbdae.h"

namespace {

const std::string kStep = std::string(MBDAE_SOURCE_DIR) + "/cases/five_point_suspension/dynamics_step.yaml";

std::map<std::string, mbdae::ParameterEntry> by_path(const mbdae::Scene& s) {
  std::map<std::string, mbdae::ParameterEntry> m;
  for (const auto& p : mbdae::parameters(s)) m[p.path] = p;
  return m;
}

TEST(Parameters, ValuesUnitsFilesAndLines) {
  const auto p = by_path(mbdae::load_scene(kStep));
  EXPECT_EQ(p.at("forces.tyre.stiffness").value, "2.0e5");
  EXPECT_EQ(p.at("forces.tyre.stiffness").unit, "N/m");
  EXPECT_NE(p.at("forces.tyre.stiffness").file.find("dynamics_step.yaml"), std::string::npos);
  EXPECT_EQ(p.at("forces.suspension.damping").unit, "N s/m");
  EXPECT_EQ(p.at("bodies.chassis.mass").unit, "kg");
  EXPECT_EQ(p.at("bodies.chassis.mass").line, 11);
  EXPECT_NE(p.at("bodies.chassis.mass").file.find("model.yaml"), std::string::npos);
  EXPECT_EQ(p.at("bodies.chassis.points.bp1").value, "[-0.064, 0.413, 0.327]");
  EXPECT_EQ(p.at("bodies.chassis.points.bp1.2").value, "0.327");
  EXPECT_EQ(p.at("coordinates.q4.initial").unit, "rad");  // q4: an R1 chain element
  EXPECT_EQ(p.at("coordinates.q1.initial").unit, "m");    // q1: T3
  EXPECT_EQ(p.at("analysis.dynamics.t_end").unit, "s");
  EXPECT_EQ(p.at("joints.rod1_mount.anchor").unit, "");   // a point name: no unit
  EXPECT_EQ(p.count("bodies.chassis.name"), 0u);          // an item's name is its path segment
  EXPECT_EQ(p.count("model"), 0u);
}

// Every third listed number (141 on this scene; all of them pass, 12 s in Release: a third keeps
// the test at seconds, also under the sanitizers).
TEST(Parameters, ListedPathsAreAcceptedWithTheirOwnValues) {
  const mbdae::Scene scene = mbdae::load_scene(kStep);
  int numeric = 0;
  for (const auto& p : mbdae::parameters(scene)) {
    if (p.unit.empty() || numeric++ % 3 != 0) continue;
    mbdae::Scene copy = scene;
    EXPECT_NO_THROW(mbdae::set_parameter(copy, p.path, p.value)) << p.path;
    EXPECT_EQ(by_path(copy).at(p.path).value, p.value) << p.path;
  }
  EXPECT_GT(numeric, 100);
}

TEST(Parameters, ListIndexEqualsTheWholeList) {
  mbdae::Scene a = mbdae::load_scene(kStep), b = a;
  mbdae::set_parameter(a, "bodies.carrier.points.cp5.2", "0.14");
  mbdae::set_parameter(b, "bodies.carrier.points.cp5", "[-0.0025, 0.0323383831212649, 0.14]");
  EXPECT_EQ(by_path(a).at("bodies.carrier.points.cp5").value, "[-0.0025, 0.0323383831212649, 0.14]");
  mbdae::set_parameter(a, "analysis.dynamics.t_end", "0.3");
  mbdae::set_parameter(b, "analysis.dynamics.t_end", "0.3");
  const mbdae::Result ra = mbdae::run(a, {}), rb = mbdae::run(b, {});
  ASSERT_TRUE(ra.ok() && rb.ok());
  EXPECT_EQ(ra.column("wheel_z"), rb.column("wheel_z"));
  mbdae::Scene c = mbdae::load_scene(kStep);
  try {
    mbdae::set_parameter(c, "bodies.carrier.points.cp5.3", "1");
    FAIL() << "an index past the end was accepted";
  } catch (const mbdae::SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("no item '3' in the list"), std::string::npos) << e.what();
  }
}

TEST(Parameters, OverridesShowInTheList) {
  mbdae::Scene s = mbdae::load_scene(kStep);
  mbdae::set_parameter(s, "gravity.2", "-9.80665");
  const auto p = by_path(s);
  EXPECT_EQ(p.at("gravity").value, "[0, 0, -9.80665]");
  EXPECT_EQ(p.at("gravity.2").unit, "m/s^2");
}

TEST(Parameters, OutputColumnsAreWhatARunWrites) {
  mbdae::Scene s = mbdae::load_scene(kStep);
  mbdae::set_parameter(s, "analysis.dynamics.t_end", "0.25");
  const auto cols = mbdae::output_columns(s);
  const mbdae::Result r = mbdae::run(s, {});
  ASSERT_EQ(cols.size(), r.columns.size());
  for (size_t k = 0; k < cols.size(); ++k) {
    EXPECT_EQ(cols[k].first, r.columns[k]);
    EXPECT_EQ(cols[k].second, r.units[k]);
  }
}

}  // namespace
