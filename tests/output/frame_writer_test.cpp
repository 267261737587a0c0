// Unit tests of hfmpm::output::FrameWriter: three frames round-trip exactly through HDF5 and XDMF, the files on
// disk are complete after every end_frame(), also when the writing process dies without destructors.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <functional>
#include <map>

#include "frame_model.hpp"
#include "h5_reader.hpp"
#include "hfmpm/output/frame_writer.hpp"
#include "test_support.hpp"

namespace {

using hfmpm::output::FrameWriter;
using hfmpm::test::FrameData;
using hfmpm::test::Scratch;
namespace fs = std::filesystem;

std::vector<FrameData> first(const std::vector<FrameData>& frames, std::size_t n) {
  return {frames.begin(), frames.begin() + static_cast<std::ptrdiff_t>(n)};
}

// Copies the pair as it is on disk now (the writer still has the HDF5 file open) to dir/<name>/.
std::string snapshot(const std::string& dir, const std::string& name) {
  const std::string to = dir + "/" + name;
  fs::create_directory(to);
  fs::copy_file(dir + "/run.h5", to + "/run.h5");
  if (fs::exists(dir + "/run.xmf")) fs::copy_file(dir + "/run.xmf", to + "/run.xmf");
  return to;
}

// Runs body in a forked child that then ends with _exit(1): no destructors, no atexit, no flushing of
// anything the writer has not flushed itself. Returns the child's exit code (2 if body threw).
int crashing_child(const std::function<void()>& body) {
  std::fflush(nullptr);
  const pid_t pid = fork();
  if (pid == 0) {
    try {
      body();
    } catch (const std::exception& e) {
      std::fprintf(stderr, "child: %s\n", e.what());
      _exit(2);
    }
    _exit(1);
  }
  int status = 0;
  if (pid < 0 || waitpid(pid, &status, 0) != pid) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(FrameWriter, ThreeFramesRoundTripExactlyAndEveryFrameIsOnDisk) {
  Scratch scratch("output-roundtrip");
  const std::string dir = scratch.dir();
  const auto frames = hfmpm::test::sample_frames();
  const std::map<std::string, std::string> root{
      {"title", "KGD <plane strain> & \"water\""}, {"units", "SI"}, {"code_version", "0.1.0"}};
  {
    FrameWriter writer(dir + "/run.h5", root.at("title"));
    EXPECT_EQ(writer.h5_path(), dir + "/run.h5");
    EXPECT_EQ(writer.xdmf_path(), dir + "/run.xmf");
    writer.attribute("units", "metric");
    writer.attribute("units", "SI");  // replaces
    writer.attribute("code_version", "0.1.0");
    EXPECT_EQ(writer.frames_written(), 0u);
    {
      SCOPED_TRACE("before any frame");
      const std::string snap = snapshot(dir, "snap0");
      hfmpm::test::verify_files(snap + "/run.h5", snap + "/run.xmf", {}, root);
    }
    for (std::size_t k = 0; k < frames.size(); ++k) {
      hfmpm::test::write_frame(writer, frames[k]);
      EXPECT_EQ(writer.frames_written(), k + 1);
      EXPECT_FALSE(writer.in_frame());
      SCOPED_TRACE("after end_frame " + std::to_string(k));
      const std::string snap = snapshot(dir, "snap" + std::to_string(k + 1));
      hfmpm::test::verify_files(snap + "/run.h5", snap + "/run.xmf", first(frames, k + 1), root);
    }
  }
  SCOPED_TRACE("after the writer closed");
  hfmpm::test::verify_files(dir + "/run.h5", dir + "/run.xmf", frames, root);
  EXPECT_FALSE(fs::exists(dir + "/run.xmf.tmp"));
}

TEST(FrameWriter, FramesSurviveAProcessThatDiesAfterEndFrame) {
  const auto frames = hfmpm::test::sample_frames();
  for (std::size_t k = 1; k <= frames.size(); ++k) {
    SCOPED_TRACE("child wrote " + std::to_string(k) + " frames");
    Scratch scratch("output-crash");
    const std::string h5 = scratch.dir() + "/run.h5";
    const int code = crashing_child([&] {
      auto* writer = new FrameWriter(h5, "crash");  // never deleted
      for (std::size_t i = 0; i < k; ++i) hfmpm::test::write_frame(*writer, frames[i]);
    });
    ASSERT_EQ(code, 1);
    hfmpm::test::verify_files(h5, scratch.dir() + "/run.xmf", first(frames, k), {{"title", "crash"}});
  }
}

TEST(FrameWriter, AProcessDyingInsideAFrameLosesOnlyThatFrame) {
  Scratch scratch("output-crash-mid");
  const std::string h5 = scratch.dir() + "/run.h5";
  const auto frames = hfmpm::test::sample_frames();
  const int code = crashing_child([&] {
    auto* writer = new FrameWriter(h5, "crash");
    hfmpm::test::write_frame(*writer, frames[0]);
    hfmpm::test::write_frame(*writer, frames[1]);
    writer->begin_frame(frames[2].time_s, frames[2].step);
    writer->points("particles", frames[2].sets[0].positions);
    writer->scalar("particles", "mass", frames[2].sets[0].scalars.at("mass"));
    writer->attribute("note", "set mid-frame");
  });
  ASSERT_EQ(code, 1);
  hfmpm::test::verify_files(h5, scratch.dir() + "/run.xmf", first(frames, 2),
                            {{"title", "crash"}, {"note", "set mid-frame"}});
}

TEST(FrameWriter, DestroyingTheWriterInsideAFrameDropsThatFrame) {
  Scratch scratch("output-drop");
  const std::string h5 = scratch.dir() + "/run.h5";
  const auto frames = hfmpm::test::sample_frames();
  {
    FrameWriter writer(h5, "drop");
    hfmpm::test::write_frame(writer, frames[0]);
    writer.begin_frame(frames[1].time_s, frames[1].step);
    writer.points("particles", frames[1].sets[0].positions);
    EXPECT_TRUE(writer.in_frame());
  }
  hfmpm::test::verify_files(h5, scratch.dir() + "/run.xmf", first(frames, 1), {{"title", "drop"}});
}

TEST(FrameWriter, EmptySetsAndEmptyFramesAreWrittenButLeftOutOfTheXdmf) {
  Scratch scratch("output-empty");
  const std::string h5 = scratch.dir() + "/run.h5";
  std::vector<FrameData> frames(4);
  frames[0] = {0.5, 1, {{"ghost", {}, {{"w", {}}}, {{"tip", {}}}, {{"v", {}}}, {{"s", {}}}}}};
  frames[1] = {1.0, 2, {}};                                                // no sets at all
  frames[2] = {2.0, 3, {{"fluid", {hfmpm::Vec2(1, 2)}, {}, {}, {}, {}}}};  // one point, no arrays
  frames[3] = {3.0, 4, {{"ghost", {}, {}, {}, {}, {}}}};
  hfmpm::test::write_file(scratch.dir() + "/run.xmf", "left by an earlier run");
  {
    FrameWriter writer(h5, "empty");
    EXPECT_FALSE(fs::exists(scratch.dir() + "/run.xmf")) << "the old XDMF must go with the old HDF5 data";
    for (std::size_t i = 0; i < frames.size(); ++i) {
      hfmpm::test::write_frame(writer, frames[i]);
      // No XDMF until a set has points (ParaView's XDMF reader crashes on a Domain without grids).
      EXPECT_EQ(fs::exists(scratch.dir() + "/run.xmf"), i >= 2) << "after frame " << i;
    }
  }
  // ghost is empty in every frame: it has HDF5 groups with 0 x 2 positions but no XDMF collection.
  hfmpm::test::verify_files(h5, scratch.dir() + "/run.xmf", frames, {{"title", "empty"}});
  hfmpm::test::H5Reader reader(h5);
  EXPECT_EQ(reader.dims("/frames/000000/ghost/positions"), (std::vector<std::uint64_t>{0, 2}));
  EXPECT_EQ(reader.dims("/frames/000000/ghost/s"), (std::vector<std::uint64_t>{0, 4}));
}

TEST(FrameWriter, HoldsNoLockThatWouldKeepAViewerOut) {
  Scratch scratch("output-lock");
  const std::string h5 = scratch.dir() + "/run.h5";
  FrameWriter writer(h5, "lock");
  hfmpm::test::write_frame(writer, hfmpm::test::sample_frames()[0]);
  const int fd = open(h5.c_str(), O_RDONLY);
  ASSERT_GE(fd, 0);
  EXPECT_EQ(flock(fd, LOCK_EX | LOCK_NB), 0) << "the writer holds a lock on " << h5;
  close(fd);
}

TEST(FrameWriter, CanBeMoved) {
  Scratch scratch("output-move");
  const std::string h5 = scratch.dir() + "/run.h5";
  const auto frames = hfmpm::test::sample_frames();
  FrameWriter a(h5, "move");
  hfmpm::test::write_frame(a, frames[0]);
  FrameWriter b(std::move(a));
  EXPECT_THROW(static_cast<void>(a.in_frame()), std::logic_error);  // NOLINT(bugprone-use-after-move)
  hfmpm::test::write_frame(b, frames[1]);
  EXPECT_EQ(b.frames_written(), 2u);
}

}  // namespace

namespace {

// The writer's state goes to an archive in memory (hfmpm::MemoryState; checkpoints go to
// HDF5 through hfmpm_output's write_checkpoint; save/resume do not depend on that).
using hfmpm::MemoryState;

// A restart: the writer's state saved after frame 2, frame 3 written by a run that is then
// killed; the resumed writer drops frame 3 and writes it again: the files hold exactly the
// three frames, as if nothing had happened.
TEST(FrameWriter, ResumesFromSavedStateDroppingLaterFrames) {
  Scratch scratch("output-resume");
  const std::string h5 = scratch.dir() + "/run.h5", xmf = scratch.dir() + "/run.xmf";
  const auto frames = hfmpm::test::sample_frames();
  MemoryState saved;
  {
    FrameWriter writer(h5, "resume");
    writer.attribute("units", "SI");
    hfmpm::test::write_frame(writer, frames[0]);
    hfmpm::test::write_frame(writer, frames[1]);
    writer.save(saved);
    hfmpm::test::write_frame(writer, frames[2]);  // after the checkpoint: lost with the run
  }
  {
    FrameWriter writer(h5, static_cast<const hfmpm::StateReader&>(saved));
    EXPECT_EQ(writer.frames_written(), 2u);
  }
  hfmpm::test::verify_files(h5, xmf, first(frames, 2), {{"title", "resume"}, {"units", "SI"}});
  {
    FrameWriter writer(h5, static_cast<const hfmpm::StateReader&>(saved));  // again: a second restart
    hfmpm::test::write_frame(writer, frames[2]);
  }
  hfmpm::test::verify_files(h5, xmf, frames, {{"title", "resume"}, {"units", "SI"}});
  EXPECT_THROW(FrameWriter(scratch.dir() + "/missing.h5", static_cast<const hfmpm::StateReader&>(saved)),
               std::runtime_error);
}

}  // namespace
