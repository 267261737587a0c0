// Exact orientation test for the crack side tests (after Shewchuk 1997,
// "Adaptive precision floating-point arithmetic and fast robust geometric
// predicates"): a floating-point filter, and when its error bound cannot
// decide, the exact sign from expansion arithmetic (two-sum, FMA products).
#pragma once

#include "hfmpm/exchange.hpp"

namespace hfmpm::solid::mpm {

// +1 if c lies to the left of the directed line a -> b, -1 to the right, 0 on it. Exact.
int orient2d(const Vec2& a, const Vec2& b, const Vec2& c);

// Do the closed segments p-q and a-b cross? A point exactly on the other
// segment's line counts as lying on its left (symbolic perturbation), so a
// line through a vertex shared by two crack segments crosses exactly one.
bool segments_cross(const Vec2& p, const Vec2& q, const Vec2& a, const Vec2& b);

}  // namespace hfmpm::solid::mpm
