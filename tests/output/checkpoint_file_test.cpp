// Unit tests of the checkpoint file's checksums (hfmpm/output/checkpoint_file.hpp; docs/reliability.md,
// "Damaged checkpoints"): a checkpoint written and read back whole, every checksum as documented, and
// the same file damaged at random places inside its datasets (fixed seed): each damaged copy is refused
// naming the file and the dataset, before anything of it is handed to the reader.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <random>
#include <set>

#include "h5_reader.hpp"
#include "hfmpm/checksum.hpp"
#include "hfmpm/output/checkpoint_file.hpp"
#include "test_support.hpp"

namespace hfmpm::test {
namespace {

namespace fs = std::filesystem;
using output::DamagedCheckpoint;

CheckpointStamp sample_stamp() {
  CheckpointStamp s;
  s.role = "solid";
  s.implementation = "hfmpm-solid";
  s.program_version = "0.1.0";
  s.protocol_version = 3;
  s.scene_schema_version = 7;
  s.scene_hash = "0123456789abcdef";
  s.step = 348;
  s.t = 0.2;
  return s;
}

// A state like a small solid's: particle positions (the "move one particle by 0.5 m"), grid
// masses, integer ids, an adapter's bytes, one number and an empty array.
struct SampleState {
  std::vector<double> x, mass;
  std::vector<std::uint64_t> ids;
  std::string adapter;
  double time = 0;
  std::vector<double> empty;
  bool operator==(const SampleState&) const = default;
};

SampleState sample_state() {
  SampleState s;
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int i = 0; i < 3000; ++i) s.x.push_back(10 * unit(random));
  for (int i = 0; i < 1500; ++i) s.mass.push_back(unit(random) * 1e-3);
  for (std::uint64_t i = 0; i < 700; ++i) s.ids.push_back(i * 3 + 1);
  for (int i = 0; i < 400; ++i) s.adapter.push_back(static_cast<char>(random() & 0xff));
  s.time = 0.2;
  return s;
}

void write_sample(const std::string& path, const SampleState& s) {
  output::write_checkpoint(path, sample_stamp(), [&](StateWriter& out) {
    out.f64("solid.particles.x", s.x);
    out.f64("solid.grid.mass", s.mass);
    out.u64("solid.crack0.ids", s.ids);
    out.text("solid.adapter", s.adapter);
    out.put("solid.time", s.time);
    out.f64("solid.empty", s.empty);
  });
}

// Reads the file back; `handed` says whether read_checkpoint got as far as handing over the state.
SampleState read_sample(const std::string& path, bool& handed) {
  SampleState s;
  handed = false;
  output::read_checkpoint(path, sample_stamp(), [&](const StateReader& in) {
    handed = true;
    s.x = in.f64("solid.particles.x");
    s.mass = in.f64("solid.grid.mass");
    s.ids = in.u64("solid.crack0.ids");
    s.adapter = in.text("solid.adapter");
    in.get("solid.time", s.time);
    s.empty = in.f64("solid.empty");
  });
  return s;
}

// Whole files as bytes (text mode is binary on Linux).
std::string file_bytes(const std::string& path) { return read_file(path); }
void put_bytes(const std::string& path, const std::string& bytes) { write_file(path, bytes); }

// The message of what read_checkpoint (or verify_checkpoint) threw, and whether it was DamagedCheckpoint.
struct Refusal {
  bool thrown = false, damaged = false;
  std::string what;
};

template <class F>
Refusal refusal_of(F&& f) {
  Refusal r;
  try {
    f();
  } catch (const DamagedCheckpoint& e) {
    r = {true, true, e.what()};
  } catch (const std::exception& e) {
    r = {true, false, e.what()};
  }
  return r;
}

TEST(CheckpointFile, Fnv1a64MatchesItsPublishedValues) {
  // The reference values of FNV-1a 64 (Fowler, Noll, Vo: the FNV test suite).
  EXPECT_EQ(checksum_text(fnv1a64(std::string())), "cbf29ce484222325");
  EXPECT_EQ(checksum_text(fnv1a64(std::string("a"))), "af63dc4c8601ec8c");
  EXPECT_EQ(checksum_text(fnv1a64(std::string("foobar"))), "85944171f73967e8");
  // A continued checksum is the checksum of the whole.
  EXPECT_EQ(fnv1a64("bar", 3, fnv1a64("foo", 3)), fnv1a64(std::string("foobar")));
}

TEST(CheckpointFile, RoundTripsWithAChecksumOnEveryDataset) {
  const std::string dir = scratch_dir("checkpoint-roundtrip");
  const std::string path = dir + "/solid.h5";
  const SampleState state = sample_state();
  write_sample(path, state);
  bool handed = false;
  EXPECT_EQ(read_sample(path, handed), state);
  EXPECT_TRUE(handed);
  EXPECT_NO_THROW(output::verify_checkpoint(path));

  // As documented: each dataset's attribute is FNV-1a of its name and type, each ended by a zero
  // byte, and its elements' little-endian bytes; the root
  // counts the datasets and holds the stamp's checksum; the format is 2.
  const H5Reader file(path);
  auto sum_of = [&](const std::string& name, const std::string& type, const void* data, std::size_t size) {
    const std::string head = name + '\0' + type + '\0';
    EXPECT_EQ(file.attribute_string("/" + name, "checksum_fnv1a64"), checksum_text(fnv1a64(data, size, fnv1a64(head))))
        << name;
  };
  sum_of("solid.particles.x", "f64", state.x.data(), state.x.size() * sizeof(double));
  sum_of("solid.grid.mass", "f64", state.mass.data(), state.mass.size() * sizeof(double));
  sum_of("solid.crack0.ids", "u64", state.ids.data(), state.ids.size() * sizeof(std::uint64_t));
  sum_of("solid.adapter", "u8", state.adapter.data(), state.adapter.size());
  sum_of("solid.time", "f64", &state.time, sizeof(double));
  sum_of("solid.empty", "f64", nullptr, 0);
  EXPECT_EQ(file.attribute_string("/", "datasets"), "6");
  EXPECT_EQ(file.attribute_string("/", "format"), "2");
  std::string stamp;
  for (const std::string key : {"format", "role", "implementation", "program_version", "protocol_version",
                                "scene_schema_version", "scene_hash", "step", "t_bits", "t_s", "datasets"}) {
    stamp += key + "=" + file.attribute_string("/", key) + "\n";
  }
  EXPECT_EQ(file.attribute_string("/", "checksum_fnv1a64"), checksum_text(fnv1a64(stamp)));
}

// The trials: 100 copies of one checkpoint, each damaged at a random place inside one of its
// datasets (a bit flipped, a byte changed, or 64 bytes overwritten, cut at the dataset's end). Every
// copy is refused, naming the file and that dataset, and the reader never gets its state.
TEST(CheckpointFile, EveryDatasetDamagedAtRandomIsRefusedNamingIt) {
  const std::string dir = scratch_dir("checkpoint-damaged");
  const std::string pristine = dir + "/pristine.h5", path = dir + "/solid.h5";
  write_sample(pristine, sample_state());
  const std::string good = file_bytes(pristine);
  struct Extent {
    std::string name;
    std::uint64_t offset = 0, size = 0;
  };
  std::vector<Extent> extents;
  {
    const H5Reader file(pristine);
    for (const auto& name : file.children("/")) {
      const auto [offset, size] = file.data_extent("/" + name);
      if (size > 0) extents.push_back({name, offset, size});
    }
  }
  ASSERT_EQ(extents.size(), 5u) << "every dataset but the empty one has bytes in the file";

  std::mt19937_64 random(49);  // issue 49
  std::set<std::string> hit;
  int refused = 0;
  for (int trial = 0; trial < 100; ++trial) {
    const Extent& e = extents[random() % extents.size()];
    const std::uint64_t at = e.offset + random() % e.size;
    std::string bytes = good;
    const auto kind = trial % 3;
    if (kind == 0) {
      bytes[at] = static_cast<char>(bytes[at] ^ (1 << (random() % 8)));  // one bit
    } else if (kind == 1) {
      bytes[at] = static_cast<char>(bytes[at] ^ static_cast<char>(1 + random() % 255));  // one byte
    } else {
      for (std::uint64_t i = at; i < std::min(at + 64, e.offset + e.size); ++i) {  // 64 bytes
        bytes[i] = static_cast<char>(random() & 0xff);
      }
    }
    if (bytes == good) {  // random bytes equal to those they replaced: nothing to detect
      bytes[at] = static_cast<char>(bytes[at] ^ 1);
    }
    put_bytes(path, bytes);
    bool handed = false;
    const Refusal read = refusal_of([&] { read_sample(path, handed); });
    const Refusal verified = refusal_of([&] { output::verify_checkpoint(path); });
    const std::string named = "checkpoint " + path + " is damaged: dataset " + e.name + " does not match its checksum";
    EXPECT_TRUE(read.damaged) << "trial " << trial << ": " << e.name << " at byte " << at << ": " << read.what;
    EXPECT_NE(read.what.find(named), std::string::npos) << "trial " << trial << ": " << read.what;
    EXPECT_NE(read.what.find("a checkpoint is used only if its stamp and every dataset match"), std::string::npos);
    EXPECT_FALSE(handed) << "trial " << trial;
    EXPECT_TRUE(verified.damaged) << "trial " << trial;
    EXPECT_EQ(verified.what, read.what);
    if (read.damaged && read.what.find(named) != std::string::npos && !handed) ++refused;
    hit.insert(e.name);
  }
  EXPECT_EQ(refused, 100);
  EXPECT_EQ(hit.size(), extents.size()) << "every dataset was damaged in some trial";

  // The issue's own example: one particle moved by 0.5 m.
  const Extent& x =
      *std::find_if(extents.begin(), extents.end(), [](const Extent& e) { return e.name == "solid.particles.x"; });
  std::string moved = good;
  double value = 0;
  std::memcpy(&value, moved.data() + x.offset + 17 * sizeof(double), sizeof value);
  value += 0.5;
  std::memcpy(moved.data() + x.offset + 17 * sizeof(double), &value, sizeof value);
  put_bytes(path, moved);
  bool handed = false;
  const Refusal r = refusal_of([&] { read_sample(path, handed); });
  EXPECT_TRUE(r.damaged);
  EXPECT_NE(r.what.find("dataset solid.particles.x does not match its checksum (FNV-1a of its name, type and 24000 "
                        "bytes is "),
            std::string::npos)
      << r.what;
  EXPECT_FALSE(handed);

  // Undamaged, the same bytes still read whole.
  put_bytes(path, good);
  EXPECT_EQ(read_sample(path, handed), sample_state());
}

// Damage outside the datasets' elements: the stamp (a root attribute), a dataset's checksum, a
// checksum removed, a file HDF5 cannot open, and a file of format 1 (no checksums).
TEST(CheckpointFile, DamagedStampOrChecksumsAndFilesWithoutChecksumsAreRefused) {
  const std::string dir = scratch_dir("checkpoint-stamp");
  const std::string pristine = dir + "/pristine.h5", path = dir + "/solid.h5";
  write_sample(pristine, sample_state());
  auto fresh = [&] { fs::copy_file(pristine, path, fs::copy_options::overwrite_existing); };
  bool handed = false;

  fresh();
  set_string_attribute(path, "/", "step", "347");
  Refusal r = refusal_of([&] { read_sample(path, handed); });
  EXPECT_TRUE(r.damaged);
  EXPECT_NE(r.what.find("checkpoint " + path + " is damaged: its stamp (the root attributes format,"),
            std::string::npos)
      << r.what;
  EXPECT_NE(r.what.find("does not match its checksum"), std::string::npos) << r.what;

  fresh();
  set_string_attribute(path, "/solid.grid.mass", "checksum_fnv1a64", "0000000000000000");
  r = refusal_of([&] { read_sample(path, handed); });
  EXPECT_TRUE(r.damaged);
  EXPECT_NE(r.what.find("dataset solid.grid.mass does not match its checksum"), std::string::npos) << r.what;
  EXPECT_NE(r.what.find("written as 0000000000000000"), std::string::npos) << r.what;

  fresh();
  delete_attribute(path, "/solid.crack0.ids", "checksum_fnv1a64");
  r = refusal_of([&] { read_sample(path, handed); });
  EXPECT_TRUE(r.damaged);
  EXPECT_NE(r.what.find("dataset solid.crack0.ids has no checksum (attribute checksum_fnv1a64)"), std::string::npos)
      << r.what;

  put_bytes(path, file_bytes(pristine).substr(0, 512));  // cut short: HDF5 cannot open it
  r = refusal_of([&] { read_sample(path, handed); });
  EXPECT_TRUE(r.damaged);
  EXPECT_NE(r.what.find("checkpoint " + path + " is damaged: it cannot be read (HDF5 file"), std::string::npos)
      << r.what;

  // Format 1, as written before checksums: refused as another version, not read unchecked.
  fresh();
  set_string_attribute(path, "/", "format", "1");
  delete_attribute(path, "/", "checksum_fnv1a64");
  delete_attribute(path, "/", "datasets");
  for (const std::string name :
       {"solid.particles.x", "solid.grid.mass", "solid.crack0.ids", "solid.adapter", "solid.time", "solid.empty"}) {
    delete_attribute(path, "/" + name, "checksum_fnv1a64");
  }
  r = refusal_of([&] { read_sample(path, handed); });
  EXPECT_TRUE(r.thrown);
  EXPECT_FALSE(r.damaged);
  EXPECT_NE(r.what.find("checkpoint " + path +
                        " has format = '1', this run needs '2': it was written by another version of the program "
                        "(a checkpoint without checksums, format 1, cannot be checked and is not used)"),
            std::string::npos)
      << r.what;
  EXPECT_FALSE(handed);
  r = refusal_of([&] { output::verify_checkpoint(path); });
  EXPECT_TRUE(r.thrown);
  EXPECT_FALSE(r.damaged);
}

// Damage anywhere in the file, HDF5's own structures included (1000 trials, fixed seed: one byte
// changed, or 64 bytes overwritten): each copy is refused as damaged, or reads back the very state
// written (the damage fell on bytes nothing reads: free space, padding). Never other numbers.
TEST(CheckpointFile, DamageAnywhereIsRefusedOrLeavesTheStateUnchanged) {
  const std::string dir = scratch_dir("checkpoint-anywhere");
  const std::string pristine = dir + "/pristine.h5", path = dir + "/solid.h5";
  const SampleState state = sample_state();
  write_sample(pristine, state);
  const std::string good = file_bytes(pristine);
  std::mt19937_64 random(4949);
  int refused = 0, unchanged = 0;
  for (int trial = 0; trial < 1000; ++trial) {
    std::string bytes = good;
    const std::uint64_t at = random() % bytes.size();
    if (trial % 2 == 0) {
      bytes[at] = static_cast<char>(bytes[at] ^ static_cast<char>(1 + random() % 255));
    } else {
      for (std::uint64_t i = at; i < std::min<std::uint64_t>(at + 64, bytes.size()); ++i) {
        bytes[i] = static_cast<char>(random() & 0xff);
      }
    }
    put_bytes(path, bytes);
    bool handed = false;
    SampleState read;
    const Refusal r = refusal_of([&] { read = read_sample(path, handed); });
    if (r.damaged) {
      ++refused;
      EXPECT_NE(r.what.find("checkpoint " + path + " is damaged: "), std::string::npos) << r.what;
      EXPECT_FALSE(handed) << "trial " << trial;
    } else {
      EXPECT_FALSE(r.thrown) << "trial " << trial << ", byte " << at << ": refused, but not as damaged: " << r.what;
      EXPECT_EQ(read, state) << "trial " << trial << ", byte " << at << ": read without a refusal, but different";
      if (!r.thrown && read == state) ++unchanged;
    }
  }
  EXPECT_EQ(refused + unchanged, 1000);
  EXPECT_GT(refused, 900) << "most bytes of the file matter";
  std::printf("damage anywhere: %d of 1000 refused as damaged, %d read back unchanged\n", refused, unchanged);
}

}  // namespace
}  // namespace hfmpm::test
