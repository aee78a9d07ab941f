// The force-type table (formulation/force_types.h): the built-in kinds name their rows, and each
// row is complete and consistent (its fields hold its attachment's fields and its parameters, its
// operations are set), so that the loader, the model rules and the units can rely on it.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <string>

#include "formulation/force_types.h"

namespace mbdae {
namespace {

TEST(ForceTypes, BuiltInKindsNameTheirRows) {
  const std::pair<ForceKind, const char*> kinds[] = {
      {ForceKind::kSpringDamper, "spring_damper"}, {ForceKind::kPointForce, "point_force"},
      {ForceKind::kTorque, "torque"},           {ForceKind::kJointSpringDamper, "joint_spring_damper"},
      {ForceKind::kBushing, "bushing"},          {ForceKind::kWheelContact, "wheel_contact"},
      {ForceKind::kUser, "user"}};
  for (const auto& [kind, name] : kinds) {
    EXPECT_STREQ(force_type(kind).name, name);
    EXPECT_EQ(find_force_type(name), kind) << name;
  }
  EXPECT_EQ(find_force_type("joint_friction").id, 7);
  EXPECT_EQ(find_force_type("spring").id, -1);
  EXPECT_THROW(force_type(ForceKind{99}), std::logic_error);
}

std::vector<std::string> attachment_fields(ForceAttach a) {
  switch (a) {
    case ForceAttach::kTwoPoints: return {"body1", "point1", "body2", "point2"};
    case ForceAttach::kBodyPoint: return {"body", "point"};
    case ForceAttach::kBody: return {"body"};
    case ForceAttach::kCoordinate: return {"coordinate"};
  }
  return {};
}

TEST(ForceTypes, EveryRowIsComplete) {
  std::set<std::string> names;
  for (const ForceType* row : force_types()) {
    SCOPED_TRACE(row->name);
    EXPECT_TRUE(names.insert(row->name).second) << "two rows named " << row->name;
    auto has = [&](const std::string& f) { return std::count(row->fields.begin(), row->fields.end(), f) == 1; };
    for (const char* f : {"name", "type"}) EXPECT_TRUE(has(f)) << f;
    for (const std::string& f : attachment_fields(row->attach)) EXPECT_TRUE(has(f)) << f;
    for (const ForceParameter& p : row->parameters) {
      EXPECT_TRUE(has(p.name)) << p.name;
      EXPECT_NE(std::string(p.unit), "") << p.name;
      if (row->attach == ForceAttach::kCoordinate) {
        EXPECT_NE(std::string(p.unit_translation), "") << p.name;
      }
      ASSERT_NE(p.spec, nullptr);
      ASSERT_NE(p.value, nullptr);
      ForceSpec spec;
      EXPECT_NE(p.spec(spec), nullptr);
      EXPECT_EQ(find_force_parameter(*row, p.name), &p);
    }
    for (const char* c : row->components) {
      if (c) {
        EXPECT_TRUE(has(c)) << c;
      }
    }
    EXPECT_NE(row->eval, nullptr);
    EXPECT_NE(row->length, nullptr);
    EXPECT_NE(row->magnitude, nullptr);
    EXPECT_NE(std::string(row->length_unit), "");
    EXPECT_NE(std::string(row->value_unit), "");
  }
}

}  // namespace
}  // namespace mbdae
