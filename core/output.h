// Result files written safely: rows go to NAME.partial (flushed as they come, so a failing run
// keeps what it computed), and the file is renamed to NAME when the run ends, successfully or
// not. A run never leaves a half-written file under the final name.
#pragma once

#include <cstdio>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace mbdae {

class CsvWriter {
 public:
  CsvWriter() = default;
  ~CsvWriter();
  CsvWriter(const CsvWriter&) = delete;
  CsvWriter& operator=(const CsvWriter&) = delete;
  // Opens NAME.partial and writes the header. Throws std::runtime_error on failure.
  void open(const std::string& path, const std::vector<std::string>& columns);
  void row(const double* values);  // as many values as columns
  void flush();
  // Flushes and renames to the final name.
  void close();
  long rows() const { return rows_; }

 private:
  std::FILE* file_ = nullptr;
  std::string path_;
  size_t columns_ = 0;
  long rows_ = 0;
  std::vector<char> line_;  // one row's text
};

// Writes JSON to path atomically (temporary name, then rename).
void write_json_file(const std::string& path, const nlohmann::ordered_json& j);

// Checks that a folder exists (creating it) and is writable; throws ModelError (field --out,
// exit code 2: an input error found before any solve) if not.
void prepare_output_folder(const std::string& dir);

}  // namespace mbdae
