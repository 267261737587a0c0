// The in-memory transport (runtime/include/hfmpm/runtime/memory_transport.hpp)
// on its own: routing ids, replies, the data plane in both directions, a send
// before the peer connects, bad bytes, an unknown peer, poll.
#include "hfmpm/runtime/memory_transport.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "hfmpm/proto/envelope.hpp"

namespace {

using hfmpm::coupling::MemoryTransport;
using hfmpm::coupling::PollItem;
using std::chrono::microseconds;
using std::chrono::milliseconds;
namespace protocol = hfmpm::protocol;

protocol::Envelope beat(std::uint64_t step) {
  protocol::Envelope envelope;
  envelope.mutable_heartbeat()->set_role(protocol::SOLID);
  envelope.mutable_heartbeat()->set_step(step);
  return envelope;
}

TEST(MemoryTransport, RoutesBySideAndAnswers) {
  MemoryTransport transport;
  auto router = transport.bind_router("inproc://control", {});
  EXPECT_EQ(router->endpoint(), "inproc://control");
  auto solid = transport.connect_control("inproc://control", protocol::SOLID, std::nullopt);
  auto heartbeat = transport.connect_heartbeat("inproc://control", protocol::SOLID, std::nullopt);
  solid->send(beat(1));
  EXPECT_TRUE(heartbeat->send_bytes(hfmpm::proto::encode(beat(2)), false));
  auto first = router->receive(microseconds(0));
  ASSERT_TRUE(first);
  EXPECT_EQ(first->peer, "solid");
  EXPECT_TRUE(first->well_framed);
  EXPECT_EQ(hfmpm::proto::decode(first->payload.data(), first->payload.size(), "test").heartbeat().step(), 1u);
  auto second = router->receive(microseconds(0));
  ASSERT_TRUE(second);
  EXPECT_EQ(second->peer, "solid.hb");
  EXPECT_FALSE(router->receive(microseconds(1000)));

  router->send("solid", beat(3));
  const auto answer = solid->receive("the coupler", microseconds(0));
  ASSERT_TRUE(answer);
  EXPECT_EQ(answer->heartbeat().step(), 3u);
  EXPECT_FALSE(heartbeat->receive("the coupler", microseconds(0)));
  EXPECT_EQ(transport.messages(), 3u);
}

TEST(MemoryTransport, AnUnknownOrDepartedPeerIsUnreachable) {
  MemoryTransport transport;
  auto router = transport.bind_router("inproc://control", {});
  EXPECT_THROW(router->send("fluid", beat(1)), std::runtime_error);
  auto fluid = transport.connect_control("inproc://control", protocol::FLUID, std::nullopt);
  EXPECT_NO_THROW(router->send("fluid", beat(1)));
  fluid.reset();
  EXPECT_THROW(router->send("fluid", beat(2)), std::runtime_error);
  EXPECT_THROW(transport.bind_router("inproc://control", {}), std::runtime_error);
}

TEST(MemoryTransport, TheDataPlaneCarriesFramesBothWaysEvenBeforeThePeerConnects) {
  MemoryTransport transport;
  auto solid = transport.bind_data("inproc://data", 1 << 20, std::nullopt);
  EXPECT_EQ(solid->endpoint(), "inproc://data");
  EXPECT_TRUE(solid->send_bytes(hfmpm::proto::encode(beat(0)), false));  // queued for the fluid
  auto fluid = transport.connect_data(solid->endpoint(), 1 << 20, std::nullopt);
  const auto frame = fluid->receive("the solid", microseconds(0));
  ASSERT_TRUE(frame);
  EXPECT_EQ(frame->heartbeat().step(), 0u);
  fluid->send(beat(1));
  EXPECT_EQ(solid->receive("the fluid", microseconds(0))->heartbeat().step(), 1u);
  EXPECT_FALSE(solid->receive("the fluid", microseconds(0)));
}

TEST(MemoryTransport, BadBytesAreAProtocolErrorNamingTheSender) {
  MemoryTransport transport;
  auto solid = transport.bind_data("inproc://data", 1 << 20, std::nullopt);
  auto fluid = transport.connect_data("inproc://data", 1 << 20, std::nullopt);
  ASSERT_TRUE(solid->send_bytes(std::string("\xff\x01garbage", 9), true));
  try {
    (void)fluid->receive("the solid side (data plane)", microseconds(0));
    FAIL() << "no ProtocolError";
  } catch (const hfmpm::proto::ProtocolError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("the solid side (data plane)"));
  }
}

TEST(MemoryTransport, PollWakesOnAMessageFromAnotherThread) {
  MemoryTransport transport;
  auto solid = transport.bind_data("inproc://data", 1 << 20, std::nullopt);
  auto fluid = transport.connect_data("inproc://data", 1 << 20, std::nullopt);
  auto router = transport.bind_router("inproc://control", {});
  auto control = transport.connect_control("inproc://control", protocol::FLUID, std::nullopt);
  PollItem items[] = {{fluid.get(), false}, {control.get(), false}};
  EXPECT_EQ(transport.poll(items, milliseconds(0)), 0);
  EXPECT_FALSE(items[0].ready);
  std::thread sender([&] {
    std::this_thread::sleep_for(milliseconds(20));
    solid->send(beat(5));
  });
  EXPECT_EQ(transport.poll(items, milliseconds(5000)), 1);
  sender.join();
  EXPECT_TRUE(items[0].ready);
  EXPECT_FALSE(items[1].ready);
  PollItem send_item[] = {{fluid.get(), true}};
  EXPECT_EQ(transport.poll(send_item, milliseconds(0)), 1);  // a queue always takes a message
}

}  // namespace
