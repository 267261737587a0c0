// One live run per output directory (coupler/include/hfmpm/coupling/run_state.hpp,
// RunLock): a second holder is refused with the first's name and nothing in the
// directory written; the lock goes with its holder; a lock file whose holder is
// gone (no flock on it) does not block. The same with real runs, one of them
// killed: Failure.OneLiveRunPerOutputDirectory, Failure.ALockLeftByAKilledRunDoesNotBlock.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <optional>
#include <string>

#include "hfmpm/coupling/run_state.hpp"
#include "hfmpm/runtime/transport.hpp"
#include "test_support.hpp"

namespace hfmpm::coupling {
namespace {

using test::read_file;
using test::scratch_dir;
using test::write_file;

TEST(RunLock, ASecondHolderIsRefusedWithTheFirstsNameAndNothingWritten) {
  const std::string dir = scratch_dir("lock") + "/out";  // made by the lock
  const RunLock first(dir);
  EXPECT_EQ(first.path(), dir + "/.lock");
  const std::string held = read_file(first.path());
  EXPECT_NE(held.find("\"pid\": " + std::to_string(getpid())), std::string::npos) << held;
  EXPECT_NE(held.find("\"host\": \"" + host_name() + "\""), std::string::npos) << held;
  try {
    // flock belongs to the open file: a second open in the same process is refused as another run's.
    const RunLock second(dir);
    ADD_FAILURE() << "a second lock on " << dir << " was granted";
  } catch (const DirectoryInUse& e) {
    EXPECT_EQ(e.holder.pid, getpid());
    EXPECT_EQ(e.holder.host, host_name());
    EXPECT_FALSE(e.holder.started_at.empty());
    EXPECT_EQ(e.lock_path, dir + "/.lock");
    const std::string message = e.what();
    EXPECT_NE(message.find("'" + dir + "' is in use by another run (coupler pid " + std::to_string(getpid()) + " on " +
                           host_name() + ", started "),
              std::string::npos)
        << message;
  }
  EXPECT_EQ(read_file(first.path()), held) << "the refused one wrote nothing";
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir), std::filesystem::directory_iterator()), 1)
      << "the lock file only";
}

TEST(RunLock, ReleasedWithItsHolder) {
  const std::string dir = scratch_dir("lock");
  std::optional<RunLock> first(std::in_place, dir);
  first.reset();
  EXPECT_NO_THROW(RunLock again(dir));
}

// A run killed with SIGKILL leaves its lock file naming it, but the kernel has
// dropped its flock: the file alone does not block, and names the new holder.
TEST(RunLock, AFileLeftByADeadRunDoesNotBlock) {
  const std::string dir = scratch_dir("lock");
  write_file(dir + "/.lock", "{\n  \"host\": \"" + host_name() +
                                 "\",\n  \"pid\": 4194304,\n  \"started_at\": \"2026-01-01T00:00:00Z\"\n}\n");
  const RunLock taken(dir);
  const std::string text = read_file(dir + "/.lock");
  EXPECT_NE(text.find("\"pid\": " + std::to_string(getpid()) + ","), std::string::npos) << text;
  EXPECT_EQ(text.find("4194304"), std::string::npos) << text;
}

TEST(RunLock, AFileInThePlaceOfTheDirectoryIsNamed) {
  const std::string path = scratch_dir("lock") + "/taken";
  write_file(path, "not a directory");
  try {
    const RunLock lock(path);
    ADD_FAILURE() << "locked a file as a directory";
  } catch (const DirectoryInUse&) {
    ADD_FAILURE() << "a file is not a run";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot create the output directory '" + path + "'"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace hfmpm::coupling
