// The scene-rule toolkit shared by the coupler's and the sides' rules
// (hfmpm/proto/scene_rules.hpp).
#include "hfmpm/proto/scene_rules.hpp"

#include <set>

#include "hfmpm/proto/envelope.hpp"

namespace hfmpm::proto {

// `min_value`: the smallest value the function may take (e.g. 0 for an opening).
void check_time_function(Checker& c, const std::string& key, const scene::TimeFunction& f, double min_value,
                         const std::string& unit) {
  switch (f.kind_case()) {
    case scene::TimeFunction::KIND_NOT_SET:
      c.missing(key, "one of constant, ramp, table, power");
      return;
    case scene::TimeFunction::kConstant:
      c.range(key + ".constant", f.constant(), min_value, kInf, false, unit);
      return;
    case scene::TimeFunction::kRamp: {
      const auto& r = f.ramp();
      if (!r.has_t1())
        c.missing(key + ".ramp.t1", "the ramp's end time t1 (s), > t0");
      else
        c.range(key + ".ramp.t1", r.t1(), r.t0(), kInf, true, "s, > ramp.t0");
      c.range(key + ".ramp.t0", r.t0(), -kInf, kInf, false, "s");
      c.range(key + ".ramp.v0", r.v0(), min_value, kInf, false, unit);
      if (!r.has_v1())
        c.missing(key + ".ramp.v1", "the ramp's end value v1 (" + unit + ")");
      else
        c.range(key + ".ramp.v1", r.v1(), min_value, kInf, false, unit);
      return;
    }
    case scene::TimeFunction::kTable: {
      const auto& t = f.table();
      if (t.t_size() < 2 || t.t_size() != t.v_size()) {
        c.bad(key + ".table", std::to_string(t.t_size()) + " times, " + std::to_string(t.v_size()) + " values",
              "at least 2 points, with as many values 'v' as times 't'");
        return;
      }
      for (int i = 0; i < t.t_size(); ++i) {
        const std::string k = key + ".table.t[" + std::to_string(i) + "]";
        if (!std::isfinite(t.t(i)))
          c.bad(k, text(t.t(i)), "a finite time (s)");
        else if (i > 0 && !(t.t(i) > t.t(i - 1)))
          c.bad(k, text(t.t(i)), "times strictly increasing, > " + text(t.t(i - 1)));
        c.range(key + ".table.v[" + std::to_string(i) + "]", t.v(i), min_value, kInf, false, unit);
      }
      return;
    }
    case scene::TimeFunction::kPower: {
      const auto& p = f.power();
      if (!p.has_scale())
        c.missing(key + ".power.scale", "the scale (" + unit + ")");
      else
        c.range(key + ".power.scale", p.scale(), min_value, kInf, false, unit);
      c.positive(key + ".power.t_ref", p.t_ref(), "s");
      if (!p.has_exponent())
        c.missing(key + ".power.exponent", "the exponent, >= 0");
      else
        c.non_negative(key + ".power.exponent", p.exponent(), "");
      return;
    }
  }
}

namespace {

// Every double and float field set anywhere in `message` (repeated and
// nested ones included) that is NaN or infinite, as problems keyed by its path
// ("solid.mpm.cracks[0].x_m[1]"); non_finite_numbers finds them by reflection,
// so a new field is covered without code here.
void check_finite(Checker& c, const google::protobuf::Message& message) {
  for (const auto& n : non_finite_numbers(message)) {
    c.bad(n.path, text(n.value), "a finite number: every number in a scene must be finite");
  }
}

}  // namespace

std::vector<SceneProblem> finite_first(std::vector<SceneProblem> problems, const google::protobuf::Message& message) {
  Checker finite;
  check_finite(finite, message);
  const auto not_finite = finite.take();
  if (not_finite.empty()) return problems;
  std::set<std::string> keys;
  for (const auto& p : not_finite) keys.insert(p.key);
  std::vector<SceneProblem> out;
  std::set<std::string> reported;
  for (auto& p : problems) {
    // The key's own rule wins where it says what is wrong (a finite value in a range).
    const bool says_finite = p.allowed.find("finite") != std::string::npos;
    if (keys.count(p.key) && says_finite && reported.insert(p.key).second) out.push_back(std::move(p));
  }
  for (const auto& p : not_finite) {
    if (!reported.count(p.key)) out.push_back(p);
  }
  return out;
}

std::string problem_text(const SceneProblem& p) {
  if (p.value.empty()) return p.key + " is missing; expected " + p.allowed;
  return p.key + " = " + p.value + " is not allowed; expected " + p.allowed;
}

std::vector<std::string> side_scene_problems(const scene::Scene& scene, const SideSceneRules& rules) {
  Checker c;
  if (rules.check) rules.check(c, scene);
  std::vector<std::string> lines;
  for (const auto& p : finite_first(c.take(), scene)) lines.push_back(problem_text(p));
  return lines;
}

}  // namespace hfmpm::proto
