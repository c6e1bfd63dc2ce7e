// Validity per navigation group: a group the epoch marks invalid goes on the bus as the
// not-available raw code of every one of its signals (never the zero or identity the state may
// hold), the other groups are unaffected, and GfinsStatus flags the epoch (bit 5).
#include <gtest/gtest.h>

#include <cmath>

#include "fake_bus.hpp"
#include "gfins/can/publisher.hpp"
#include "gfins/can/signal_codec.hpp"

namespace gfins::can {
namespace {

using testing::ArrayBus;

/// A navigating epoch with a value in every navigation field (none of them zero).
Epoch moving_epoch() {
  Epoch e;
  e.nav.seq = 0;
  e.nav.q_nb = nav::Quat<float>(0.9f, 0.1f, -0.3f, 0.2f).normalized();
  e.nav.w_b = nav::Vec3<float>(0.1f, -0.2f, 0.3f);
  e.nav.wdot_b = nav::Vec3<float>(1.0f, -2.0f, 3.0f);
  e.nav.f_b = nav::Vec3<float>(0.5f, -0.4f, -9.8f);
  e.nav.v_n = nav::Vec3<float>(10.0f, -3.0f, 0.2f);
  e.nav.r_n = nav::Vec3<float>(100.0f, -30.0f, 2.0f);
  e.mode = Mode::kNavigating;
  return e;
}

enum class Group { kAttitude, kRate, kAngularAccel, kAccel, kVelocity, kPosition };

Validity all_but(Group g) {
  Validity v;
  switch (g) {
    case Group::kAttitude:
      v.attitude = false;
      break;
    case Group::kRate:
      v.rate = false;
      break;
    case Group::kAngularAccel:
      v.angular_accel = false;
      break;
    case Group::kAccel:
      v.accel = false;
      break;
    case Group::kVelocity:
      v.velocity = false;
      break;
    case Group::kPosition:
      v.position = false;
      break;
  }
  return v;
}

bool in_group(Field f, Group g) {
  switch (g) {
    case Group::kAttitude:
      return f == Field::kQuaternion || f == Field::kEuler;
    case Group::kRate:
      return f == Field::kRate;
    case Group::kAngularAccel:
      return f == Field::kAngularAccel;
    case Group::kAccel:
      return f == Field::kAccel;
    case Group::kVelocity:
      return f == Field::kVelocity;
    case Group::kPosition:
      return f == Field::kPosition;
  }
  return false;
}

bool is_navigation(Field f) {
  for (Group g : {Group::kAttitude, Group::kRate, Group::kAngularAccel, Group::kAccel,
                  Group::kVelocity, Group::kPosition}) {
    if (in_group(f, g)) return true;
  }
  return false;
}

TEST(Validity, EveryNavigationSignalHasANotAvailableCode) {
  int n = 0;
  for (const MessageDef& m : kMessages) {
    for (const SignalDef& s : m.signals) {
      if (!is_navigation(s.field)) continue;
      EXPECT_TRUE(s.has_na) << s.name;
      ++n;
    }
  }
  EXPECT_EQ(n, 4 + 3 + 3 + 3 + 3 + 3 + 3);  // q, Euler, rate, ω̇, f, v, r
}

TEST(Validity, AnInvalidGroupIsSentAsNotAvailableSignalBySignal) {
  for (Group g : {Group::kAttitude, Group::kRate, Group::kAngularAccel, Group::kAccel,
                  Group::kVelocity, Group::kPosition}) {
    SCOPED_TRACE(static_cast<int>(g));
    Epoch e = moving_epoch();
    e.valid = all_but(g);
    int na = 0;
    int valid = 0;
    for (const MessageDef& m : kMessages) {
      if (m.kind != MessageKind::kData) continue;
      std::uint32_t saturated = 0;
      std::uint32_t unavailable = 0;
      const hal::CanFrame f = encode_data_frame(m, e, 0, 0, &saturated, &unavailable);
      const std::uint64_t p = payload_of(f);
      std::uint32_t expected_na = 0;
      for (const SignalDef& s : m.signals) {
        if (!is_navigation(s.field)) continue;
        const std::int64_t raw = raw_value(s, extract_bits(p, s));
        if (in_group(s.field, g)) {
          EXPECT_EQ(raw, s.na_raw) << s.name;
          EXPECT_TRUE(std::isnan(decode_signal(s, extract_bits(p, s)))) << s.name;
          ++expected_na;
          ++na;
        } else {
          EXPECT_NE(raw, s.na_raw) << s.name;  // the other groups keep their values
          EXPECT_FALSE(std::isnan(decode_signal(s, extract_bits(p, s)))) << s.name;
          ++valid;
        }
      }
      // σ and the other non-navigation signals of this epoch are not available either (no
      // filter output given), so count only at least the group's signals.
      EXPECT_GE(unavailable, expected_na) << m.name;
    }
    EXPECT_GT(na, 0);
    EXPECT_GT(valid, 0);
  }
}

TEST(Validity, NothingValidSendsNoZeroAndNoIdentityAndFlagsTheEpoch) {
  ArrayBus<64> bus;
  Publisher pub(bus, PublisherConfig{});
  Epoch e;  // identity attitude, zero everything: what an aligning state holds
  e.mode = Mode::kAligning;
  e.valid = Validity::none();
  pub.publish(e);
  ASSERT_GT(bus.count, 2u);
  int na = 0;
  for (std::size_t i = 0; i < bus.count; ++i) {
    const MessageDef* m = find_message(bus.frames[i].id, nullptr);
    ASSERT_NE(m, nullptr);
    const std::uint64_t p = payload_of(bus.frames[i]);
    for (const SignalDef& s : m->signals) {
      if (!is_navigation(s.field)) continue;
      EXPECT_EQ(raw_value(s, extract_bits(p, s)), s.na_raw) << s.name;
      ++na;
    }
  }
  EXPECT_EQ(na, 4 + 3 + 3 + 3 + 3 + 3 + 3);  // every navigation signal of epoch 0 (seq 0)
  const MessageDef& status = message(MessageId::kStatus);
  const SignalDef& flags = status.signals[signal_index(status, "StatusFlags")];
  EXPECT_NE(extract_bits(payload_of(bus.frames[1]), flags) & status_bits::kCanNotAvailable, 0u);
}

TEST(Validity, AllValidIsWhatTheBoardAlwaysSent) {
  // Default Validity: every group valid, so an app that does not set it is unchanged.
  const Epoch e = moving_epoch();
  for (const MessageDef& m : kMessages) {
    for (const SignalDef& s : m.signals) {
      if (!is_navigation(s.field)) continue;
      EXPECT_FALSE(std::isnan(epoch_field(e, s.field, s.index))) << s.name;
    }
  }
}

}  // namespace
}  // namespace gfins::can
