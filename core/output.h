// Result files written safely. Rows go to NAME.partial through a buffer that holds whole rows
// only, so every write(2) ends at a row end; a repair process cuts back a write that SIGKILL
// stopped halfway (core/output_guard.h), so even a killed run leaves whole rows. Every write,
// close and rename is checked: a failure throws OutputError naming the file and the OS error,
// the .partial file is cut back to its last whole row and keeps its .partial name. Only a file
// written completely is renamed to NAME (docs/errors.md, exit code 4).
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/output_guard.h"

namespace mbdae {

// An output file or folder that cannot be written (disk full, file size limit, I/O error, a
// folder in use by another run). The message names the file and the OS error. Exit code 4.
struct OutputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

class CsvWriter {
 public:
  CsvWriter() = default;
  ~CsvWriter();  // closes (and renames) a file not closed yet, unless a write failed
  CsvWriter(const CsvWriter&) = delete;
  CsvWriter& operator=(const CsvWriter&) = delete;
  // Opens NAME.partial and writes the header (names quoted per RFC 4180 where they hold a comma,
  // a quote or a line break). Throws OutputError on failure.
  void open(const std::string& path, const std::vector<std::string>& columns);
  void row(const double* values);  // as many values as columns; throws OutputError
  void flush();                    // writes the buffered rows; throws OutputError
  // Writes what is buffered, closes and renames to the final name; throws OutputError.
  void close();
  long rows() const { return rows_; }

 private:
  void write_buffer();
  int fd_ = -1;
  OutputGuard guard_;  // cuts the file back to whole rows if this process is killed
  bool failed_ = false;
  std::string path_;
  size_t columns_ = 0;
  long rows_ = 0;       // rows handed to row()
  long rows_on_disk_ = 0;
  long long bytes_on_disk_ = 0;  // whole rows written so far
  std::vector<char> buffer_;     // whole rows waiting to be written
  size_t used_ = 0, rows_buffered_ = 0;
  std::vector<char> line_;  // one row's text
};

// A CSV header field: quoted per RFC 4180 if it holds a comma, a double quote or a line break.
std::string csv_field(const std::string& name);

// Writes JSON to path atomically (temporary name, then rename); throws OutputError.
void write_json_file(const std::string& path, const nlohmann::ordered_json& j);

// Checks that a folder exists (creating it) and is writable, and that each of `files` and its
// .partial temporary name can be created there (no folder in the way, the name not too long);
// throws ModelError (field --out, exit code 2: an input error found before any solve) if not.
void prepare_output_folder(const std::string& dir, const std::vector<std::string>& files = {});

// One run per output folder: an exclusive lock (flock) on DIR/.mbdae.lock, held while this
// object lives. The constructor throws OutputError if another run holds the folder.
class OutputFolderLock {
 public:
  OutputFolderLock() = default;
  explicit OutputFolderLock(const std::string& dir);
  ~OutputFolderLock();
  OutputFolderLock(OutputFolderLock&& o) noexcept : fd_(o.fd_) { o.fd_ = -1; }
  OutputFolderLock& operator=(OutputFolderLock&& o) noexcept;
  OutputFolderLock(const OutputFolderLock&) = delete;
  OutputFolderLock& operator=(const OutputFolderLock&) = delete;

 private:
  int fd_ = -1;
};

// Everything a run does to its output folder before solving: prepare_output_folder(dir, files),
// take the folder's lock, and remove a previous run's summary.json so that a run that is stopped
// cannot leave an old "status: ok" behind.
OutputFolderLock claim_output_folder(const std::string& dir, const std::vector<std::string>& files);

}  // namespace mbdae
