// The state of a physics object as named arrays, for checkpoints (docs/reliability.md,
// "Checkpoint and restart"). The physics libraries write and read their full state through
// these interfaces and know nothing of the file format; hfmpm_output implements them over HDF5
// (hfmpm/output/checkpoint_file.hpp). Doubles are kept bit for bit; integers as 64 bits.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace hfmpm {

// What a side's checkpoint file belongs to; a file whose stamp differs from the run's is refused.
struct CheckpointStamp {
  std::string role;             // "solid" or "fluid"
  std::string implementation;   // e.g. "hfmpm-solid"
  std::string program_version;  // e.g. "0.1.0"
  std::uint32_t protocol_version = 0;
  std::uint32_t scene_schema_version = 0;
  std::string scene_hash;  // of the run's scene (proto::scene_hash)
  std::uint64_t step = 0;
  double t = 0;  // s
};

class StateWriter {
 public:
  virtual ~StateWriter() = default;
  // One named array; a name is written once per archive ([A-Za-z0-9_.]+).
  virtual void f64(const std::string& name, const std::vector<double>& values) = 0;
  virtual void u64(const std::string& name, const std::vector<std::uint64_t>& values) = 0;
  virtual void text(const std::string& name, const std::string& bytes) = 0;

  void put(const std::string& name, double value) { f64(name, {value}); }
  void put(const std::string& name, const std::vector<double>& values) { f64(name, values); }
  template <class T>
  requires std::is_integral_v<T>
  void put(const std::string& name, T value) { u64(name, {static_cast<std::uint64_t>(value)}); }
  template <class T>
  requires std::is_integral_v<T>
  void put(const std::string& name, const std::vector<T>& values) {
    std::vector<std::uint64_t> wide(values.size());
    std::transform(values.begin(), values.end(), wide.begin(), [](T v) { return static_cast<std::uint64_t>(v); });
    u64(name, wide);
  }
  // Fixed-size Eigen vectors and matrices, flattened in their storage order.
  template <class M>
  requires(M::SizeAtCompileTime > 0) void put(const std::string& name, const std::vector<M>& values) {
    constexpr auto k = static_cast<std::size_t>(M::SizeAtCompileTime);
    std::vector<double> flat(values.size() * k);
    for (std::size_t i = 0; i < values.size(); ++i) std::copy_n(values[i].data(), k, flat.data() + i * k);
    f64(name, flat);
  }
};

class StateReader {
 public:
  virtual ~StateReader() = default;
  // The named array; throws std::runtime_error naming it if it is missing or of another type.
  virtual std::vector<double> f64(const std::string& name) const = 0;
  virtual std::vector<std::uint64_t> u64(const std::string& name) const = 0;
  virtual std::string text(const std::string& name) const = 0;

  void get(const std::string& name, double& value) const { value = one(f64(name), name); }
  void get(const std::string& name, std::vector<double>& values) const { values = f64(name); }
  template <class T>
  requires std::is_integral_v<T>
  void get(const std::string& name, T& value) const { value = static_cast<T>(one(u64(name), name)); }
  template <class T>
  requires std::is_integral_v<T>
  void get(const std::string& name, std::vector<T>& values) const {
    const auto wide = u64(name);
    std::vector<T> narrow;
    narrow.reserve(wide.size());
    for (std::uint64_t v : wide) narrow.push_back(static_cast<T>(v));
    values = std::move(narrow);
  }
  template <class M>
  requires(M::SizeAtCompileTime > 0) void get(const std::string& name, std::vector<M>& values) const {
    constexpr auto k = static_cast<std::size_t>(M::SizeAtCompileTime);
    const auto flat = f64(name);
    if (flat.size() % k != 0) {
      throw std::runtime_error("checkpoint array " + name + " has " + std::to_string(flat.size()) +
                               " numbers, not a multiple of " + std::to_string(k));
    }
    values.resize(flat.size() / k);
    for (std::size_t i = 0; i < values.size(); ++i) std::copy_n(flat.data() + i * k, k, values[i].data());
  }

 private:
  template <class T>
  static T one(const std::vector<T>& values, const std::string& name) {
    if (values.size() != 1) {
      throw std::runtime_error("checkpoint array " + name + " has " + std::to_string(values.size()) +
                               " entries; one was expected");
    }
    return values.front();
  }
};

// Names inside a part of the state: prefix "solid.crack3." + name.
class PrefixedWriter final : public StateWriter {
 public:
  PrefixedWriter(StateWriter& inner, std::string prefix) : inner_(inner), prefix_(std::move(prefix)) {}
  void f64(const std::string& name, const std::vector<double>& v) override { inner_.f64(prefix_ + name, v); }
  void u64(const std::string& name, const std::vector<std::uint64_t>& v) override { inner_.u64(prefix_ + name, v); }
  void text(const std::string& name, const std::string& bytes) override { inner_.text(prefix_ + name, bytes); }

 private:
  StateWriter& inner_;
  std::string prefix_;
};

class PrefixedReader final : public StateReader {
 public:
  PrefixedReader(const StateReader& inner, std::string prefix) : inner_(inner), prefix_(std::move(prefix)) {}
  std::vector<double> f64(const std::string& name) const override { return inner_.f64(prefix_ + name); }
  std::vector<std::uint64_t> u64(const std::string& name) const override { return inner_.u64(prefix_ + name); }
  std::string text(const std::string& name) const override { return inner_.text(prefix_ + name); }

 private:
  const StateReader& inner_;
  std::string prefix_;
};

// A state archive in memory: what is written can be read back at once (tests of
// save and load, and in-process copies of a state, without a file).
class MemoryState final : public StateWriter, public StateReader {
 public:
  void f64(const std::string& name, const std::vector<double>& v) override { reals_[name] = v; }
  void u64(const std::string& name, const std::vector<std::uint64_t>& v) override { ints_[name] = v; }
  void text(const std::string& name, const std::string& bytes) override { texts_[name] = bytes; }
  std::vector<double> f64(const std::string& name) const override { return find(reals_, name); }
  std::vector<std::uint64_t> u64(const std::string& name) const override { return find(ints_, name); }
  std::string text(const std::string& name) const override { return find(texts_, name); }

 private:
  template <class Map>
  static const typename Map::mapped_type& find(const Map& map, const std::string& name) {
    const auto it = map.find(name);
    if (it == map.end()) throw std::runtime_error("the state has no array '" + name + "' of this type");
    return it->second;
  }
  std::map<std::string, std::vector<double>> reals_;
  std::map<std::string, std::vector<std::uint64_t>> ints_;
  std::map<std::string, std::string> texts_;
};

}  // namespace hfmpm
