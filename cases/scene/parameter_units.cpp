// Units of scene parameters (cases/parameter_units.h), from docs/scene-format.md.
#include "cases/scene/parameter_units.h"

#include <cctype>
#include <map>

#include "formulation/force_types.h"

namespace mbdae {
namespace {

bool is_index(const std::string& s) { return !s.empty() && std::isdigit(static_cast<unsigned char>(s[0])); }

// The unit of a time function's field (fy: {type: sine, amplitude: ...}) whose values are in `u`.
std::string function_unit(const std::string& field, const std::string& u) {
  static const std::map<std::string, std::string> fixed = {
      {"time", "s"}, {"t0", "s"}, {"t1", "s"}, {"frequency", "Hz"}, {"f0", "Hz"}, {"f1", "Hz"}, {"phase", "rad"}};
  const auto f = fixed.find(field);
  if (f != fixed.end()) return f->second;
  if (field == "value" || field == "before" || field == "after" || field == "amplitude" || field == "offset") return u;
  return "";
}

std::string force_unit(const std::vector<std::string>& segs, const std::string& type, char kind) {
  const std::string& f = segs.size() > 2 ? segs[2] : "";
  // The parameters of the type's row (formulation/force_types.h); on a coordinate, by its kind.
  const ForceKind k = find_force_type(type);
  const ForceType* row = k.id >= 0 ? &force_type(k) : nullptr;
  if (const ForceParameter* p = row ? find_force_parameter(*row, f) : nullptr) {
    if (row->attach != ForceAttach::kCoordinate) return p->unit;
    return kind == 'R' ? p->unit : kind == 'T' ? p->unit_translation : "";
  }
  if (row && row->attach == ForceAttach::kCoordinate) return f == "rest_deg" ? "deg" : "";
  if (f == "stiffness") return "N/m";
  if (f == "damping") return "N s/m";
  if (f == "rotational_stiffness") return "N m/rad";
  if (f == "rotational_damping") return "N m s/rad";
  if (f == "free_length" || f == "radius" || f == "point" || f == "point1" || f == "point2") return "m";
  const std::string load = (f == "fx" || f == "fy" || f == "fz") ? "N" : f == "torque" ? "N m" : f == "ground" ? "m" : "";
  if (load.empty()) return "";
  if (segs.size() == 3) return load;
  if (segs[3] == "points" && segs.size() == 6) return segs[5] == "0" ? "s" : load;  // [[t, y], ...]
  return function_unit(segs[3], load);
}

std::string analysis_unit(const std::string& f) {
  static const std::map<std::string, std::string> units = {
      {"t0", "s"}, {"t_end", "s"}, {"output_step", "s"}, {"max_step", "s"}, {"quiet_until", "s"},
      {"time_scale", "s"}, {"rtol", "1"}, {"atol", "m"}, {"atol_rotation", "1"}, {"atol_velocity", "m/s"},
      {"length_scale", "m"}, {"newton_convergence", "1"}, {"constraint_scale", "1"}, {"penalty", "1"},
      {"baumgarte_alpha", "1/s"}, {"baumgarte_beta", "1/s"}, {"mode_check_deg", "deg"}};
  const auto u = units.find(f);
  return u == units.end() ? "" : u->second;
}

}  // namespace

std::string parameter_unit(const std::vector<std::string>& segs, const std::string& type, char kind) {
  if (segs.empty()) return "";
  const std::string& section = segs[0];
  const std::string& last = segs.back();
  if (section == "gravity") return "m/s^2";
  if (section == "bodies" && segs.size() > 2) {
    if (segs[2] == "mass") return "kg";
    if (segs[2] == "inertia") return "kg m^2";
    if (segs[2] == "com" || segs[2] == "points") return "m";
    return "";
  }
  if (section == "ground" && segs.size() > 1 && segs[1] == "points") return "m";
  if (section == "joints" && segs.size() > 2 && segs[2] == "anchor") return "m";
  if (section == "coordinates" && segs.size() > 2) {
    if (segs[2] == "initial_deg") return "deg";
    if (segs[2] == "initial") return kind == 'R' ? "rad" : kind == 'T' ? "m" : "";
    if (segs[2] == "drive" && segs.size() > 3) {
      const std::string q = kind == 'R' ? "rad" : kind == 'T' ? "m" : "";
      if (segs[3] == "points" && segs.size() == 6) return segs[5] == "0" ? "s" : q;
      return function_unit(segs[3], q);
    }
    return "";
  }
  if (section == "cuts" && segs.size() > 2 && segs[2] == "distance") return "m";
  if (section == "forces") return force_unit(segs, type, kind);
  if (section == "analysis" && segs.size() > 2) {
    if (segs[2] == "initial_velocities") return "";  // rad/s or m/s by coordinate
    return is_index(last) && segs.size() > 3 ? "" : analysis_unit(segs[2]);
  }
  return "";
}

}  // namespace mbdae
