// The force-type table (force_types.h): one line per type, each row defined in its own file
// under formulation/forces/.
#include "formulation/force_types.h"

#include <stdexcept>

namespace mbdae {

// Each of these is defined in formulation/forces/<name>.cpp.
const ForceType& spring_damper_type();
const ForceType& point_force_type();
const ForceType& torque_type();
const ForceType& joint_spring_damper_type();
const ForceType& bushing_type();
const ForceType& wheel_contact_type();
const ForceType& user_force_type();
const ForceType& joint_friction_type();

const std::vector<const ForceType*>& force_types() {
  // In ForceKind order (the built-in kinds of model.h are the indices of the first seven rows),
  // which is also the order in which messages list the types.
  static const std::vector<const ForceType*> table = {
      &spring_damper_type(), &point_force_type(), &torque_type(), &joint_spring_damper_type(),
      &bushing_type(), &wheel_contact_type(), &user_force_type(),
      &joint_friction_type(),
  };
  return table;
}

const ForceType& force_type(ForceKind kind) {
  const auto& table = force_types();
  if (kind.id < 0 || kind.id >= static_cast<int>(table.size()))
    throw std::logic_error("force kind " + std::to_string(kind.id) + " has no row in the force-type table");
  return *table[kind.id];
}

ForceKind find_force_type(const std::string& name) {
  const auto& table = force_types();
  for (size_t k = 0; k < table.size(); ++k)
    if (name == table[k]->name) return ForceKind{static_cast<int>(k)};
  return ForceKind{-1};
}

std::string force_type_names() {
  std::string names;
  for (const ForceType* t : force_types()) names += (names.empty() ? "" : ", ") + std::string(t->name);
  return names;
}

std::string force_sensor_unit(const Force& f, bool length) {
  const ForceType& row = force_type(f.type);
  if (row.attach == ForceAttach::kCoordinate && !f.coordinate.rotation) return length ? "m" : "N";
  return length ? row.length_unit : row.value_unit;
}

const ForceParameter* find_force_parameter(const ForceType& type, const std::string& name) {
  for (const ForceParameter& p : type.parameters)
    if (name == p.name) return &p;
  return nullptr;
}

}  // namespace mbdae
