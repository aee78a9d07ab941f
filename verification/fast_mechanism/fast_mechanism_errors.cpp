#include "verification/fast_mechanism/fast_mechanism_errors.h"

#include <algorithm>
#include <cmath>

#include "verification/fast_mechanism/slider_crank_reference.h"

namespace mbdae {

Scene load_fast_mechanism() {
  return load_scene(std::string(MBDAE_SOURCE_DIR) + "/verification/fast_mechanism/slider_crank_fast.yaml");
}

FastMechanismErrors fast_mechanism_errors(const Result& r, double reference_tol) {
  FastMechanismErrors e;
  const std::vector<double>& t = r.column("t");
  const std::vector<SliderCrankSample> ref = slider_crank_reference({}, t, reference_tol);
  e.final_rate = ref.back().rate;
  for (size_t c = 1; c < r.columns.size(); ++c) {
    const std::string& name = r.columns[c];
    double err = 0, scale = 0;
    for (size_t k = 0; k < t.size(); ++k) {
      const double x = ref[k].value(name);
      err = std::max(err, std::fabs(r.data[c][k] - x));
      scale = std::max(scale, std::fabs(x));
    }
    e.sensors.push_back(name);
    e.error.push_back(err);
    e.scale.push_back(scale);
    const bool velocity = name.find("_v") != std::string::npos || name == "crank_rate";
    double& group = velocity ? e.velocity : e.position;
    group = std::max(group, err / scale);
  }
  return e;
}

}  // namespace mbdae
