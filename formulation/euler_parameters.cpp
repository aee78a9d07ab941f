#include "formulation/euler_parameters.h"

#include <cmath>

namespace mbdae {

Vec4 euler_parameters_from_rotation(const Mat3& a) {
  // Shepperd: pick the largest of 4 e0^2, 4 e1^2, ... to divide by.
  const double tr = a.trace();
  Vec4 p;
  const double d[4] = {tr, a(0, 0), a(1, 1), a(2, 2)};
  int k = 0;
  for (int i = 1; i < 4; ++i)
    if (d[i] > d[k]) k = i;
  if (k == 0) {
    const double s = 2.0 * std::sqrt(1.0 + tr);
    p << 0.25 * s, (a(2, 1) - a(1, 2)) / s, (a(0, 2) - a(2, 0)) / s, (a(1, 0) - a(0, 1)) / s;
  } else if (k == 1) {
    const double s = 2.0 * std::sqrt(1.0 + 2.0 * a(0, 0) - tr);
    p << (a(2, 1) - a(1, 2)) / s, 0.25 * s, (a(0, 1) + a(1, 0)) / s, (a(0, 2) + a(2, 0)) / s;
  } else if (k == 2) {
    const double s = 2.0 * std::sqrt(1.0 + 2.0 * a(1, 1) - tr);
    p << (a(0, 2) - a(2, 0)) / s, (a(0, 1) + a(1, 0)) / s, 0.25 * s, (a(1, 2) + a(2, 1)) / s;
  } else {
    const double s = 2.0 * std::sqrt(1.0 + 2.0 * a(2, 2) - tr);
    p << (a(1, 0) - a(0, 1)) / s, (a(0, 2) + a(2, 0)) / s, (a(1, 2) + a(2, 1)) / s, 0.25 * s;
  }
  if (p[0] < 0) p = -p;
  return p.normalized();
}

Mat3 axis_rotation(int axis, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  Mat3 r = Mat3::Identity();
  const int j = (axis + 1) % 3, k = (axis + 2) % 3;
  r(j, j) = c;
  r(j, k) = -s;
  r(k, j) = s;
  r(k, k) = c;
  return r;
}

}  // namespace mbdae
