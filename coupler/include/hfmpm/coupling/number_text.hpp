// Numbers as the scene builder and the derived method write them.
#pragma once

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace hfmpm::text {

inline std::string join(const std::vector<std::string>& lines) {
  std::string out;
  for (const auto& l : lines) out += (out.empty() ? "" : "\n") + l;
  return out;
}

inline std::string num(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.6g", v);
  return buffer;
}

// Grid and region bounds: whole (or half) multiples of the cell, written with
// 12 digits so that the scene's own check of whole cells holds (6 lost it).
inline std::string exact(double v) {
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.12g", v);
  return buffer;
}

// For the comments: three significant digits.
inline std::string approx(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.3g", v);
  return buffer;
}

// x rounded to `digits` significant digits, down (floor) or to nearest.
inline double significant(double x, int digits, bool down) {
  if (!(x > 0)) return x;
  const double scale = std::pow(10.0, digits - 1 - static_cast<int>(std::floor(std::log10(x))));
  return (down ? std::floor(x * scale) : std::round(x * scale)) / scale;
}

}  // namespace hfmpm::text
