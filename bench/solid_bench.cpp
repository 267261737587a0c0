// Solid MPM speed: particle-steps per second (particles x steps / wall time)
// with 1 and 2 threads, and memory per particle, for an uncracked block under
// a confining stress with one loaded edge (so every step does real work).
//
//   build/release/bin/hfmpm-bench-solid [--cells N] [--steps S] [--uncracked-only]
//
// --cells: the block's cells per side (default 200: 160,000 particles at 2 x 2
// per cell); --uncracked-only skips the cracked case (its size is fixed).
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
  c.tractions = {{Edge::Right, TimeFunction::constant(-1e6)},
                 {Edge::Top, TimeFunction::table({0.0, 1.0}, {-1e6, -2e6})}};
  c.damping.grid_alpha = 100;
  c.threads = threads;
  return c;
}

// Sneddon's set-up (bench only): half box 5a x 10a, crack from the symmetry
// plane to x = a with uniform face pressure, h = a / cells_per_a.
SolidConfig cracked(int cells_per_a, int threads) {
  SolidConfig c;
  const double h = 1.0 / cells_per_a;
  c.grid.origin = Vec2(0, -5 - 2 * h);
  c.grid.h = h;
  c.grid.nx = 5 * cells_per_a + 2;
  c.grid.ny = 10 * cells_per_a + 4;
  c.materials = {{"rock", 1e10, 0.25, 2500}};
  Region r;
  r.lo = Vec2(0, -5);
  r.hi = Vec2(5, 5);
  c.regions = {r};
  c.constraints = {{Constraint::Kind::PlaneX, 0.0}};
  CrackSpec crack;
  for (int k = 0; k <= 2 * cells_per_a; ++k) crack.points.emplace_back(k / (2.0 * cells_per_a), 0.0);
  c.cracks = {crack};
  c.damping.grid_alpha = 688;
  c.threads = threads;
  return c;
}

// Bytes the solver holds per particle: the particle arrays as allocated (x, v,
// mass, volume, half size, stress, material; displacement and its gradient
// only in cracked scenes) plus the grid's arrays as allocated / particles.
double bytes_per_particle(const Solver& solid) {
  const auto& p = solid.particles();
  auto bytes = [](const auto& v) { return static_cast<double>(v.capacity() * sizeof(v[0])); };
  const double particle = (bytes(p.x) + bytes(p.v) + bytes(p.displacement) + bytes(p.grad_u) + bytes(p.mass) +
                           bytes(p.volume) + bytes(p.half_size) + bytes(p.stress) + bytes(p.material)) /
                          static_cast<double>(p.size());
  const double grid = static_cast<double>(solid.grid_bytes());  // fields, velocities, P2G's accumulators
  return particle + grid / static_cast<double>(p.size());
}

template <class Make>
void run(const char* name, Make make, int size, int steps) {
  for (int threads : {1, 2}) {
    Solver solid(make(size, threads));
    if (!solid.cracks().empty()) solid.set_crack_pressure(0, std::vector<double>(solid.cracks()[0].size(), 1e6));
    const double dt = solid.stable_dt();
    solid.step(dt);  // warm up: first touch of the grid
    const auto start = std::chrono::steady_clock::now();
    for (int s = 0; s < steps; ++s) solid.step(dt);
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const double n = static_cast<double>(solid.particles().size());
    std::printf("| %s | %.0f | %d | %d | %.3f | %.3g | %.0f |\n", name, n, threads, steps, wall, n * steps / wall,
                bytes_per_particle(solid));
  }
}

}  // namespace

int main(int argc, char** argv) {
  int cells = 200, steps = 200;
  bool cracked_case = true;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--cells" && i + 1 < argc) {
      cells = std::atoi(argv[++i]);
    } else if (arg == "--steps" && i + 1 < argc) {
      steps = std::atoi(argv[++i]);
    } else if (arg == "--uncracked-only") {
      cracked_case = false;
    } else {
      std::fprintf(stderr, "usage: %s [--cells N] [--steps S] [--uncracked-only]\n", argv[0]);
      return 2;
    }
  }
  if (cells < 2 || cells > 4000 || steps < 1) {
    std::fprintf(stderr, "--cells must be in [2, 4000] and --steps >= 1 (got %d, %d)\n", cells, steps);
    return 2;
  }
  std::printf(
      "| case | particles | threads | steps | wall (s) | particle-steps/s | bytes/particle |\n"
      "|---|---|---|---|---|---|---|\n");
  run("uncracked block", block, cells, steps);
  if (cracked_case) run("Sneddon, cracked (h = a/20)", cracked, 20, steps);
  return 0;
}
