// A scalar function of time (inlet pressure, flow rate, prescribed opening),
// plain C++. Built from the scene's TimeFunction by hfmpm::proto::to_time_function.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

namespace hfmpm {

class TimeFunction {
 public:
  enum class Kind { Constant, Table, Power };

  static TimeFunction constant(double v) {
    TimeFunction f;
    f.kind_ = Kind::Constant;
    f.value_ = v;
    return f;
  }
  // Piecewise linear through (t[i], v[i]); constant outside. A ramp is a 2-point table.
  static TimeFunction table(std::vector<double> t, std::vector<double> v) {
    TimeFunction f;
    f.kind_ = Kind::Table;
    f.t_ = std::move(t);
    f.v_ = std::move(v);
    return f;
  }
  // v = scale * (t / t_ref)^exponent for t > 0, 0 for t <= 0.
  static TimeFunction power(double scale, double t_ref, double exponent) {
    TimeFunction f;
    f.kind_ = Kind::Power;
    f.value_ = scale;
    f.t_ref_ = t_ref;
    f.exponent_ = exponent;
    return f;
  }

  double operator()(double t) const {
    switch (kind_) {
      case Kind::Constant:
        return value_;
      case Kind::Power:
        return t > 0 ? value_ * std::pow(t / t_ref_, exponent_) : 0.0;
      case Kind::Table: {
        if (t <= t_.front()) return v_.front();
        if (t >= t_.back()) return v_.back();
        const auto it = std::upper_bound(t_.begin(), t_.end(), t);
        const std::size_t i = static_cast<std::size_t>(it - t_.begin());
        const double a = (t - t_[i - 1]) / (t_[i] - t_[i - 1]);
        return (1 - a) * v_[i - 1] + a * v_[i];
      }
    }
    return 0.0;
  }

  Kind kind() const { return kind_; }

 private:
  Kind kind_ = Kind::Constant;
  double value_ = 0, t_ref_ = 1, exponent_ = 0;
  std::vector<double> t_, v_;
};

}  // namespace hfmpm
