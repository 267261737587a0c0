// Coupled-loop speed with the stand-in sides: steps per second and coupling
// overhead per step for 100, 1,000 and 5,000 crack particles, over inproc, ipc
// and tcp, exchanging every step and every 10 steps. The yardstick is a bare
// ZeroMQ PAIR round trip of 64 bytes on the same transport, measured here.
//
//   build/release/bin/hfmpm-bench-coupling [--steps N] [--quick] [--particles N,N,...] [--transports T,T,...]
//
// --particles: crack particle counts (default 100,1000,5000; --quick: 100);
// --transports: any of inproc, ipc, tcp (default all three).
//
// Prints a Markdown table (docs/performance.md holds a copy with the machine).
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <iostream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>
#include <zmq.hpp>

#include "fluid_scene_rules.hpp"
#include "hfmpm/coupling/coupler.hpp"
#include "hfmpm/coupling/process.hpp"
#include "hfmpm/coupling/scene_loader.hpp"
#include "hfmpm/runtime/transport.hpp"
#include "prescribed_fluid_side.hpp"
#include "prescribed_solid_side.hpp"
#include "solid_scene_rules.hpp"

namespace {

using namespace hfmpm;
using coupling::Clock;

// Median wall time of a 64-byte round trip between two threads over the
// transport: the wake-up cost that dominates every exchange.
double round_trip_us(const std::string& transport, int count) {
  zmq::context_t context;
  zmq::socket_t a(context, zmq::socket_type::pair), b(context, zmq::socket_type::pair);
  a.set(zmq::sockopt::linger, 0);
  b.set(zmq::sockopt::linger, 0);
  std::string endpoint;
  if (transport == "inproc") {
    endpoint = "inproc://bench-rt";
    a.bind(endpoint);
  } else if (transport == "ipc") {
    a.bind("ipc:///tmp/hfmpm-bench-rt-" + std::to_string(getpid()));
    endpoint = a.get(zmq::sockopt::last_endpoint);
  } else {
    a.bind("tcp://127.0.0.1:*");
    endpoint = a.get(zmq::sockopt::last_endpoint);
  }
  b.connect(endpoint);
  std::thread echo([&] {
    zmq::message_t m;
    for (int i = 0; i < count; ++i) {
      (void)b.recv(m);
      b.send(m, zmq::send_flags::none);
    }
  });
  std::vector<double> samples;
  const std::string payload(64, 'x');
  for (int i = 0; i < count; ++i) {
    const auto start = Clock::now();
    a.send(zmq::buffer(payload), zmq::send_flags::none);
    zmq::message_t m;
    (void)a.recv(m);
    samples.push_back(coupling::seconds_since(start) * 1e6);
  }
  echo.join();
  std::nth_element(samples.begin(), samples.begin() + count / 2, samples.end());
  return samples[static_cast<std::size_t>(count / 2)];
}

std::unique_ptr<coupling::SideModel> make_side(protocol::Role role, const scene::Scene&) {
  if (role == protocol::SOLID) return solid::make_prescribed_solid_side();
  return fluid::make_prescribed_fluid_side();
}

struct Case {
  int particles;
  std::string transport;
  int exchange_interval;
  int control_interval;
};

coupling::RunSummary run_case(const Case& c, int steps, const std::string& scene_path) {
  // dt = 0.5 * 1e-4 s; no growth so the particle count stays fixed.
  const double length = 1.0;
  const double spacing = length / (c.particles - 1);
  std::vector<std::string> overrides{
      "solid.prescribed_crack.initial_length_m=1.0",
      "solid.prescribed_crack.max_length_m=1.0",
      "solid.prescribed_crack.growth_speed_m_per_s=0",
      "solid.prescribed_crack.spacing_m=" + std::to_string(spacing),
      "time.end_s=" + std::to_string(steps * 5e-5),
      "output.interval_s=" + std::to_string(steps * 5e-5),
      "coupling.transport=" + std::string(c.transport == "inproc" ? "INPROC"
                                          : c.transport == "ipc"  ? "IPC"
                                                                  : "TCP"),
      "coupling.exchange_interval=" + std::to_string(c.exchange_interval),
      "coupling.control_interval=" + std::to_string(c.control_interval),
  };
  const auto scene = coupling::load_scene(scene_path, {solid::scene_rules(), fluid::scene_rules()}, overrides);
  coupling::RunOptions options;
  options.output_dir = "/tmp/hfmpm-bench-coupling";
  options.progress = false;
  options.inproc_factory = make_side;
  return coupling::run_coupled(scene, options);
}

}  // namespace

int main(int argc, char** argv) {
  int steps = 4000;
  std::vector<int> sizes{100, 1000, 5000};
  std::vector<std::string> transports{"inproc", "ipc", "tcp"};
  auto split = [](const std::string& text) {
    std::vector<std::string> items;
    std::stringstream list(text);
    for (std::string item; std::getline(list, item, ',');) items.push_back(item);
    return items;
  };
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--steps" && i + 1 < argc) {
      steps = std::stoi(argv[++i]);
    } else if (arg == "--quick") {
      sizes = {100};
    } else if (arg == "--particles" && i + 1 < argc) {
      sizes.clear();
      for (const auto& item : split(argv[++i])) {
        const int n = std::atoi(item.c_str());
        if (n < 2 || n > 1000000) {
          std::cerr << "--particles: each count must be an integer in [2, 1e6], got '" << item << "'\n";
          return 2;
        }
        sizes.push_back(n);
      }
    } else if (arg == "--transports" && i + 1 < argc) {
      transports = split(argv[++i]);
      for (const auto& t : transports) {
        if (t != "inproc" && t != "ipc" && t != "tcp") {
          std::cerr << "--transports: each must be inproc, ipc or tcp, got '" << t << "'\n";
          return 2;
        }
      }
    } else {
      std::cerr << "usage: hfmpm-bench-coupling [--steps N] [--quick] [--particles N,N,...] [--transports T,T,...]\n";
      return 2;
    }
  }
  const std::string scene_path = std::string(HFMPM_SOURCE_DIR) + "/scenarios/prescribed.scene";

  std::cout << "64-byte ZeroMQ PAIR round trip between two threads (median of 2000):\n\n"
            << "| transport | round trip (us) |\n|---|---|\n";
  std::vector<double> rtt;
  for (const auto& t : transports) {
    rtt.push_back(round_trip_us(t, 2000));
    std::printf("| %s | %.1f |\n", t.c_str(), rtt.back());
  }
  std::cout << "\nCoupled loop with the stand-in sides, " << steps << " steps per run "
            << "(overhead = stepping wall time minus the slower side's compute time, per step):\n\n"
            << "| crack particles | transport | exchange every | control round every | steps/s | overhead (us/step) "
               "| overhead per exchange / round trip |\n|---|---|---|---|---|---|---|\n";
  std::vector<Case> cases;
  for (int n : sizes) {
    for (const auto& t : transports) {
      cases.push_back({n, t, 1, 1});
      cases.push_back({n, t, 1, 20});
      cases.push_back({n, t, 10, 20});
    }
  }
  for (const auto& c : cases) {
    const auto summary = run_case(c, steps, scene_path);
    if (!summary.ok) {
      std::cerr << "run failed: " << summary.error << "\n";
      return 1;
    }
    const double per_exchange = summary.overhead_per_step_us() * c.exchange_interval;
    const std::size_t ti =
        static_cast<std::size_t>(std::find(transports.begin(), transports.end(), c.transport) - transports.begin());
    std::printf("| %d | %s | %d | %d | %.0f | %.1f | %.2f |\n", c.particles, c.transport.c_str(), c.exchange_interval,
                c.control_interval, static_cast<double>(summary.steps) / summary.stepping_wall_s,
                summary.overhead_per_step_us(), per_exchange / rtt[ti]);
    std::fflush(stdout);
  }
  return 0;
}
