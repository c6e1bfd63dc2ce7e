// Accuracy on the bus: the filter's 1σ (GfinsAccuracy, GfinsPositionD), the filter mode
// (GfinsVelocity) and the aiding counters (GfinsAidingCounters, multiplexed by kind): values
// round-trip, a σ rounds up and saturates at its maximum (never wraps, never shows smaller than
// it is), a σ without a filter is not available, and the counters take turns by kind.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "fake_bus.hpp"
#include "gfins/can/publisher.hpp"
#include "gfins/can/signal_codec.hpp"

namespace gfins::can {
namespace {

using testing::ArrayBus;

const SignalDef& signal_of(MessageId id, std::string_view name) {
  const MessageDef& m = message(id);
  const std::size_t i = signal_index(m, name);
  EXPECT_NE(i, kNoSignal) << name;
  return m.signals[i];
}

double decoded(const hal::CanFrame& f, MessageId id, std::string_view name) {
  const SignalDef& s = signal_of(id, name);
  return decode_signal(s, extract_bits(payload_of(f), s));
}

Epoch aided_epoch() {
  Epoch e;
  Accuracy& a = e.accuracy;
  a.sigma_roll_rad = 0.0012f;
  a.sigma_pitch_rad = 0.0015f;
  a.sigma_heading_rad = 0.0213f;
  a.sigma_vel_h_mps = 0.123f;
  a.sigma_vel_v_mps = 0.2f;
  a.sigma_pos_h_m = 1.234f;
  a.sigma_pos_v_m = 2.5f;
  a.filter_mode = filter_mode::kGnss | filter_mode::kHeading;
  for (std::size_t k = 0; k < kAidKindCount; ++k) {
    a.aiding[k].accepted = 1000 * static_cast<std::uint32_t>(k + 1) + 70000;  // wraps mod 2^16
    a.aiding[k].rejected = static_cast<std::uint32_t>(k + 3);
    a.aiding[k].since_accepted_s = 0.25f * static_cast<float>(k + 1);
  }
  a.aiding[1].since_accepted_s = kNoValue;  // no ZARU yet
  return e;
}

hal::CanFrame frame(MessageId id, const Epoch& e, std::uint8_t selector = 0,
                    std::uint32_t* saturated = nullptr, std::uint32_t* unavailable = nullptr) {
  return encode_data_frame(message(id), e, 0, 0, saturated, unavailable, selector);
}

TEST(Accuracy, SigmasRoundTripRoundedUpByLessThanAStep) {
  const Epoch e = aided_epoch();
  struct Case {
    MessageId id;
    const char* name;
    float value;
  };
  const Accuracy& a = e.accuracy;
  for (const Case& c : {Case{MessageId::kAccuracy, "SigmaRoll", a.sigma_roll_rad},
                        Case{MessageId::kAccuracy, "SigmaPitch", a.sigma_pitch_rad},
                        Case{MessageId::kAccuracy, "SigmaHeading", a.sigma_heading_rad},
                        Case{MessageId::kAccuracy, "SigmaVelH", a.sigma_vel_h_mps},
                        Case{MessageId::kAccuracy, "SigmaVelV", a.sigma_vel_v_mps},
                        Case{MessageId::kPositionD, "SigmaPosH", a.sigma_pos_h_m},
                        Case{MessageId::kPositionD, "SigmaPosV", a.sigma_pos_v_m}}) {
    SCOPED_TRACE(c.name);
    const double step = signal_of(c.id, c.name).factor;
    const double x = static_cast<double>(c.value);
    const double got = decoded(frame(c.id, e), c.id, c.name);
    EXPECT_GE(got, x - 1e-9 * step);
    EXPECT_LT(got, x + step);
  }
  EXPECT_EQ(decoded(frame(MessageId::kVelocity, e), MessageId::kVelocity, "FilterMode"),
            filter_mode::kGnss | filter_mode::kHeading);
}

TEST(Accuracy, ASigmaBeyondItsRangeSaturatesAtMaxNeverWraps) {
  Epoch e = aided_epoch();
  e.accuracy.sigma_heading_rad = 3.0f;  // beyond 2.046 rad
  e.accuracy.sigma_pos_h_m = 1e7f;      // an unaided drift
  std::uint32_t saturated = 0;
  const hal::CanFrame acc = frame(MessageId::kAccuracy, e, 0, &saturated);
  const SignalDef& h = signal_of(MessageId::kAccuracy, "SigmaHeading");
  EXPECT_DOUBLE_EQ(decoded(acc, MessageId::kAccuracy, "SigmaHeading"), h.max);
  EXPECT_EQ(saturated, 0u);  // "at least max": not a clipped navigation value (no status bit 4)
  const hal::CanFrame pos = frame(MessageId::kPositionD, e);
  const SignalDef& p = signal_of(MessageId::kPositionD, "SigmaPosH");
  EXPECT_DOUBLE_EQ(decoded(pos, MessageId::kPositionD, "SigmaPosH"), p.max);
  // The saturated code is max, one below the not-available code: never NA, never small.
  EXPECT_EQ(raw_value(p, extract_bits(payload_of(pos), p)), p.na_raw - 1);
}

TEST(Accuracy, NoFilterMeansNotAvailableNotZero) {
  const Epoch e;  // default Accuracy: every σ NaN, no filter
  std::uint32_t unavailable = 0;
  const hal::CanFrame acc = frame(MessageId::kAccuracy, e, 0, nullptr, &unavailable);
  EXPECT_EQ(unavailable, 0u);  // by design without a filter: no status bit 5
  for (const char* n : {"SigmaRoll", "SigmaPitch", "SigmaHeading", "SigmaVelH", "SigmaVelV"}) {
    EXPECT_TRUE(std::isnan(decoded(acc, MessageId::kAccuracy, n))) << n;
    const SignalDef& s = signal_of(MessageId::kAccuracy, n);
    EXPECT_EQ(raw_value(s, extract_bits(payload_of(acc), s)), s.na_raw) << n;
  }
  EXPECT_EQ(decoded(frame(MessageId::kVelocity, e), MessageId::kVelocity, "FilterMode"), 0.0);
}

TEST(AidingCounters, EachSelectorCarriesItsKindsCounts) {
  const Epoch e = aided_epoch();
  const char* names[] = {"Zupt", "Zaru", "GnssPos", "GnssVel", "Heading"};
  ASSERT_EQ(selector_count(message(MessageId::kAidingCounters)), kAidKindCount);
  for (std::uint8_t k = 0; k < kAidKindCount; ++k) {
    SCOPED_TRACE(names[k]);
    const hal::CanFrame f = frame(MessageId::kAidingCounters, e, k);
    EXPECT_EQ(decoded(f, MessageId::kAidingCounters, "AidKind"), k);
    EXPECT_EQ(f.data[0] & 0x0F, k);  // ICD: AidKind in bits 0..3
    const std::string n(names[k]);
    EXPECT_EQ(decoded(f, MessageId::kAidingCounters, n + "Accepted"),
              (1000.0 * (k + 1) + 70000) - 65536);  // mod 2^16
    EXPECT_EQ(decoded(f, MessageId::kAidingCounters, n + "Rejected"), k + 3);
    const double since = decoded(f, MessageId::kAidingCounters, n + "Since");
    if (k == 1) {
      EXPECT_TRUE(std::isnan(since));
    } else {
      EXPECT_NEAR(since, 0.25 * (k + 1), 1e-9);
    }
  }
}

TEST(AidingCounters, ThePublisherSendsTheKindsInTurn) {
  ArrayBus<4096> bus;
  Publisher pub(bus, PublisherConfig{});
  Epoch e = aided_epoch();
  for (std::uint32_t seq = 0; seq < 4000; ++seq) {
    e.nav.seq = seq;
    pub.publish(e);
  }
  std::vector<int> kinds;
  for (std::size_t i = 0; i < bus.count; ++i) {
    if (bus.frames[i].id == message(MessageId::kAidingCounters).base_id) {
      kinds.push_back(bus.frames[i].data[0] & 0x0F);
    }
  }
  ASSERT_EQ(kinds.size(), 10u);  // every 400 samples
  for (std::size_t i = 0; i < kinds.size(); ++i) EXPECT_EQ(kinds[i], static_cast<int>(i % 5));
}

}  // namespace
}  // namespace gfins::can
