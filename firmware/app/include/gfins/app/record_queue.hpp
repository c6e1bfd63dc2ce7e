// The loop's side of the raw-sample recorder (recorder.hpp): a record is encoded in the loop
// (32 bytes, the codec of nav_core/recording) and pushed into a RecordQueue without waiting.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "gfins/app/spsc_ring.hpp"
#include "gfins/hal/can_bus.hpp"
#include "gfins/recording/codec.hpp"
#include "gfins/sample/raw_sample.hpp"

namespace gfins::app {

struct RecordSlot {
  std::array<std::uint8_t, recording::kRecordBytes> bytes{};
};

/// 8192 records (256 KiB): eight seconds of samples at 1 kHz while the writer thread waits on a
/// slow card.
inline constexpr std::size_t kRecordQueueCapacity = 8192;
using RecordQueue = SpscRing<RecordSlot, kRecordQueueCapacity>;

/// The sample's record into `q`; false when the queue was full or the sample does not fit a
/// record (neither happens in a healthy run; the caller counts it).
inline bool record_sample(RecordQueue& q, const RawSample& s) {
  RecordSlot slot;
  if (!recording::encode_record(s, slot.bytes).ok()) return false;
  return q.push(slot);
}

/// A received frame's record, stamped with the handling cycle's time.
inline bool record_frame(RecordQueue& q, const hal::CanFrame& f, std::int64_t t_ns) {
  recording::FrameRecord r;
  r.t_ns = t_ns;
  r.id = f.id;
  r.extended = f.extended;
  r.len = f.len;
  r.data = f.data;
  RecordSlot slot;
  if (!recording::encode_frame_record(r, slot.bytes).ok()) return false;
  return q.push(slot);
}

}  // namespace gfins::app
