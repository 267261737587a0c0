// The rules a scene must satisfy before any process starts. Each rule names
// the key and what is allowed; the loader adds file and line.
#include <google/protobuf/descriptor.h>
#include <google/protobuf/message.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <sstream>

#include "hfmpm/coupling/scene_loader.hpp"
#include "scene_checker.hpp"

namespace hfmpm::coupling {

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

void check_time(Checker& c, const scene::Scene& s) {
  if (!s.has_time() || !s.time().has_end_s()) {
    c.missing("time.end_s", "the end time in seconds, > 0");
  } else {
    c.positive("time.end_s", s.time().end_s(), "s");
  }
  c.range("time.safety_factor", s.time().safety_factor(), 0, 1, true, "fraction of the smallest stable step");
  if (s.time().max_steps() == 0) c.bad("time.max_steps", "0", "an integer >= 1");
  const double end = s.time().end_s();
  const bool end_valid = s.time().has_end_s() && std::isfinite(end) && end > 0;
  const double upper = end_valid ? end : kInf;  // NOLINT(bugprone-narrowing-conversions): clang-tidy 14 misreads inf
  c.range("output.interval_s", s.output().interval_s(), 0, upper, false, "s, 0 for end_s / 100");
  c.range("output.checkpoint_interval_s", s.output().checkpoint_interval_s(), 0, upper, false,
          "s, 0 for no checkpoints");
  if (s.output().checkpoint_interval_s() > 0 &&
      ((s.has_solid() && s.solid().has_prescribed_crack()) || (s.has_fluid() && s.fluid().has_prescribed_pressure()))) {
    std::ostringstream value;
    value << s.output().checkpoint_interval_s();
    c.bad("output.checkpoint_interval_s", value.str(),
          "0 with a stand-in side (solid.prescribed_crack, fluid.prescribed_pressure): the stand-ins do not write "
          "checkpoints; only the MPM sides do");
  }
}

void check_coupling(Checker& c, const scene::Coupling& k) {
  if (k.transport() == scene::Coupling::TRANSPORT_UNSPECIFIED) {
    c.bad("coupling.transport", "TRANSPORT_UNSPECIFIED", "IPC, TCP or INPROC");
  }
  if (k.scheme() == scene::Coupling::SCHEME_UNSPECIFIED) {
    c.bad("coupling.scheme", "SCHEME_UNSPECIFIED", "JACOBI, GAUSS_SEIDEL or IMPLICIT");
  }
  if (k.scheme() == scene::Coupling::IMPLICIT && k.exchange_interval() != 1) {
    c.bad("coupling.exchange_interval", std::to_string(k.exchange_interval()),
          "1 with coupling.scheme = IMPLICIT (the fluid needs the solid's response over every step)");
  }
  if (k.exchange_interval() < 1 || k.exchange_interval() > 10000) {
    c.bad("coupling.exchange_interval", std::to_string(k.exchange_interval()), "an integer from 1 to 10000 (steps)");
  }
  if (k.control_interval() < 1 || k.control_interval() > 1000000) {
    c.bad("coupling.control_interval", std::to_string(k.control_interval()), "an integer from 1 to 1000000 (steps)");
  }
  c.range("coupling.heartbeat_interval_s", k.heartbeat_interval_s(), 0.01, 60, false, "s");
  c.range("coupling.heartbeat_timeout_s", k.heartbeat_timeout_s(), 2 * k.heartbeat_interval_s(), 3600, true,
          "s, more than twice coupling.heartbeat_interval_s");
  if (k.heartbeat_timeout_s() < 0.5) {
    c.bad("coupling.heartbeat_timeout_s", text(k.heartbeat_timeout_s()),
          "at least 0.5 s (sides send heartbeats every 0.1 s before they know the scene)");
  }
  c.range("coupling.setup_timeout_s", k.setup_timeout_s(), 0, 86400, true, "s");
  c.range("coupling.step_timeout_s", k.step_timeout_s(), 0, 86400, true, "s");
  c.range("coupling.join_timeout_s", k.join_timeout_s(), 0, 86400, true, "s");
  if (k.tcp_host().empty()) c.bad("coupling.tcp_host", "\"\"", "a host name or address to bind, e.g. 127.0.0.1");
  if (k.spin_us() > 1000000) c.bad("coupling.spin_us", std::to_string(k.spin_us()), "0 to 1000000 (us)");
  c.range("coupling.energy_bound", k.energy_bound(), 0, 1e12, false,
          "0 (no check) or a factor: the solid's kinetic energy may reach it x the fluid's inlet work plus p0 V0");
}

void check_prescribed_crack(Checker& c, const scene::PrescribedCrack& p) {
  const std::string key = "solid.prescribed_crack.";
  c.range(key + "mouth_x_m", p.mouth_x_m(), -kInf, kInf, false, "m");
  c.range(key + "mouth_y_m", p.mouth_y_m(), -kInf, kInf, false, "m");
  c.range(key + "angle_deg", p.angle_deg(), -180, 180, false, "degrees");
  if (!p.has_initial_length_m())
    c.missing(key + "initial_length_m", "the initial crack length (m), > 0");
  else
    c.positive(key + "initial_length_m", p.initial_length_m(), "m");
  c.non_negative(key + "growth_speed_m_per_s", p.growth_speed_m_per_s(), "m/s");
  const double max_length = p.has_max_length_m() ? p.max_length_m() : p.initial_length_m();
  if (p.has_max_length_m()) {
    c.range(key + "max_length_m", p.max_length_m(), p.initial_length_m(), kInf, false, "m, >= initial_length_m");
  } else if (p.growth_speed_m_per_s() > 0) {
    c.missing(key + "max_length_m",
              "the length where growth stops (m), >= initial_length_m, with growth_speed_m_per_s > 0");
  }
  if (!p.has_spacing_m()) {
    c.missing(key + "spacing_m", "the crack-particle spacing (m), > 0");
  } else {
    c.range(key + "spacing_m", p.spacing_m(), 0, p.initial_length_m(), true, "m, at most initial_length_m");
    if (std::isfinite(max_length) && p.spacing_m() > 0 && max_length / p.spacing_m() > 1e6) {
      c.bad(key + "spacing_m", text(p.spacing_m()), "at most 1e6 crack particles up to max_length_m");
    }
  }
  if (!p.has_mouth_opening_m())
    c.missing(key + "mouth_opening_m", "the mouth opening w(t) (m), a TimeFunction");
  else
    check_time_function(c, key + "mouth_opening_m", p.mouth_opening_m(), 0.0, "m");
  if (p.profile() == scene::PrescribedCrack::PROFILE_UNSPECIFIED) {
    c.bad(key + "profile", "PROFILE_UNSPECIFIED", "ELLIPTIC, UNIFORM or CHANNEL");
  }
  if (!p.has_stable_dt_s())
    c.missing(key + "stable_dt_s", "the step this stand-in reports (s), > 0");
  else
    c.positive(key + "stable_dt_s", p.stable_dt_s(), "s");
}

void check_prescribed_pressure(Checker& c, const scene::PrescribedPressure& p) {
  const std::string key = "fluid.prescribed_pressure.";
  if (!p.has_inlet_pressure_pa())
    c.missing(key + "inlet_pressure_pa", "the inlet pressure p(t) (Pa), a TimeFunction");
  else
    check_time_function(c, key + "inlet_pressure_pa", p.inlet_pressure_pa(), 0.0, "Pa");
  if (p.profile() == scene::PrescribedPressure::PROFILE_UNSPECIFIED) {
    c.bad(key + "profile", "PROFILE_UNSPECIFIED", "UNIFORM or LINEAR");
  }
  c.range(key + "front_fraction", p.front_fraction(), 0, 1, true, "fraction of the crack length");
  if (!p.has_stable_dt_s())
    c.missing(key + "stable_dt_s", "the step this stand-in reports (s), > 0");
  else
    c.positive(key + "stable_dt_s", p.stable_dt_s(), "s");
}

// Every double and float field set anywhere in `message` (repeated and
// nested ones included) that is NaN or infinite, as problems keyed by its path
// ("solid.mpm.cracks[0].x_m[1]"). By reflection, so a new field is covered
// without code here.
void check_finite(Checker& c, const google::protobuf::Message& message, const std::string& prefix) {
  namespace pb = google::protobuf;
  const auto* reflection = message.GetReflection();
  std::vector<const pb::FieldDescriptor*> fields;
  reflection->ListFields(message, &fields);
  const std::string allowed = "a finite number: every number in a scene must be finite";
  for (const auto* field : fields) {
    const std::string key = prefix + field->name();
    const int count = field->is_repeated() ? reflection->FieldSize(message, field) : 1;
    for (int i = 0; i < count; ++i) {
      const std::string k = field->is_repeated() ? key + "[" + std::to_string(i) + "]" : key;
      switch (field->cpp_type()) {
        case pb::FieldDescriptor::CPPTYPE_DOUBLE: {
          const double v = field->is_repeated() ? reflection->GetRepeatedDouble(message, field, i)
                                                : reflection->GetDouble(message, field);
          if (!std::isfinite(v)) c.bad(k, text(v), allowed);
          break;
        }
        case pb::FieldDescriptor::CPPTYPE_FLOAT: {
          const double v = field->is_repeated() ? reflection->GetRepeatedFloat(message, field, i)
                                                : reflection->GetFloat(message, field);
          if (!std::isfinite(v)) c.bad(k, text(v), allowed);
          break;
        }
        case pb::FieldDescriptor::CPPTYPE_MESSAGE:
          check_finite(c,
                       field->is_repeated() ? reflection->GetRepeatedMessage(message, field, i)
                                            : reflection->GetMessage(message, field),
                       k + ".");
          break;
        default:
          break;
      }
    }
  }
}

// The name is used as a directory and file name: letters, digits, '_', '.',
// '-', at most kMaxNameLength of them, and not "." or "..". Plain scanning
// (no std::regex: its recursion overflows the stack on long input).
constexpr std::size_t kMaxNameLength = 100;

void check_name(Checker& c, const scene::Scene& s) {
  if (!s.has_name()) return;
  const std::string& name = s.name();
  const bool chars_ok = !name.empty() && std::all_of(name.begin(), name.end(), [](char ch) {
    return (ch >= 'A' && ch <= 'Z') || (ch >= 'a' && ch <= 'z') || (ch >= '0' && ch <= '9') || ch == '_' || ch == '.' ||
           ch == '-';
  });
  const std::string shown = name.size() > 60
                                ? "\"" + name.substr(0, 40) + "...\" (" + std::to_string(name.size()) + " characters)"
                                : "\"" + name + "\"";
  if (!chars_ok) {
    c.bad("name", shown, "letters, digits, '_', '.', '-' (it is used in file names)");
  } else if (name.size() > kMaxNameLength) {
    c.bad("name", shown, "at most " + std::to_string(kMaxNameLength) + " characters (it is used in file names)");
  } else if (name == "." || name == "..") {
    c.bad("name", shown, "a name that is not \".\" or \"..\" (it is used as the output directory under hfmpm-out/)");
  }
}

// The number of steps to time.end_s, from the stable steps known before any
// process starts (the MPM solid's cfl h / c_p, the stand-ins' stable_dt_s;
// the MPM fluid's step is known only once it runs, and can only be smaller).
// Refused: more than kMaxRunSteps, or not finite (E = 1e300 gives a step of
// 1e-150 s); and, when every side's step is known, a single step that is
// longer than end_s (the run would end at that step's end, not at end_s).
void check_step_count(Checker& c, const scene::Scene& s) {
  const double end = s.time().end_s(), safety = s.time().safety_factor();
  if (!s.time().has_end_s() || !(std::isfinite(end) && end > 0) || !(safety > 0 && safety <= 1)) return;
  double stable = kInf;
  std::string source;
  bool complete = true;
  auto take = [&](double dt, const std::string& what) {
    if (!(dt > 0) || !std::isfinite(dt)) {
      complete = false;
      return;
    }
    if (dt < stable) stable = dt, source = what;
  };
  if (s.solid().has_prescribed_crack()) {
    take(s.solid().prescribed_crack().stable_dt_s(), "solid.prescribed_crack.stable_dt_s");
  } else if (s.solid().has_mpm()) {
    const double dt = mpm_solid_stable_dt(s.solid().mpm());
    if (std::isnan(dt)) return;  // invalid materials or grid: reported by their own rules
    if (!(dt > 0) || !std::isfinite(dt)) {
      c.bad("time.end_s", text(end),
            "a run of finitely many steps: the MPM solid's stable step cfl h / c_p is " + text(dt) +
                " s (check the materials' youngs_modulus_pa and density_kg_m3 and cell_size_m)");
      return;
    }
    take(dt, "the MPM solid's stable step cfl h / c_p");
  } else {
    return;
  }
  if (s.has_fluid()) {
    if (s.fluid().has_prescribed_pressure())
      take(s.fluid().prescribed_pressure().stable_dt_s(), "fluid.prescribed_pressure.stable_dt_s");
    else
      complete = false;
  }
  if (!std::isfinite(stable)) return;
  const double dt = safety * stable;
  const double steps = end / dt;
  if (!std::isfinite(steps) || steps > kMaxRunSteps) {
    c.bad("time.end_s", text(end),
          "at most " + text(kMaxRunSteps) + " steps to reach it: " + source + " is " + text(stable) +
              " s, dt = time.safety_factor x that = " + text(dt) + " s, so the run needs " + text(steps) +
              " steps (check the moduli, densities and cell size, or shorten end_s)");
  } else if (complete && dt > end) {
    c.bad("time.end_s", text(end),
          "at least one step: " + source + " is " + text(stable) + " s, dt = time.safety_factor x that = " + text(dt) +
              " s, longer than end_s, so the run would be one step ending at t = " + text(dt) +
              " s, not at end_s (check the moduli, densities and cell size, or lengthen end_s)");
  }
}

}  // namespace

std::vector<SceneProblem> validate(const scene::Scene& s) {
  Checker c;
  check_name(c, s);
  check_time(c, s);
  check_coupling(c, s.coupling());
  if (!s.has_solid() || s.solid().model_case() == scene::Solid::MODEL_NOT_SET) {
    c.missing("solid", "a solid model: solid { mpm { ... } } or solid { prescribed_crack { ... } }");
  } else if (s.solid().has_prescribed_crack()) {
    check_prescribed_crack(c, s.solid().prescribed_crack());
  } else if (s.solid().has_mpm()) {
    check_mpm_solid(c, s.solid().mpm());
  }
  if (s.has_fluid()) {
    if (s.fluid().model_case() == scene::Fluid::MODEL_NOT_SET) {
      c.missing("fluid",
                "a fluid model: fluid { mpm { ... } } or fluid { prescribed_pressure { ... } }, or no fluid "
                "block for a dry run");
    } else if (s.fluid().has_prescribed_pressure()) {
      check_prescribed_pressure(c, s.fluid().prescribed_pressure());
    } else if (s.fluid().has_mpm()) {
      check_mpm_fluid(c, s);
    }
  }
  if (s.coupling().scheme() == scene::Coupling::IMPLICIT && s.has_fluid() && s.fluid().has_mpm() && s.has_solid() &&
      !s.solid().has_mpm()) {
    c.bad("coupling.scheme", "IMPLICIT",
          "JACOBI or GAUSS_SEIDEL with this solid: the implicit scheme needs solid.mpm (the prescribed crack "
          "reports no face response for the fluid's interface solve)");
  }
  check_step_count(c, s);
  // A NaN or an infinity anywhere makes every rule that uses it meaningless:
  // then only those numbers are reported (by the rule of their key if it has
  // one that speaks of finiteness, else as not finite), and the other rules are
  // checked once they are finite.
  Checker finite;
  check_finite(finite, s, "");
  auto problems = c.take();
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

double output_interval(const scene::Scene& scene) {
  const double interval = scene.output().interval_s();
  return interval > 0 ? interval : scene.time().end_s() / 100.0;
}

}  // namespace hfmpm::coupling
