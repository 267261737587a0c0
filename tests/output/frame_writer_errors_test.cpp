// Unit tests of hfmpm::output::FrameWriter's error paths: size mismatches, bad names, calls out of order, bad
// times and paths. A rejected call leaves the writer as it was, so each test ends by writing a good frame.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <string>

#include "frame_model.hpp"
#include "hfmpm/output/frame_writer.hpp"

namespace {

using hfmpm::Vec2;
using hfmpm::output::FrameWriter;
using hfmpm::test::FrameData;
using hfmpm::test::Scratch;

// The message of the exception of type E that call throws ("" and a test failure if none or another).
template <class E, class F>
std::string message_of(F&& call) {
  try {
    call();
  } catch (const E& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "wrong exception type: " << e.what();
    return "";
  }
  ADD_FAILURE() << "no exception";
  return "";
}

// Writes sample frame 0 and checks that the files hold exactly it. The check reads copies: this process
// has the HDF5 file open for writing, and HDF5 would hand a second open of the same file that same handle.
void finish_with_a_good_frame(FrameWriter& writer, const std::string& title) {
  namespace fs = std::filesystem;
  const FrameData frame = hfmpm::test::sample_frames()[0];
  hfmpm::test::write_frame(writer, frame);
  const fs::path h5(writer.h5_path()), xmf(writer.xdmf_path());
  const fs::path copy = h5.parent_path() / "copy";
  fs::create_directory(copy);
  fs::copy_file(h5, copy / h5.filename());
  fs::copy_file(xmf, copy / xmf.filename());
  hfmpm::test::verify_files(copy / h5.filename(), copy / xmf.filename(), {frame}, {{"title", title}});
}

TEST(FrameWriterErrors, SizeMismatchNamesTheSetTheArrayAndBothSizes) {
  Scratch scratch("output-size");
  FrameWriter writer(scratch.dir() + "/run.h5", "size");
  writer.begin_frame(0.0, 0);
  writer.points("particles", std::vector<Vec2>(3, Vec2(1, 2)));
  const std::string scalar = message_of<std::invalid_argument>([&] { writer.scalar("particles", "mass", {1, 2}); });
  for (const char* part : {"particles", "mass", "2", "3"}) EXPECT_NE(scalar.find(part), std::string::npos) << scalar;
  const std::string integer = message_of<std::invalid_argument>([&] {
    writer.integer("particles", "id", {1, 2, 3, 4, 5});
  });
  for (const char* part : {"particles", "id", "5", "3"}) EXPECT_NE(integer.find(part), std::string::npos) << integer;
  const std::string vector = message_of<std::invalid_argument>([&] { writer.vector("particles", "velocity", {}); });
  for (const char* part : {"particles", "velocity", "0", "3"}) {
    EXPECT_NE(vector.find(part), std::string::npos) << vector;
  }
  const std::string tensor = message_of<std::invalid_argument>(
      [&] { writer.tensor("particles", "stress", std::vector<Eigen::Vector4d>(4, Eigen::Vector4d::Zero())); });
  for (const char* part : {"particles", "stress", "4", "3"}) {
    EXPECT_NE(tensor.find(part), std::string::npos) << tensor;
  }
  // Nothing was added: the right sizes are still accepted under the same names.
  writer.scalar("particles", "mass", {1, 2, 3});
  EXPECT_THROW(writer.scalar("particles", "mass", {1, 2, 3}), std::logic_error);  // twice in a frame
  writer.end_frame();
  writer.begin_frame(1.0, 1);
  writer.end_frame();
  EXPECT_EQ(writer.frames_written(), 2u);
}

TEST(FrameWriterErrors, BadNamesAreRejected) {
  Scratch scratch("output-names");
  FrameWriter writer(scratch.dir() + "/run.h5", "names");
  writer.begin_frame(0.0, 0);
  writer.points("particles", {Vec2(0, 0)});
  for (const std::string bad : {"", "a b", "a-b", "a/b", "a.b", "a:b", "caf\xc3\xa9", "x\n", "<x>", "a&b"}) {
    SCOPED_TRACE("name '" + bad + "'");
    const std::string m = message_of<std::invalid_argument>([&] { writer.points(bad, {}); });
    EXPECT_NE(m.find("invalid set name"), std::string::npos) << m;
    EXPECT_THROW(writer.scalar("particles", bad, {1.0}), std::invalid_argument);
    EXPECT_THROW(writer.integer("particles", bad, {1}), std::invalid_argument);
    EXPECT_THROW(writer.vector("particles", bad, {Vec2(0, 0)}), std::invalid_argument);
    EXPECT_THROW(writer.tensor("particles", bad, {Eigen::Vector4d::Zero()}), std::invalid_argument);
    EXPECT_THROW(writer.scalar(bad, "mass", {1.0}), std::invalid_argument);
    EXPECT_THROW(writer.attribute(bad, "value"), std::invalid_argument);
  }
  const std::string reserved = message_of<std::invalid_argument>([&] { writer.scalar("particles", "positions", {1}); });
  EXPECT_NE(reserved.find("positions"), std::string::npos) << reserved;
  writer.points("Crack_2", {});  // all allowed characters
  writer.end_frame();
  writer.begin_frame(1.0, 1);
  writer.end_frame();
  EXPECT_EQ(writer.frames_written(), 2u);
}

TEST(FrameWriterErrors, AttributesNeedTheirSetsPointsInTheSameFrame) {
  Scratch scratch("output-before");
  FrameWriter writer(scratch.dir() + "/run.h5", "before");
  writer.begin_frame(0.0, 0);
  const std::string m = message_of<std::logic_error>([&] { writer.scalar("particles", "mass", {}); });
  EXPECT_NE(m.find("before points()"), std::string::npos) << m;
  EXPECT_NE(m.find("particles"), std::string::npos) << m;
  EXPECT_THROW(writer.integer("particles", "id", {}), std::logic_error);
  EXPECT_THROW(writer.vector("particles", "v", {}), std::logic_error);
  EXPECT_THROW(writer.tensor("particles", "s", {}), std::logic_error);
  writer.points("particles", {});
  writer.scalar("particles", "mass", {});
  writer.end_frame();
  // A set from the previous frame is not declared in this one.
  writer.begin_frame(1.0, 1);
  EXPECT_THROW(writer.scalar("particles", "mass", {}), std::logic_error);
  writer.end_frame();
  EXPECT_EQ(writer.frames_written(), 2u);
}

TEST(FrameWriterErrors, CallsOutOfOrderAreLogicErrors) {
  Scratch scratch("output-order");
  FrameWriter writer(scratch.dir() + "/run.h5", "order");
  const std::string m = message_of<std::logic_error>([&] { writer.end_frame(); });
  EXPECT_NE(m.find("end_frame"), std::string::npos) << m;
  EXPECT_NE(m.find("begin_frame"), std::string::npos) << m;
  EXPECT_THROW(writer.points("particles", {}), std::logic_error);
  EXPECT_THROW(writer.scalar("particles", "mass", {}), std::logic_error);
  writer.begin_frame(0.0, 0);
  EXPECT_THROW(writer.begin_frame(1.0, 1), std::logic_error);
  writer.points("particles", {Vec2(1, 1)});
  EXPECT_THROW(writer.points("particles", {Vec2(1, 1)}), std::logic_error);  // same set twice
  writer.scalar("particles", "s_xx", {1.0});
  const std::string clash = message_of<std::logic_error>(
      [&] { writer.tensor("particles", "s", {Eigen::Vector4d::Zero()}); });  // would show as s_xx
  EXPECT_NE(clash.find("s_xx"), std::string::npos) << clash;
  writer.attribute("units", "SI");  // allowed inside a frame
  writer.end_frame();
  EXPECT_THROW(writer.end_frame(), std::logic_error);
  EXPECT_EQ(writer.frames_written(), 1u);
}

TEST(FrameWriterErrors, TimesMustBeFiniteAndIncrease) {
  Scratch scratch("output-time");
  FrameWriter writer(scratch.dir() + "/run.h5", "time");
  EXPECT_THROW(writer.begin_frame(std::nan(""), 0), std::invalid_argument);
  EXPECT_THROW(writer.begin_frame(INFINITY, 0), std::invalid_argument);
  EXPECT_FALSE(writer.in_frame());
  writer.begin_frame(-1.0, 0);  // negative times are fine
  writer.end_frame();
  EXPECT_THROW(writer.begin_frame(-1.0, 1), std::invalid_argument);
  EXPECT_THROW(writer.begin_frame(-2.0, 1), std::invalid_argument);
  EXPECT_FALSE(writer.in_frame());
  writer.begin_frame(-0.5, 1);
  writer.end_frame();
  EXPECT_EQ(writer.frames_written(), 2u);
}

TEST(FrameWriterErrors, BadPathsAreReported) {
  const std::string missing = "/nonexistent-hfmpm-dir/run.h5";
  const std::string m = message_of<std::runtime_error>([&] { FrameWriter writer(missing, "t"); });
  EXPECT_NE(m.find(missing), std::string::npos) << m;
  Scratch scratch("output-paths");
  EXPECT_THROW(FrameWriter(scratch.dir() + "/run.xmf", "t"), std::invalid_argument);
  EXPECT_THROW(FrameWriter(scratch.dir() + "/a:b.h5", "t"), std::invalid_argument);
  EXPECT_THROW(FrameWriter(scratch.dir() + "/", "t"), std::invalid_argument);
  // No extension: the XDMF is <path>.xmf.
  FrameWriter writer(scratch.dir() + "/run", "plain");
  EXPECT_EQ(writer.xdmf_path(), scratch.dir() + "/run.xmf");
  finish_with_a_good_frame(writer, "plain");
}

TEST(FrameWriterErrors, RejectedCallsLeaveTheWriterUsable) {
  Scratch scratch("output-usable");
  FrameWriter writer(scratch.dir() + "/run.h5", "usable");
  EXPECT_THROW(writer.end_frame(), std::logic_error);
  EXPECT_THROW(writer.begin_frame(std::nan(""), 0), std::invalid_argument);
  EXPECT_THROW(writer.attribute("bad key", "v"), std::invalid_argument);
  finish_with_a_good_frame(writer, "usable");
}

}  // namespace
