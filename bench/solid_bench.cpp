// Solid MPM speed: particle-steps per second (particles x steps / wall time)
// with 1 and 2 threads, and memory per particle, for an uncracked block under
// a confining stress with one loaded edge (so every step does real work).
//
//   build/release/bin/hfmpm-bench-solid [--cells N] [--steps S] [--threads T] [--ppc P] [--uncracked-only]
//                                       [--no-roofline]
//
// --cells: the block's cells per side (default 200: 160,000 particles at 2 x 2
// per cell); --threads: only T threads (default: 1, then 2); --ppc: particles
// per cell and direction of the uncracked block (default 2; the coupled KGD
// scenes have 1 in most of the body); --uncracked-only skips the cracked case
// (its size is fixed); --no-roofline skips the bandwidth estimate.
//
// Then a roofline estimate: the machine's memory bandwidth (a STREAM-style
// triad a = b + s c over 3 x 64 MB, 1 and 2 threads, best of 5), the bytes
// one particle-step moves (a model, bytes_moved below), and the throughput
// that bandwidth would allow against the measured one.
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "hfmpm/solid/mpm/solver.hpp"

namespace {

using namespace hfmpm::solid::mpm;
using hfmpm::TimeFunction;
using hfmpm::Vec2;

SolidConfig block(int cells, int threads, int ppc) {
  SolidConfig c;
  c.particles_per_cell = ppc;
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
SolidConfig cracked(int cells_per_a, int threads, int /*ppc: the default*/) {
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

// Bytes one particle-step moves to and from memory, from the arrays the step
// touches (solid/src/mpm/transfer.cpp): P2G reads x, half size, mass, v,
// stress, volume (and displacement with cracks); G2P reads x, half size, v,
// material, stress and writes v, x, stress (with cracks also reads and writes
// displacement and its gradient). The grid's arrays are counted twice per
// step (P2G's accumulators written and reduced, the update and G2P reading
// the fields), shared out per particle. Caches are ignored: the particle
// arrays of the bench (25-40 MB) do not fit in them.
double bytes_moved(const Solver& solid) {
  const auto& p = solid.particles();
  const bool cracked = !solid.cracks().empty();
  const double x = sizeof(p.x[0]), v = sizeof(p.v[0]), stress = sizeof(p.stress[0]);
  const double scalar = sizeof(p.mass[0]), material = sizeof(p.material[0]);
  double bytes = (x + scalar + scalar + v + stress + scalar)  // P2G: x, half size, mass, v, stress, volume
                 + (x + scalar + v + material + stress) + (v + x + stress);  // G2P reads, then writes
  if (cracked) bytes += sizeof(p.displacement[0]) * 3 + sizeof(p.grad_u[0]) * 2;
  return bytes + 2 * static_cast<double>(solid.grid_bytes()) / static_cast<double>(p.size());
}

// Memory bandwidth, GB/s: the triad a[i] = b[i] + s c[i] over arrays far
// larger than the caches, 3 x 8 bytes per element plus the write-allocate
// read of a (32 bytes counted per element), best of 5 passes.
double triad_bandwidth(int threads) {
  const std::size_t n = std::size_t{8} << 20;  // 8 M doubles: 64 MB per array
  std::vector<double> a(n, 0.0), b(n, 1.0), c(n, 2.0);
  double best = 0;
  for (int pass = 0; pass < 5; ++pass) {
    const auto start = std::chrono::steady_clock::now();
    const double s = 0.5 + pass;
#pragma omp parallel for num_threads(threads) schedule(static)
    for (std::size_t i = 0; i < n; ++i) a[i] = b[i] + s * c[i];
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    best = std::max(best, 32.0 * static_cast<double>(n) / wall / 1e9);
  }
  if (a[n / 2] < 0) std::printf("impossible\n");  // keep the stores
  return best;
}

struct Measured {
  double rate = 0, bytes = 0;  // particle-steps/s (2 threads), bytes per particle-step
};

template <class Make>
Measured run(const char* name, Make make, int size, int ppc, int steps, const std::vector<int>& thread_counts) {
  Measured out;
  for (int threads : thread_counts) {
    Solver solid(make(size, threads, ppc));
    if (!solid.cracks().empty()) solid.set_crack_pressure(0, std::vector<double>(solid.cracks()[0].size(), 1e6));
    const double dt = solid.stable_dt();
    solid.step(dt);  // warm up: first touch of the grid
    const auto start = std::chrono::steady_clock::now();
    for (int s = 0; s < steps; ++s) solid.step(dt);
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const double n = static_cast<double>(solid.particles().size());
    std::printf("| %s | %.0f | %d | %d | %.3f | %.3g | %.0f |\n", name, n, threads, steps, wall, n * steps / wall,
                bytes_per_particle(solid));
    out.rate = n * steps / wall;
    out.bytes = bytes_moved(solid);
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  int cells = 200, steps = 200;
  int ppc = 2;
  bool cracked_case = true, roofline = true;
  std::vector<int> thread_counts{1, 2};
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--cells" && i + 1 < argc) {
      cells = std::atoi(argv[++i]);
    } else if (arg == "--steps" && i + 1 < argc) {
      steps = std::atoi(argv[++i]);
    } else if (arg == "--threads" && i + 1 < argc) {
      thread_counts = {std::max(1, std::atoi(argv[++i]))};
    } else if (arg == "--ppc" && i + 1 < argc) {
      ppc = std::atoi(argv[++i]);
    } else if (arg == "--no-roofline") {
      roofline = false;
    } else if (arg == "--uncracked-only") {
      cracked_case = false;
    } else {
      std::fprintf(stderr,
                   "usage: %s [--cells N] [--steps S] [--threads T] [--ppc P] [--uncracked-only] [--no-roofline]\n",
                   argv[0]);
      return 2;
    }
  }
  if (cells < 2 || cells > 4000 || steps < 1 || ppc < 1 || ppc > 4) {
    std::fprintf(stderr, "--cells must be in [2, 4000], --steps >= 1 and --ppc in [1, 4] (got %d, %d, %d)\n", cells,
                 steps, ppc);
    return 2;
  }
  std::printf(
      "| case | particles | threads | steps | wall (s) | particle-steps/s | bytes/particle |\n"
      "|---|---|---|---|---|---|---|\n");
  std::vector<std::pair<std::string, Measured>> cases{
      {"uncracked block", run("uncracked block", block, cells, ppc, steps, thread_counts)}};
  if (cracked_case)
    cases.emplace_back("Sneddon, cracked", run("Sneddon, cracked (h = a/20)", cracked, 20, 2, steps, thread_counts));
  if (!roofline) return 0;
  const double bw1 = triad_bandwidth(1), bw2 = triad_bandwidth(2);
  std::printf("\nmemory bandwidth (triad, best of 5): %.1f GB/s on 1 thread, %.1f GB/s on 2\n", bw1, bw2);
  std::printf(
      "\n| case (2 threads) | bytes moved per particle-step (model) | bandwidth limit (particle-steps/s) | measured | "
      "measured / limit |\n|---|---|---|---|---|\n");
  for (const auto& [name, m] : cases) {
    const double limit = bw2 * 1e9 / m.bytes;
    std::printf("| %s | %.0f | %.3g | %.3g | %.2f |\n", name.c_str(), m.bytes, limit, m.rate, m.rate / limit);
  }
  return 0;
}
