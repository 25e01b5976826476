// A time history for prescribed motions (deck `curve`, LS-DYNA *DEFINE_CURVE): piecewise
// linear through points (t, value) with t strictly increasing, held at its end values
// outside [t_first, t_last]. (LS-DYNA extrapolates with the end segments' slopes; a ramp
// [[0, 0], [1e-4, 1]] that kept rising after 0.1 ms would surprise a deck's reader, so
// anvil holds the end value, and the keyword reader warns where the two differ.)
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
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

// Why `amplitude` times this curve cannot be a time history (of a prescribed motion or a
// body load), or "" when it can: a displacement history starts from the initial position
// (0 at t = 0, to round-off of its largest value); the values, and a displacement's rates
// (the velocities it prescribes), must be finite numbers.
inline std::string time_history_problem(double amplitude, const TimeCurve& c, bool displacement) {
  auto text = [](const char* format, double x) {
    char buf[256];
    std::snprintf(buf, sizeof buf, format, x);
    return std::string(buf);
  };
  double largest = 0;
  for (const double v : c.value) largest = std::max(largest, std::abs(v));
  if (displacement && std::abs(c.at(0.0)) > 1e-12 * largest)
    return text("a displacement history starts from the initial position: its value at t = 0 "
                "must be 0, found %g",
                c.at(0.0));
  for (std::size_t k = 0; k < c.t.size(); ++k) {
    // (Times whose span overflows made every value between them 0, QA round 25.)
    if (k > 0 && !std::isfinite(c.t[k] - c.t[k - 1]))
      return text("the times before t = %g span more than a number can hold (their "
                  "difference overflows)",
                  c.t[k]);
    if (!std::isfinite(amplitude * c.value[k]))
      return text("the value at t = %g overflows (the scale factor times the curve is not a "
                  "finite number)",
                  c.t[k]);
    if (displacement && k > 0 &&
        !std::isfinite(amplitude * ((c.value[k] - c.value[k - 1]) / (c.t[k] - c.t[k - 1]))))
      return text("the velocity this displacement history prescribes before t = %g overflows "
                  "(points too close in time for their values)",
                  c.t[k]);
  }
  return {};
}

} // namespace anvil
