#include "cases/output/sinks.h"

namespace mbdae {

void CsvSink::begin(const RunInfo& info) { csv_.open(path_, *info.columns); }

void CsvSink::sample(const Sample& s) {
  csv_.row(s.row);
  if (csv_.rows() % 256 == 0) csv_.flush();
}

void CsvSink::end(const Result&) { csv_.close(); }

void SummarySink::end(const Result& result) { write_json_file(path_, result.summary); }

}  // namespace mbdae
