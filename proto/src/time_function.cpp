#include "hfmpm/proto/convert.hpp"

namespace hfmpm::proto {

TimeFunction to_time_function(const scene::TimeFunction& f) {
  switch (f.kind_case()) {
    case scene::TimeFunction::kConstant:
      return TimeFunction::constant(f.constant());
    case scene::TimeFunction::kRamp:
      return TimeFunction::table({f.ramp().t0(), f.ramp().t1()}, {f.ramp().v0(), f.ramp().v1()});
    case scene::TimeFunction::kTable:
      return TimeFunction::table({f.table().t().begin(), f.table().t().end()},
                                 {f.table().v().begin(), f.table().v().end()});
    case scene::TimeFunction::kPower:
      return TimeFunction::power(f.power().scale(), f.power().t_ref(), f.power().exponent());
    case scene::TimeFunction::KIND_NOT_SET:
      break;
  }
  return TimeFunction::constant(0.0);
}

}  // namespace hfmpm::proto
