// The two scenes of verification/redundancy and their errors against the references
// (turning_loops_reference.h): per tracked sensor, the largest |x - x_ref| over the samples and
// the sensor's scale (its largest |x_ref|). Shared by the test and the study.
#pragma once

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "cases/mbdae.h"
#include "verification/redundancy/turning_loops_reference.h"

namespace mbdae {

constexpr double kTurningReferenceStep = 1e-4;

struct TurningCase {
  const char* scene;
  const char* coordinate;  // the reference's theta (a coordinate sensor)
  const char* point;       // the tracked point's sensors: <point>x, <point>vx, ...
  int redundant;           // equations set aside
  double theta0, rate0;
  std::vector<LoopSample> (*reference)(double, double, const std::vector<double>&, double);
};

inline const TurningCase kTurntableFourBar{"turntable_four_bar.yaml", "th", "D", 3, 0.5, 4.0,
                                           turntable_four_bar_reference};
inline const TurningCase kPinnedGovernor{"governor_pinned_links.yaml", "aA", "ball", 6, 0.6, 0.0, governor_reference};

inline Scene load_turning_case(const TurningCase& c) {
  return load_scene(std::string(MBDAE_SOURCE_DIR) + "/verification/redundancy/" + c.scene);
}

struct TurningErrors {
  std::vector<std::string> sensors;
  std::vector<double> error, scale;
  double worst = 0;  // largest error / scale
};

inline TurningErrors turning_errors(const TurningCase& c, const Result& r) {
  const std::vector<double>& t = r.column("t");
  const std::vector<LoopSample> ref = c.reference(c.theta0, c.rate0, t, kTurningReferenceStep);
  TurningErrors e;
  const std::string p = c.point;
  const std::string names[] = {c.coordinate, p + "x", p + "y", p + "z", p + "vx", p + "vy", p + "vz"};
  for (int s = 0; s < 7; ++s) {
    const std::vector<double>& x = r.column(names[s]);
    double err = 0, scale = 0;
    for (size_t k = 0; k < t.size(); ++k) {
      const double xr = s == 0 ? ref[k].theta : s < 4 ? ref[k].point[s - 1] : ref[k].velocity[s - 4];
      err = std::max(err, std::fabs(x[k] - xr));
      scale = std::max(scale, std::fabs(xr));
    }
    e.sensors.push_back(names[s]);
    e.error.push_back(err);
    e.scale.push_back(scale);
    e.worst = std::max(e.worst, err / scale);
  }
  return e;
}

}  // namespace mbdae
