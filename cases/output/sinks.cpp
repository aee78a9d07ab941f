#include "cases/output/sinks.h"

#include <cerrno>
#include <cstdio>
#include <cstring>

namespace mbdae {

void CsvSink::begin(const RunInfo& info) { csv_.open(path_, *info.columns); }

void CsvSink::sample(const Sample& s) {
  csv_.row(s.row);
  if (csv_.rows() % 256 == 0) csv_.flush();
}

void CsvSink::end(const Result&) { csv_.close(); }

namespace {

// Whole columns (column-major) to PATH through CsvWriter.
void write_columns(const std::string& path, const std::vector<std::string>& names,
                   const std::vector<std::vector<double>>& data) {
  CsvWriter csv;
  csv.open(path, names);
  std::vector<double> row(names.size());
  const size_t rows = data.empty() ? 0 : data[0].size();
  for (size_t i = 0; i < rows; ++i) {
    for (size_t k = 0; k < row.size(); ++k) row[k] = data[k][i];
    csv.row(row.data());
  }
  csv.close();
}

}  // namespace

void SensitivityCsvSink::open(const std::vector<std::string>& columns) {
  csv_.open(path_, columns);
  row_.resize(columns.size());
  open_ = true;
}

void SensitivityCsvSink::begin(const RunInfo& info) {
  result_ = info.result;
  if (!open_ && result_ && !result_->sensitivity_columns.empty()) open(result_->sensitivity_columns);
}

void SensitivityCsvSink::sample(const Sample&) {
  if (open_) write_rows(*result_);
}

void SensitivityCsvSink::write_rows(const Result& r) {
  const size_t rows = r.sensitivities.empty() ? 0 : r.sensitivities[0].size();
  for (; written_ < rows; ++written_) {
    for (size_t k = 0; k < row_.size(); ++k) row_[k] = r.sensitivities[k][written_];
    csv_.row(row_.data());
    if (csv_.rows() % 256 == 0) csv_.flush();
  }
}

void SensitivityCsvSink::end(const Result& r) {
  if (r.sensitivity_columns.empty()) return;
  if (!open_) open(r.sensitivity_columns);  // no integration step (static steps only): the header
  write_rows(r);
  csv_.close();
  if (normalized_path_.empty()) return;
  const NormalizedSensitivities n = normalized_sensitivities(r);
  write_columns(normalized_path_, n.columns, n.data);
}

void SummarySink::end(const Result& result) { write_json_file(path_, result.summary); }

RunSinks open_sinks(const Scene& scene, const OutputRequest& request) {
  RunSinks s;
  // The animation's size bound against its disk budget and the free space, before any folder
  // is claimed or changed (cases/output/animation_sink.h).
  if (!request.animation_dir.empty()) check_animation_size(scene, request.animation_dir, request.animation_rate);
  if (!request.out_dir.empty()) {
    s.lock = claim_output_folder(request.out_dir,
                                 {"results.csv", "summary.json", "sensitivities.csv", "sensitivities_normalized.csv"});
    // An earlier run's sensitivities, which this run does not replace.
    for (const auto& [name, written] : {std::pair<const char*, bool>{"sensitivities.csv", request.sensitivities},
                                        {"sensitivities_normalized.csv", request.normalized_sensitivities}}) {
      const std::string old = request.out_dir + "/" + name;
      if (!written && std::remove(old.c_str()) != 0 && errno != ENOENT)
        throw OutputError("cannot remove the previous run's " + old + ": " + std::strerror(errno));
    }
    // An earlier run's animation files, when this run writes none there.
    if (request.animation_dir != request.out_dir) remove_animation_files(request.out_dir);
  }
  renew_sinks(scene, request, s);
  return s;
}

void renew_sinks(const Scene& scene, const OutputRequest& request, RunSinks& s) {
  s.list.clear();
  if (!request.out_dir.empty()) {
    s.csv = std::make_unique<CsvSink>(request.out_dir + "/results.csv");
    s.summary = std::make_unique<SummarySink>(request.out_dir + "/summary.json");
    s.list = {s.csv.get()};
    if (request.sensitivities) {
      s.sensitivities = std::make_unique<SensitivityCsvSink>(
          request.out_dir + "/sensitivities.csv",
          request.normalized_sensitivities ? request.out_dir + "/sensitivities_normalized.csv" : "");
      s.list.push_back(s.sensitivities.get());
    }
    s.list.push_back(s.summary.get());
  }
  if (!request.animation_dir.empty()) {
    if (request.animation_dir != request.out_dir) prepare_output_folder(request.animation_dir);
    s.animation = std::make_unique<AnimationSink>(scene, request.animation_dir, request.animation_rate);
    s.list.push_back(s.animation.get());
  }
}

}  // namespace mbdae
