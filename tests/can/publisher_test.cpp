// Publisher: dividers, the epoch counter, frame order, the saturation flag, divider rules.
#include "gfins/can/publisher.hpp"

#include <gtest/gtest.h>

#include "fake_bus.hpp"
#include "gfins/can/signal_codec.hpp"

namespace gfins::can {
namespace {

using testing::ArrayBus;

Epoch epoch_at(std::uint32_t seq) {
  Epoch e;
  e.nav.seq = seq;
  e.nav.t_ns = static_cast<std::int64_t>(seq) * 1'000'000;  // 1 kHz
  return e;
}

std::uint8_t counter_of(const hal::CanFrame& f) {
  return static_cast<std::uint8_t>(f.data[6] >> 4);
}

TEST(Publisher, DefaultsSendTheDocumentedFramesPerSecond) {
  ArrayBus<4096> bus;
  Publisher pub(bus, PublisherConfig{});
  ASSERT_TRUE(pub.init_status().is_ok());
  for (std::uint32_t seq = 0; seq < 1000; ++seq) pub.publish(epoch_at(seq));  // one second
  // 8 messages at 100 Hz, Euler and angular acceleration at 50 Hz, two health frames and the
  // command counters at 1 Hz, accuracy at 5 Hz, aiding counters every 400 samples (seq 0, 400,
  // 800).
  EXPECT_EQ(bus.count, 8u * 100 + 2 * 50 + 3 + 5 + 3);
  EXPECT_EQ(pub.counters().epochs, 100u);
  EXPECT_EQ(pub.counters().frames_sent, bus.count);
}

TEST(Publisher, EachEpochOpensWithEpochThenStatusAndSharesOneCounter) {
  ArrayBus<256> bus;
  Publisher pub(bus, PublisherConfig{.node_id = 5, .dividers = default_dividers(), .budget = {}});
  for (std::uint32_t seq = 0; seq < 100; ++seq) pub.publish(epoch_at(seq));
  std::uint8_t expected_counter = 0;
  std::size_t i = 0;
  int epochs = 0;
  while (i < bus.count) {
    ASSERT_EQ(bus.frames[i].id, 0x105u) << i;      // GfinsEpoch of node 5
    ASSERT_EQ(bus.frames[i + 1].id, 0x115u) << i;  // GfinsStatus
    const std::uint8_t c = counter_of(bus.frames[i]);
    EXPECT_EQ(c, expected_counter);
    std::size_t j = i;
    while (j < bus.count && (j == i || bus.frames[j].id != 0x105u)) {
      EXPECT_EQ(counter_of(bus.frames[j]), c);
      EXPECT_TRUE(crc_ok(bus.frames[j]));
      ++j;
    }
    i = j;
    expected_counter = static_cast<std::uint8_t>((expected_counter + 1) % 16);
    ++epochs;
  }
  EXPECT_EQ(epochs, 10);
}

TEST(Publisher, SaturatedValueIsClippedAndFlaggedInThatEpochsStatus) {
  ArrayBus<64> bus;
  Publisher pub(bus, PublisherConfig{});
  Epoch e = epoch_at(0);
  e.nav.v_n = nav::Vec3<float>(400.0f, 0.0f, 0.0f);  // beyond VelN's 320 m/s
  pub.publish(e);
  const MessageDef& status = message(MessageId::kStatus);
  const std::uint64_t flags = extract_bits(payload_of(bus.frames[1]), status.signals[0]);
  EXPECT_NE(flags & status_bits::kCanSaturated, 0u);
  EXPECT_EQ(pub.counters().saturated_values, 1u);
  for (std::size_t i = 0; i < bus.count; ++i) {
    if (bus.frames[i].id != 0x170) continue;
    const MessageDef& v = message(MessageId::kVelocity);
    EXPECT_NEAR(decode_signal(v.signals[0], extract_bits(payload_of(bus.frames[i]), v.signals[0])),
                320.0, 1e-9);
  }
  // The next epoch, in range again, is not flagged.
  bus.clear();
  pub.publish(epoch_at(10));
  EXPECT_EQ(extract_bits(payload_of(bus.frames[1]), status.signals[0]) & status_bits::kCanSaturated,
            0u);
}

TEST(Publisher, NavStatusBitsReachTheStatusFrame) {
  ArrayBus<64> bus;
  Publisher pub(bus, PublisherConfig{});
  Epoch e = epoch_at(0);
  e.nav.status = nav::nav_status::kAligned | nav::nav_status::kCompensated;
  e.status_bits = status_bits::kAdcCrcError;
  e.cal_id = 0xDEADBEEF;
  pub.publish(e);
  const MessageDef& status = message(MessageId::kStatus);
  const std::uint64_t p = payload_of(bus.frames[1]);
  EXPECT_EQ(extract_bits(p, status.signals[0]),
            status_bits::kAligned | status_bits::kCompensated | status_bits::kAdcCrcError);
  EXPECT_EQ(extract_bits(p, status.signals[1]), 0xDEADBEEFu);
}

// The budget: the table's defaults at 1 kHz (aiding messages included: 910.5 frames/s x 135
// worst-case bits = 122,917.5 bit/s, docs/can-interface.md) on a 250 kbit/s bus are 49.2 %;
// with a 50 % budget one more message at 100 Hz (+13,500 bit/s, 54.6 %) is refused and changes
// nothing, one at 10 Hz (+1,350 bit/s, 49.7 %) is accepted. A construction over budget falls
// back to the defaults with the status.
TEST(Publisher, DividersBeyondTheBusBudgetAreRefused) {
  ArrayBus<8> bus;
  PublisherConfig c;
  c.budget = BusBudget{1000.0, 250000, 0.5};
  Publisher pub(bus, c);
  ASSERT_TRUE(pub.init_status().is_ok());
  EXPECT_NEAR(c.budget.load(pub.dividers()), 910.5 * 135.0 / 250000.0, 1e-12);
  EXPECT_EQ(pub.set_divider(MessageId::kSensorsA, 10).code(), ErrorCode::kResourceExhausted);
  EXPECT_EQ(pub.divider(MessageId::kSensorsA), 0);
  EXPECT_TRUE(pub.set_divider(MessageId::kSensorsA, 100).is_ok());
  EXPECT_NEAR(c.budget.load(pub.dividers()), 920.5 * 135.0 / 250000.0, 1e-12);
  // The rules come first: a divider that breaks them is refused for that, not for the load.
  EXPECT_EQ(pub.set_divider(MessageId::kSensorsB, 15).code(), ErrorCode::kInvalidArgument);
  PublisherConfig over = c;
  over.dividers[static_cast<std::size_t>(MessageId::kSensorsB)] = 10;
  Publisher refused(bus, over);
  EXPECT_EQ(refused.init_status().code(), ErrorCode::kResourceExhausted);
  EXPECT_EQ(refused.dividers(), default_dividers());
}

TEST(Publisher, DividerRules) {
  ArrayBus<8> bus;
  Publisher pub(bus, PublisherConfig{});
  EXPECT_TRUE(pub.set_divider(MessageId::kSensorsA, 10).is_ok());
  EXPECT_EQ(pub.divider(MessageId::kSensorsA), 10);
  EXPECT_FALSE(pub.set_divider(MessageId::kSensorsA, 15).is_ok());  // not a multiple of 10
  EXPECT_EQ(pub.divider(MessageId::kSensorsA), 10);                 // unchanged
  EXPECT_FALSE(pub.set_divider(MessageId::kStatus, 20).is_ok());    // follows Epoch
  EXPECT_FALSE(pub.set_divider(MessageId::kCommand, 10).is_ok());
  EXPECT_FALSE(pub.set_divider(MessageId::kEpoch, 20).is_ok());  // Quaternion at 10 would orphan
  EXPECT_TRUE(pub.set_divider(MessageId::kEuler, 0).is_ok());    // off
  // The table's limit (kMaxDivider, 10 s between frames at 1 kHz), which the DBC's Divider range
  // and the configuration rule state too: at it accepted, one above refused and unchanged.
  EXPECT_TRUE(pub.set_divider(MessageId::kSensorsA, 10000).is_ok());
  EXPECT_EQ(pub.set_divider(MessageId::kSensorsA, 10010).code(), ErrorCode::kOutOfRange);
  EXPECT_EQ(pub.divider(MessageId::kSensorsA), 10000);
  EXPECT_TRUE(pub.set_divider(MessageId::kEpoch, 5).is_ok());
  EXPECT_EQ(pub.divider(MessageId::kStatus), 5);
  // The epoch and status frames are never off, even with every other message off (a silent
  // board would look like a dead one).
  for (const MessageDef& m : kMessages) {
    if (m.kind == MessageKind::kData && m.id != MessageId::kEpoch && m.id != MessageId::kStatus) {
      ASSERT_TRUE(pub.set_divider(m.id, 0).is_ok()) << m.name;
    }
  }
  EXPECT_EQ(pub.set_divider(MessageId::kEpoch, 0).code(), ErrorCode::kOutOfRange);
  EXPECT_EQ(pub.divider(MessageId::kEpoch), 5);
  EXPECT_EQ(pub.divider(MessageId::kStatus), 5);
  PublisherConfig silent;
  silent.dividers.fill(0);
  EXPECT_EQ(check_config(silent).code(), ErrorCode::kOutOfRange);
  PublisherConfig bad;
  bad.node_id = 16;
  EXPECT_FALSE(check_config(bad).is_ok());
  Publisher fallback(bus, bad);
  EXPECT_FALSE(fallback.init_status().is_ok());
  EXPECT_EQ(fallback.node_id(), 0);
}

TEST(Publisher, RefusedFramesAreCountedNotRetried) {
  ArrayBus<64> bus;
  bus.refuse = true;
  Publisher pub(bus, PublisherConfig{});
  pub.publish(epoch_at(0));
  EXPECT_EQ(pub.counters().frames_sent, 0u);
  EXPECT_EQ(pub.counters().send_failures, 15u);  // the 15 data messages enabled by default
}

}  // namespace
}  // namespace gfins::can
