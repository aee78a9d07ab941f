// The writers of the command line, as sinks of run() (cases/mbdae.h): results.csv (t and one
// column per output sensor, streamed sample by sample) and summary.json (the Result's summary,
// written when the run ends, whether it succeeded or not).
#pragma once

#include <string>

#include "cases/mbdae.h"
#include "core/output.h"

namespace mbdae {

// Rows go to PATH.partial as they come (flushed every 256 rows, so a failing run keeps what it
// computed) and the file is renamed to PATH when the run ends (core/output.h CsvWriter).
class CsvSink : public Sink {
 public:
  explicit CsvSink(std::string path) : path_(std::move(path)) {}
  void begin(const RunInfo& info) override;
  void sample(const Sample& s) override;
  void end(const Result& result) override;

 private:
  std::string path_;
  CsvWriter csv_;
};

// summary.json at the end of the run (written atomically: core/output.h write_json_file).
class SummarySink : public Sink {
 public:
  explicit SummarySink(std::string path) : path_(std::move(path)) {}
  void end(const Result& result) override;

 private:
  std::string path_;
};

}  // namespace mbdae
