// The writers of the command line, as sinks of run() (cases/mbdae.h): results.csv (t and one
// column per output sensor, streamed sample by sample) and summary.json (the Result's summary,
// written when the run ends, whether it succeeded or not).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "cases/mbdae.h"
#include "cases/output/animation_sink.h"
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

// sensitivities.csv (RunOptions::sensitivities): the rows of Result::sensitivities as they are
// computed (each sample's row comes after the sample itself: written at the next sample and at
// the end), through PATH.partial like results.csv, so that a killed run keeps whole rows.
// With `normalized_path`, normalized_sensitivities() there when the run ends (it scales by
// each sensor's largest value over the run).
class SensitivityCsvSink : public Sink {
 public:
  SensitivityCsvSink(std::string path, std::string normalized_path)
      : path_(std::move(path)), normalized_path_(std::move(normalized_path)) {}
  void begin(const RunInfo& info) override;
  void sample(const Sample& s) override;
  void end(const Result& result) override;

 private:
  void open(const std::vector<std::string>& columns);
  void write_rows(const Result& r);  // the rows computed since the last call
  std::string path_, normalized_path_;
  const Result* result_ = nullptr;
  CsvWriter csv_;
  bool open_ = false;
  size_t written_ = 0;
  std::vector<double> row_;
};

// summary.json at the end of the run (written atomically: core/output.h write_json_file).
class SummarySink : public Sink {
 public:
  explicit SummarySink(std::string path) : path_(std::move(path)) {}
  void end(const Result& result) override;

 private:
  std::string path_;
};

// What a run writes besides its Result: results.csv and summary.json into `out_dir`, the
// animation into `animation_dir` (each empty: not written).
struct OutputRequest {
  std::string out_dir;
  std::string animation_dir;
  double animation_rate = 0;  // frames per second of simulated time (0: the scene's)
  bool sensitivities = false;  // out_dir/sensitivities.csv (else an earlier run's is removed)
  bool normalized_sensitivities = false;  // also out_dir/sensitivities_normalized.csv
};

// The sinks of one run and the lock of its output folder, held until the run ends. The one
// factory of writers: the CLI and the Python package both call open_sinks.
struct RunSinks {
  OutputFolderLock lock;
  std::unique_ptr<CsvSink> csv;
  std::unique_ptr<SensitivityCsvSink> sensitivities;
  std::unique_ptr<SummarySink> summary;
  std::unique_ptr<AnimationSink> animation;
  std::vector<Sink*> list;  // what run() takes
};

// Claims the output folder (claim_output_folder: lock, previous summary.json removed) and makes
// the sinks of `request`. Throws OutputError when the folder is in use or cannot be written.
RunSinks open_sinks(const Scene& scene, const OutputRequest& request);
// Fresh writers for another run into the same folder (the tries of an error target,
// cases/run/error_target.h), keeping the lock of `sinks`.
void renew_sinks(const Scene& scene, const OutputRequest& request, RunSinks& sinks);

}  // namespace mbdae
