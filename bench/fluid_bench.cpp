// Fluid 1D MPM speed: fluid particle-steps per second (particles x steps /
// wall time) in a filled rigid channel with a pressure inlet and an open
// outlet (steady Poiseuille flow, so every step moves fluid through the inlet
// and the outlet as well as the interior). One thread: the fluid is serial.
//
//   build/release/bin/hfmpm-bench-fluid [--steps S] [--cells N,N,...]
//
// --cells: the channel's element counts (default 100,1000,10000); counts of
// 10,000 and more run a tenth of the steps.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "hfmpm/fluid/mpm/solver.hpp"

namespace {

using namespace hfmpm::fluid::mpm;
using hfmpm::CrackGeometry;
using hfmpm::TimeFunction;
using hfmpm::Vec2;

CrackGeometry channel(int cells, double length, double width) {
  CrackGeometry g;
  for (int i = 0; i <= cells; ++i) {
    g.ids.push_back(static_cast<std::uint64_t>(i));
    g.position.emplace_back(length * i / cells, 0.0);
    g.normal.emplace_back(0.0, 1.0);
    g.width.push_back(width);
    g.tip.push_back(0);
  }
  return g;
}

struct Result {
  std::size_t particles = 0;
  double rate = 0, wall = 0;
};

Result run(int cells, int steps) {
  const double L = 1.0, w = 1e-3;
  FluidConfig c;
  c.viscosity = 0.1;
  c.particle_length = 0.5 * L / cells;
  c.inlet.kind = InletConfig::Kind::Pressure;
  c.inlet.pressure = TimeFunction::constant(1e5);
  c.outlet.enabled = true;
  FluidSolver fluid(c);
  const auto crack = channel(cells, L, w);
  fluid.set_crack(crack);
  fluid.fill(L, 0.0);
  for (int k = 0; k < 100; ++k) fluid.step(fluid.stable_dt());  // warm up (allocations, flow established)
  const double dt = fluid.stable_dt();
  double particle_steps = 0;
  const auto start = std::chrono::steady_clock::now();
  for (int k = 0; k < steps; ++k) {
    fluid.set_crack(crack);  // as in a coupled run: the grid arrives every step
    particle_steps += static_cast<double>(fluid.particles().size());
    fluid.step(dt);
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return {fluid.particles().size(), particle_steps / wall, wall};
}

}  // namespace

int main(int argc, char** argv) {
  int steps = 20000;
  std::vector<int> sizes{100, 1000, 10000};
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--steps" && i + 1 < argc) {
      steps = std::atoi(argv[++i]);
    } else if (arg == "--cells" && i + 1 < argc) {
      sizes.clear();
      std::stringstream list(argv[++i]);
      for (std::string item; std::getline(list, item, ',');) {
        const int n = std::atoi(item.c_str());
        if (n < 2 || n > 10000000) {
          std::fprintf(stderr, "--cells: each count must be an integer in [2, 1e7], got '%s'\n", item.c_str());
          return 2;
        }
        sizes.push_back(n);
      }
    } else {
      std::fprintf(stderr, "usage: %s [--steps S] [--cells N,N,...]\n", argv[0]);
      return 2;
    }
  }
  if (steps < 1) {
    std::fprintf(stderr, "--steps must be >= 1\n");
    return 2;
  }
  std::printf("fluid 1D MPM, filled channel with inlet and outlet flow, 1 thread, %d steps\n", steps);
  std::printf("%8s %10s %10s %16s %14s\n", "nodes", "particles", "wall_s", "particle-steps/s", "ns/part-step");
  for (int cells : sizes) {
    const int n = cells >= 10000 ? std::max(1, steps / 10) : steps;
    const Result r = run(cells, n);
    std::printf("%8d %10zu %10.3f %16.3e %14.1f\n", cells + 1, r.particles, r.wall, r.rate, 1e9 / r.rate);
  }
  return 0;
}
