// Range checks shared by the scene loader (cases/scene/scene_loader.cpp) and the command-line
// overrides (cases/cli/cli_options.cpp), so that a value refused in a scene is refused with the same
// message on the command line. Each returns the message for a value out of range, "" if it is fine.
#pragma once

#include <string>

namespace mbdae {

constexpr double kMaxOutputRows = 1e8;  // output_step may not ask for more rows than this

std::string format_number(double x);  // as in messages: shortest of %g-like text (1e-300, 0.5)
// A number as the scene loader reads one: all of `text`, finite. The message for text that is
// not one ("expected a number, got 'x'", "'x' is not a finite number"), "" if it is.
std::string number_error(const std::string& text, double& v);
inline bool parse_number(const std::string& text, double& v) { return number_error(text, v).empty(); }
std::string rtol_range_error(double rtol);
std::string atol_range_error(double atol);
// Positive, and at most kMaxOutputRows samples over [t0, t_end] (a span that is not valid is
// reported elsewhere: only the sign is checked then).
std::string output_step_range_error(double output_step, double t0, double t_end);

}  // namespace mbdae
