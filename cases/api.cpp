// The public API (cases/mbdae.h) over the staged run in cases/run_scene.cpp.
#include <stdexcept>

#include "cases/mbdae.h"
#include "cases/run_scene.h"

namespace mbdae {

std::vector<std::string> formulations() { return {"index3", "index3-positions", "index2-ggl", "index1", "penalty"}; }

int Result::column_index(const std::string& name) const {
  for (size_t k = 0; k < columns.size(); ++k)
    if (columns[k] == name) return static_cast<int>(k);
  return -1;
}

const std::vector<double>& Result::column(const std::string& name) const {
  const int k = column_index(name);
  if (k < 0) throw std::out_of_range("no column named '" + name + "'");
  return data[k];
}

void set_parameter(Scene& scene, const std::string& path, const std::string& yaml_value) {
  scene = reload_scene(scene, {{path, yaml_value}});
}

Scene with_parameters(const Scene& scene, const std::vector<std::pair<std::string, std::string>>& overrides) {
  return reload_scene(scene, overrides);
}

Result run(const Scene& scene, const RunOptions& options, const std::vector<Sink*>& sinks) {
  RunOutcome o = run_scene(scene, options, sinks);
  Result r;
  r.exit_code = o.exit_code;
  r.summary = std::move(o.summary);
  r.status = r.summary.value("status", std::string("running"));
  r.message = r.summary.value("message", std::string());
  if (options.stop && options.stop->load() && r.status == "ok") r.status = "interrupted";
  r.columns = std::move(o.columns);
  r.units = std::move(o.units);
  r.data.assign(r.columns.size(), {});
  for (auto& col : r.data) col.reserve(o.rows.size());
  for (const auto& row : o.rows)
    for (size_t c = 0; c < row.size() && c < r.data.size(); ++c) r.data[c].push_back(row[c]);
  r.q = std::move(o.q);
  for (Sink* s : sinks) s->end(r);
  return r;
}

}  // namespace mbdae
