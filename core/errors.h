// Error types. Input errors carry the file, the line and the field; solver failures carry a
// status the front end writes into summary.json.
#pragma once

#include <stdexcept>
#include <string>

namespace mbdae {

// A scene or model that cannot be used (exit code 2).
struct ModelError : std::runtime_error {
  std::string file, field;
  int line = 0;
  ModelError(std::string file_, int line_, std::string field_, const std::string& message)
      : std::runtime_error(format(file_, line_, field_, message)),
        file(std::move(file_)),
        field(std::move(field_)),
        line(line_) {}
  static std::string format(const std::string& file, int line, const std::string& field,
                            const std::string& message) {
    std::string s = file.empty() ? std::string("<model>") : file;
    if (line > 0) s += ":" + std::to_string(line);
    if (!field.empty()) s += ": field '" + field + "'";
    return s + ": " + message;
  }
};

// A solve that failed (exit code 3): assembly, equilibrium, integration.
struct SolveError : std::runtime_error {
  std::string status;
  explicit SolveError(std::string status_, const std::string& message)
      : std::runtime_error(message), status(std::move(status_)) {}
};

}  // namespace mbdae
