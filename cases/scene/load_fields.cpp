// Reading field values: numbers with their ranges, names, vectors, axes and functions of time.
#include "cases/scene/loader.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <unordered_map>
#include <sstream>
#include "cases/scene/field_ranges.h"
#include "cases/scene/analysis_types.h"
#include "cases/scene/scene.h"
#include "cases/scene/scene_overrides.h"
#include "cases/scene/scene_validation.h"
#include "core/errors.h"
#include "core/expression.h"
#include "formulation/formulation_registry.h"

namespace mbdae::scene_load {

std::string join(const Fields& list) {
  std::string s;
  for (const auto& x : list) s += (s.empty() ? "" : ", ") + x;
  return s;
}

std::string quote(const std::string& s) {
  std::string out = "'";
  for (size_t k = 0; k < s.size(); ++k) {
    if (k == 60) {
      out += "...";
      break;
    }
    const unsigned char c = static_cast<unsigned char>(s[k]);
    if (c < 0x20 || c == 0x7f) {
      static const char* hex = "0123456789abcdef";
      out += "\\x";
      out += hex[c >> 4];
      out += hex[c & 15];
    } else {
      out += static_cast<char>(c);
    }
  }
  return out + "'";
}

std::string describe(const YAML::Node& n) {
  if (!n.IsDefined() || n.IsNull()) return "nothing";
  if (n.IsMap()) return "a mapping";
  if (n.IsSequence()) return "a list of " + std::to_string(n.size());
  return quote(n.Scalar());
}


std::optional<double> Loader::to_number(const YAML::Node& v, const std::string& field) {
  if (!v.IsScalar()) {
    error(v, field, "expected a number, got " + describe(v));
    return std::nullopt;
  }
  const std::string& s = v.Scalar();
  std::string low;
  for (char c : s) low += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (low == ".nan" || low == ".inf" || low == "+.inf" || low == "-.inf") {
    error(v, field, quote(s) + " is not a finite number");
    return std::nullopt;
  }
  if (s.empty() || std::isspace(static_cast<unsigned char>(s[0]))) {
    error(v, field, "expected a number, got " + quote(s));
    return std::nullopt;
  }
  char* end = nullptr;
  const double x = std::strtod(s.c_str(), &end);
  if (end != s.c_str() + s.size()) {
    error(v, field, "expected a number, got " + quote(s));
    return std::nullopt;
  }
  if (!std::isfinite(x)) {
    error(v, field, quote(s) + " is not a finite number");
    return std::nullopt;
  }
  return x;
}

std::optional<double> Loader::opt_number(const YAML::Node& parent, const char* key, bool required) {
  if (!has(parent, key)) {
    if (required) error(parent, key, "missing");
    return std::nullopt;
  }
  const YAML::Node v = parent[key];
  record(parent, key, v);
  return to_number(v, key);
}

double Loader::number(const YAML::Node& parent, const char* key, double fallback, bool required) {
  return opt_number(parent, key, required).value_or(fallback);
}

std::string Loader::text(const YAML::Node& parent, const char* key, const std::string& fallback, bool required) {
  if (!has(parent, key)) {
    if (required) error(parent, key, "missing");
    return fallback;
  }
  const YAML::Node v = parent[key];
  record(parent, key, v);
  if (!v.IsScalar()) {
    error(v, key, "expected text, got " + describe(v));
    return fallback;
  }
  return v.Scalar();
}

// A required name (of the item, or of another item it refers to).
std::string Loader::name(const YAML::Node& parent, const char* key) {
  const std::string s = text(parent, key, "", true);
  if (has(parent, key) && parent[key].IsScalar()) {
    if (s.empty()) error(parent[key], key, "must not be empty");
    else if (std::any_of(s.begin(), s.end(), [](char c) { return static_cast<unsigned char>(c) < 0x20; }))
      error(parent[key], key, "must not contain control characters, got " + quote(s));
  }
  return s;
}

Vec3 Loader::vec3(const YAML::Node& parent, const char* key, const Vec3& fallback, bool required) {
  if (!has(parent, key)) {
    if (required) error(parent, key, "missing");
    return fallback;
  }
  const YAML::Node v = parent[key];
  record(parent, key, v);
  if (!v.IsSequence() || v.size() != 3) {
    error(v, key, "expected a list of 3 numbers, got " + describe(v));
    return fallback;
  }
  Vec3 out;
  for (int k = 0; k < 3; ++k) out[k] = to_number(v[k], key).value_or(fallback[k]);
  return out;
}

std::vector<std::string> Loader::names(const YAML::Node& parent, const char* key) {
  std::vector<std::string> out;
  if (!has(parent, key)) return out;
  const YAML::Node v = parent[key];
  record(parent, key, v);
  if (v.IsScalar()) return {v.Scalar()};
  if (!v.IsSequence()) {
    error(v, key, "expected a list of names, got " + describe(v));
    return out;
  }
  for (const auto& x : v) {
    if (!x.IsScalar()) {
      error(x, key, "expected a name, got " + describe(x));
      continue;
    }
    lines->add(where(parent), std::string(key) + "[" + std::to_string(out.size()) + "]", line_of(x));
    out.push_back(x.Scalar());
  }
  return out;
}

int Loader::axis_component(const YAML::Node& parent, const char* key) {
  const std::string c = text(parent, key, "x");
  if (c == "x") return 0;
  if (c == "y") return 1;
  if (c == "z") return 2;
  if (parent[key].IsScalar()) error(parent[key], key, "expected x, y or z, got " + quote(c));
  return 0;
}


TimeFunction Loader::function(const YAML::Node& n, const std::string& field) {
  TimeFunction f;
  if (n.IsScalar()) return TimeFunction::constant(to_number(n, field).value_or(0.0));
  static const Fields general = {"type", "value", "time", "before", "after", "points", "amplitude",
                                 "frequency", "phase", "offset", "f0", "f1", "t0", "t1", "coefficients"};
  if (!check_keys(n, field, general)) return f;
  const std::string type = text(n, "type", "", true);
  const std::string what = "a " + type + " function";
  if (type == "constant") {
    applies(n, what, general, {"type", "value"});
    f.a = number(n, "value", 0.0, true);
  } else if (type == "step") {
    applies(n, what, general, {"type", "time", "before", "after"});
    f.kind = TimeFunction::Kind::kStep;
    f.t0 = number(n, "time", 0.0, true);
    f.a = number(n, "before", 0.0, true);
    f.b = number(n, "after", 0.0, true);
  } else if (type == "piecewise_linear") {
    applies(n, what, general, {"type", "points"});
    f.kind = TimeFunction::Kind::kPiecewiseLinear;
    const YAML::Node pts = at(n, "points");
    if (!has(n, "points") || !pts.IsSequence() || pts.size() < 2) {
      error(pts, "points", "expected at least two [t, value] pairs");
      return TimeFunction{};
    }
    for (const auto& p : pts) {
      if (!p.IsSequence() || p.size() != 2) {
        error(p, "points", "expected a [t, value] pair, got " + describe(p));
        continue;
      }
      const auto t = to_number(p[0], "points"), y = to_number(p[1], "points");
      if (!t || !y) continue;
      if (!f.ts.empty() && !(*t > f.ts.back())) error(p, "points", "times must increase");
      f.ts.push_back(*t);
      f.ys.push_back(*y);
    }
    if (f.ts.size() < 2) return TimeFunction{};
  } else if (type == "sine") {
    applies(n, what, general, {"type", "amplitude", "frequency", "phase", "offset"});
    f.kind = TimeFunction::Kind::kSine;
    f.a = number(n, "amplitude", 0.0, true);
    f.b = number(n, "frequency", 0.0, true);
    f.c = number(n, "phase", 0.0);
    f.d = number(n, "offset", 0.0);
  } else if (type == "sweep") {
    applies(n, what, general, {"type", "amplitude", "f0", "f1", "t0", "t1"});
    f.kind = TimeFunction::Kind::kSweep;
    f.a = number(n, "amplitude", 0.0, true);
    f.b = number(n, "f0", 0.0, true);
    f.c = number(n, "f1", 0.0, true);
    const auto t0 = opt_number(n, "t0"), t1 = opt_number(n, "t1", true);
    f.t0 = t0.value_or(0.0);
    f.t1 = t1.value_or(1.0);
    if (t1 && !(f.t1 > f.t0)) error(n["t1"], "t1", "the sweep's time span is empty (t1 must exceed t0)");
  } else if (type == "polynomial") {
    applies(n, what, general, {"type", "coefficients"});
    f.kind = TimeFunction::Kind::kPolynomial;
    const YAML::Node c = at(n, "coefficients");
    if (!has(n, "coefficients") || !c.IsSequence() || c.size() == 0)
      error(c, "coefficients", "expected a list of numbers");
    else
      for (const auto& x : c) f.ys.push_back(to_number(x, "coefficients").value_or(0.0));
  } else if (!type.empty()) {
    error(n["type"], "type", "unknown function type " + quote(type) +
                                 " (constant, step, piecewise_linear, sine, sweep, polynomial)");
  }
  return f;
}

}  // namespace mbdae::scene_load
