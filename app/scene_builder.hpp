// A scene from physics alone (`hfmpm scene PROBLEM`): a plane-strain (KGD)
// hydraulic fracture given as rock, in-situ stress, fluid, injection,
// duration and notch (proto/hfmpm/problem.proto) becomes a full scene whose
// geometry (cell, body, particles) is sized from that physics. The numerical
// method is left to the run, which derives it from the same physics
// (hfmpm/coupling/method.hpp); the scene's comments list it with its reasons
// (docs/scenes.md, "A scene from physics alone").
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "hfmpm/coupling/method.hpp"
#include "hfmpm/problem.pb.h"

namespace hfmpm::app {

// A problem the builder cannot make a scene for: one line per problem, each
// naming the key, its value and what is allowed.
struct ProblemError : std::runtime_error {
  explicit ProblemError(const std::vector<std::string>& problems);
  std::vector<std::string> problems;
};

// The vertex solutions and Km, as the derived method (hfmpm/coupling/method.hpp) has them.
using method::k_vertex;
using method::m_vertex;
using method::toughness_number;
using method::Vertex;

// What the builder derived (also written into the scene's comments).
// The problem's in-situ stress (compressive magnitudes, Pa) in the grid's
// axes, and its normal, along and shear parts on the notch's plane.
struct NotchStresses {
  double xx = 0, yy = 0, xy = 0;  // sigma_xy of the compressive tensor (tension-positive xy is -xy)
  double normal = 0, along = 0, shear = 0;
  double minimum = 0;  // the smaller principal stress
};
NotchStresses notch_stresses(const problem::Problem& p);
// What is wrong with a problem, one line each ("key = value is not allowed;
// allowed: ..."); empty when build_scene can derive a scene from it.
std::vector<std::string> problem_problems(const problem::Problem& p);

struct Derived {
  double e_prime = 0, km = 0;
  bool viscosity_dominated = true;  // Km < 1: the M-vertex's checks and settings
  // Km < 2: the fluid front closed by the viscous tip solution matched to the
  // fluid (TIP_ASYMPTOTE_MATCHED), else the front's pressure reaches the tip
  // (FRONT_PRESSURE); 2 is the middle of the transition (Km 1 to 4).
  bool matched_closure = true;
  Vertex end;       // the regime's vertex at the end (time shifted by half the ramp)
  double cell = 0;  // m
  double density_scaling = 1;
  double virtual_opening = 0;  // m
  double damping = 0;          // 1/s, the grid's mass-proportional damping
  // Cells the tip grows by at a step and waits for the fluid within: 1/4,
  // or 1/8 or 1/16 for a viscosity-dominated crack on a coarse notch.
  double growth_cells = 0.25;
  int cells_x = 0;  // cells from the crack to the body's edge, along it and across it
  // Where the robustness matrix (docs/verification.md, "Scenes from physics
  // alone") saw runs like this one stall or stop: one line each, also in the
  // scene's comments. Empty: inside what the matrix ran to completion.
  std::vector<std::string> cautions;
  // The numerical method the run derives from the built scene (every key
  // the scene leaves unset), with its rules: also in the scene's comments.
  std::vector<method::Setting> method;
};

struct BuiltScene {
  std::string text;  // the scene, Protobuf text format with comments
  Derived derived;
};

// Parses a problem file's text; a syntax error names the line and column.
problem::Problem parse_problem(const std::string& text, const std::string& name);
// Throws ProblemError for a problem outside what the builder supports.
BuiltScene build_scene(const problem::Problem& problem);

}  // namespace hfmpm::app
