#include "cases/output/sinks.h"

namespace mbdae {

void CsvSink::begin(const RunInfo& info) { csv_.open(path_, *info.columns); }

void CsvSink::sample(const Sample& s) {
  csv_.row(s.row);
  if (csv_.rows() % 256 == 0) csv_.flush();
}

void CsvSink::end(const Result&) { csv_.close(); }

void SummarySink::end(const Result& result) { write_json_file(path_, result.summary); }

RunSinks open_sinks(const Scene& scene, const OutputRequest& request) {
  RunSinks s;
  // The animation's size bound against its disk budget and the free space, before any folder
  // is claimed or changed (cases/output/animation_sink.h).
  if (!request.animation_dir.empty()) check_animation_size(scene, request.animation_dir, request.animation_rate);
  if (!request.out_dir.empty()) {
    s.lock = claim_output_folder(request.out_dir, {"results.csv", "summary.json"});
    // An earlier run's animation files, when this run writes none there.
    if (request.animation_dir != request.out_dir) remove_animation_files(request.out_dir);
    s.csv = std::make_unique<CsvSink>(request.out_dir + "/results.csv");
    s.summary = std::make_unique<SummarySink>(request.out_dir + "/summary.json");
    s.list = {s.csv.get(), s.summary.get()};
  }
  if (!request.animation_dir.empty()) {
    if (request.animation_dir != request.out_dir) prepare_output_folder(request.animation_dir);
    s.animation = std::make_unique<AnimationSink>(scene, request.animation_dir, request.animation_rate);
    s.list.push_back(s.animation.get());
  }
  return s;
}

}  // namespace mbdae
