// The SI unit of a scene parameter, for `mbdae params` and Scene.parameters() (the units of
// docs/scene-format.md): by the field's name, its section and, for forces, the force type.
#pragma once

#include <string>
#include <vector>

namespace mbdae {

// segs: the path's segments (forces, tyre, stiffness); type: the item's `type` (forces,
// sensors, cuts) or ""; coordinate_kind: 'R' or 'T' for a coordinate's (or a joint
// spring-damper's) chain element, '?' if unknown. "" when the field has no unit or is unknown.
std::string parameter_unit(const std::vector<std::string>& segs, const std::string& type, char coordinate_kind);

}  // namespace mbdae
