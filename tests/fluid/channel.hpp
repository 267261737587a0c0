// Test helpers: straight cracks along +x from the origin, given node arc
// lengths and widths (a rigid channel when the widths stay fixed).
#pragma once

#include <cstdint>
#include <vector>

#include "hfmpm/exchange.hpp"

namespace hfmpm::fluid::mpm::test {

inline std::vector<double> uniform_nodes(double length, int cells) {
  std::vector<double> s(static_cast<std::size_t>(cells) + 1);
  for (std::size_t i = 0; i < s.size(); ++i) s[i] = length * static_cast<double>(i) / cells;
  return s;
}

inline CrackGeometry straight_crack(const std::vector<double>& s, const std::vector<double>& width,
                                    std::uint32_t crack_id = 0, std::uint64_t first_id = 100) {
  CrackGeometry g;
  g.crack_id = crack_id;
  for (std::size_t i = 0; i < s.size(); ++i) {
    g.ids.push_back(first_id + i);
    g.position.push_back(Vec2(s[i], 0));
    g.normal.push_back(Vec2(0, 1));
    g.width.push_back(width[i]);
    g.tip.push_back(i + 1 == s.size() ? 1 : 0);
  }
  return g;
}

inline CrackGeometry channel(double length, int cells, double width) {
  const auto s = uniform_nodes(length, cells);
  return straight_crack(s, std::vector<double>(s.size(), width));
}

}  // namespace hfmpm::fluid::mpm::test
