#include "core/time_function.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace mbdae {
namespace {
constexpr double kTwoPi = 6.283185307179586476925286766559;

// Index i such that ts[i] <= t < ts[i+1]; -1 before the first knot, n-1 after the last.
int segment(const std::vector<double>& ts, double t) {
  if (t < ts.front()) return -1;
  auto it = std::upper_bound(ts.begin(), ts.end(), t);
  return static_cast<int>(it - ts.begin()) - 1;
}
}  // namespace

double TimeFunction::value(double t) const {
  switch (kind) {
    case Kind::kConstant: return a;
    case Kind::kStep: return t < t0 ? a : b;
    case Kind::kSine: return a * std::sin(kTwoPi * b * t + c) + d;
    case Kind::kSweep: {
      if (t < t0) return 0.0;
      const double s = t - t0, k = (c - b) / (t1 - t0);
      return a * std::sin(kTwoPi * (b * s + 0.5 * k * s * s));
    }
    case Kind::kPiecewiseLinear: {
      const int i = segment(ts, t);
      if (i < 0) return ys.front();
      if (i >= static_cast<int>(ts.size()) - 1) return ys.back();
      const double w = (t - ts[i]) / (ts[i + 1] - ts[i]);
      return ys[i] + w * (ys[i + 1] - ys[i]);
    }
    case Kind::kPolynomial: {
      double v = 0;
      for (auto it = ys.rbegin(); it != ys.rend(); ++it) v = v * t + *it;
      return v;
    }
  }
  return 0.0;
}

double TimeFunction::derivative(double t) const {
  switch (kind) {
    case Kind::kConstant:
    case Kind::kStep: return 0.0;
    case Kind::kSine: return a * kTwoPi * b * std::cos(kTwoPi * b * t + c);
    case Kind::kSweep: {
      if (t < t0) return 0.0;
      const double s = t - t0, k = (c - b) / (t1 - t0);
      const double phase = kTwoPi * (b * s + 0.5 * k * s * s), rate = kTwoPi * (b + k * s);
      return a * rate * std::cos(phase);
    }
    case Kind::kPiecewiseLinear: {
      const int i = segment(ts, t);
      if (i < 0 || i >= static_cast<int>(ts.size()) - 1) return 0.0;
      return (ys[i + 1] - ys[i]) / (ts[i + 1] - ts[i]);
    }
    case Kind::kPolynomial: {
      double v = 0;
      for (int i = static_cast<int>(ys.size()) - 1; i >= 1; --i) v = v * t + i * ys[i];
      return v;
    }
  }
  return 0.0;
}

double TimeFunction::second_derivative(double t) const {
  switch (kind) {
    case Kind::kConstant:
    case Kind::kStep:
    case Kind::kPiecewiseLinear: return 0.0;
    case Kind::kSine: return -a * kTwoPi * b * kTwoPi * b * std::sin(kTwoPi * b * t + c);
    case Kind::kSweep: {
      if (t < t0) return 0.0;
      const double s = t - t0, k = (c - b) / (t1 - t0);
      const double phase = kTwoPi * (b * s + 0.5 * k * s * s), rate = kTwoPi * (b + k * s);
      return a * (kTwoPi * k * std::cos(phase) - rate * rate * std::sin(phase));
    }
    case Kind::kPolynomial: {
      double v = 0;
      // i (i - 1) in double: from degree 46342 on it does not fit an int.
      for (int i = static_cast<int>(ys.size()) - 1; i >= 2; --i) v = v * t + double(i) * (i - 1) * ys[i];
      return v;
    }
  }
  return 0.0;
}

std::vector<double> TimeFunction::breakpoints() const {
  switch (kind) {
    case Kind::kStep: return {t0};
    case Kind::kSweep: return {t0};
    case Kind::kPiecewiseLinear: return ts;
    default: return {};
  }
}

std::string TimeFunction::describe() const {
  std::ostringstream os;
  switch (kind) {
    case Kind::kConstant: os << "constant " << a; break;
    case Kind::kStep: os << "step " << a << " -> " << b << " at " << t0; break;
    case Kind::kSine: os << "sine"; break;
    case Kind::kSweep: os << "sweep " << b << ".." << c << " Hz"; break;
    case Kind::kPiecewiseLinear: os << "piecewise linear, " << ts.size() << " knots"; break;
    case Kind::kPolynomial: os << "polynomial of degree " << ys.size() - 1; break;
  }
  return os.str();
}

}  // namespace mbdae
