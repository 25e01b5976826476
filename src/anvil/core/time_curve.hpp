// A time history for prescribed motions (deck `curve`, LS-DYNA *DEFINE_CURVE): piecewise
// linear through points (t, value) with t strictly increasing, held at its end values
// outside [t_first, t_last]. (LS-DYNA extrapolates with the end segments' slopes; a ramp
// [[0, 0], [1e-4, 1]] that kept rising after 0.1 ms would surprise a deck's reader, so
// anvil holds the end value, and the keyword reader warns where the two differ.)
#pragma once

#include <algorithm>
#include <cstddef>
#include <string>
#include <vector>

namespace anvil {

struct TimeCurve {
  std::vector<double> t;     // strictly increasing, at least one point
  std::vector<double> value; // same size

  double at(double time) const {
    if (time <= t.front()) return value.front();
    if (time >= t.back()) return value.back();
    const auto k = static_cast<std::size_t>(std::upper_bound(t.begin(), t.end(), time) - t.begin());
    const double s = (time - t[k - 1]) / (t[k] - t[k - 1]);
    return value[k - 1] + s * (value[k] - value[k - 1]);
  }

  // The slope of the segment that starts at or before `time` and ends after it (0 outside
  // the points): the rate at t+, where the curve has a corner.
  double slope_after(double time) const {
    if (time < t.front() || time >= t.back()) return 0.0;
    const auto k = static_cast<std::size_t>(std::upper_bound(t.begin(), t.end(), time) - t.begin());
    return (value[k] - value[k - 1]) / (t[k] - t[k - 1]);
  }
};

// Why a curve cannot be a displacement history (it must start from the initial position,
// 0 at t = 0), or "" when it can.
inline std::string displacement_history_problem(const TimeCurve& c) {
  const double d0 = c.at(0.0);
  if (d0 == 0.0) return {};
  return "a displacement history starts from the initial position: its value at t = 0 must "
         "be 0, found " +
         std::to_string(d0);
}

} // namespace anvil
