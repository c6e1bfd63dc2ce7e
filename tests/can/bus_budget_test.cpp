// Bus load of the default dividers, recomputed from the message table with the worst-case
// stuffed frame length of the CAN 2.0 frame format written out here (ISO 11898-1 base format).
#include <gtest/gtest.h>

#include "gfins/can/message_table.hpp"
#include "gfins/can/publisher.hpp"

namespace gfins::can {
namespace {

// Base-format data frame, field by field.
constexpr int kSof = 1, kIdentifier = 11, kRtr = 1, kIde = 1, kR0 = 1, kDlc = 4, kCrcField = 15;
constexpr int kCrcDelimiter = 1, kAckSlot = 1, kAckDelimiter = 1, kEof = 7, kInterframe = 3;

/// Bits from SOF to the end of the CRC sequence are subject to stuffing: after 5 equal bits a
/// complementary one is inserted, and a stuff bit counts in the next run, so the worst case is
/// one stuff bit per 4 bits after the first: floor((n - 1) / 4).
constexpr int worst_case_frame_bits(int data_bytes) {
  const int stuffed_region =
      kSof + kIdentifier + kRtr + kIde + kR0 + kDlc + 8 * data_bytes + kCrcField;
  const int fixed_tail = kCrcDelimiter + kAckSlot + kAckDelimiter + kEof + kInterframe;
  return stuffed_region + (stuffed_region - 1) / 4 + fixed_tail;
}

// Published figures (the note on bus budgets): 8-byte 11-bit frames at 500 kbit/s, 4505 frames/s
// nominal, 3704 worst case, i.e. 111 and 135 bits.
static_assert(worst_case_frame_bits(8) == 135);
constexpr double kMaxLoad = 0.30;  // the interface's bus-load requirement

TEST(BusBudget, DefaultDividersStayBelowThirtyPercentWorstCase) {
  double bits_per_s = 0.0;
  for (const MessageDef& m : kMessages) {
    if (m.kind != MessageKind::kData || m.default_divider == 0) continue;
    const double frames_per_s = kDefaultSampleRateHz / m.default_divider;
    bits_per_s += frames_per_s * worst_case_frame_bits(kFrameLength);
  }
  const double load = bits_per_s / kDefaultBitRate;
  EXPECT_LT(load, kMaxLoad) << "worst-case load " << load;
  // The figure docs/can-interface.md states: 8 frames at 100 Hz, 2 at 50 Hz, 3 at 1 Hz (health and
  // command counters), accuracy at 5 Hz, aiding counters at 2.5 Hz = 910.5 frames/s x 135 bits =
  // 24.58 %; a table change that moves it must update the doc too.
  constexpr double kDocumentedLoad = 910.5 * 135.0 / 500000.0;
  EXPECT_DOUBLE_EQ(load, kDocumentedLoad);
}

TEST(BusBudget, EverySensorFrameOnAt100HzStillFits) {
  // Switching on the optional sensor outputs at the epoch rate must still fit the requirement
  // (the ICD says so).
  double bits_per_s = 0.0;
  for (const MessageDef& m : kMessages) {
    if (m.kind != MessageKind::kData) continue;
    const int d = m.default_divider == 0 ? 10 : m.default_divider;
    bits_per_s += kDefaultSampleRateHz / d * worst_case_frame_bits(kFrameLength);
  }
  EXPECT_LT(bits_per_s / kDefaultBitRate, kMaxLoad);
}

}  // namespace
}  // namespace gfins::can
