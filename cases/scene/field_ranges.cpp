#include "cases/scene/field_ranges.h"

#include <cmath>
#include <cstdlib>
#include <sstream>

namespace mbdae {

std::string format_number(double x) {
  std::ostringstream os;
  os << x;
  return os.str();
}

std::string number_error(const std::string& text, double& v) {
  char* end = nullptr;
  v = std::strtod(text.c_str(), &end);
  if (text.empty() || !end || *end != '\0') return "expected a number, got '" + text + "'";
  if (!std::isfinite(v)) return "'" + text + "' is not a finite number";
  return "";
}

std::string rtol_range_error(double rtol) {
  return rtol >= 1e-14 && rtol <= 0.5 ? "" : "out of range [1e-14, 0.5], got " + format_number(rtol);
}

std::string atol_range_error(double atol) {
  return atol > 0 && atol <= 1.0 ? "" : "out of range (0, 1], got " + format_number(atol);
}

std::string output_step_range_error(double output_step, double t0, double t_end) {
  if (!(output_step > 0)) return "must be positive, got " + format_number(output_step);
  if (t_end > t0 && (t_end - t0) / output_step > kMaxOutputRows)
    return "too small: more than 1e8 output rows over [" + format_number(t0) + ", " + format_number(t_end) + "]";
  return "";
}

}  // namespace mbdae
