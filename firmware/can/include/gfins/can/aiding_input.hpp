// Aiding input frames (GNSS receiver / external heading -> board), MessageKind::kInput of
// message_table.hpp: the host or a gateway encodes them, the firmware decodes them into a GnssFix
// or HeadingFix for the filter. Same end-to-end protection as every gfins frame: CRC-8/SAE-J1850
// over the identifier and bytes 0..6 in byte 7, and a 4-bit counter in bits 52..55 — here the fix
// sequence id, equal in every frame of one fix. No heap, no exceptions.
//
// A GNSS fix is four frames sent in this order: GfinsGnssPositionNE, GfinsGnssPositionD,
// GfinsGnssVelocity, GfinsGnssFixInfo. FixInfo completes the fix and says what it holds
// (position, velocity or both); the frames its content needs must have arrived before it with
// the same fix id. A fix whose id equals the last accepted fix's is a repeat (stale) and is
// rejected, as is every frame with a bad CRC or length, a value out of its range or sent as not
// available, a reserved bit set, or frames of one fix with different ids.
#pragma once

#include <array>
#include <cstdint>

#include "gfins/can/message_table.hpp"
#include "gfins/hal/can_bus.hpp"
#include "gfins/status/status.hpp"

namespace gfins::can {

/// One GNSS fix as the receiver states it, in the board's navigation frame.
struct GnssFix {
  std::uint8_t fix_id = 0;  // 0..15, advances by one per fix
  bool has_position = false;
  bool has_velocity = false;
  std::array<double, 3> r_n_m{};    // antenna position, NED, m, from the navigation origin
  std::array<double, 3> v_n_mps{};  // antenna velocity, NED, m/s
  double sigma_pos_h_m = 0.0;       // receiver's 1σ, horizontal (per axis N and E), m
  double sigma_pos_v_m = 0.0;       // 1σ, down, m
  double sigma_vel_mps = 0.0;       // 1σ per velocity axis, m/s
  double age_s = 0.0;  // age of the fix when its FixInfo frame was sent: time of validity =
                       // reception time of FixInfo - age_s
};

/// An external heading (dual-antenna GNSS, magnetometer, a surveyed direction).
struct HeadingFix {
  std::uint8_t sequence = 0;  // 0..15, advances by one per heading
  double heading_rad = 0.0;   // yaw of q_nb in [-π, π]
  double sigma_rad = 0.0;     // 1σ
  double age_s = 0.0;         // age at transmission (time of validity = reception - age_s)
};

/// Why a frame was rejected (one count each in InputCounters).
enum class InputReject : std::uint8_t {
  kNone,
  kBadLength,   // not 8 data bytes
  kBadCrc,      // CRC-8 mismatch: corrupted, or sent to another node's identifier
  kStale,       // the fix id / sequence of the last accepted fix or heading again
  kOutOfRange,  // a value beyond its signal's range, or sent as not available
  kMalformed,   // a reserved bit set, or a FixInfo that states no content
  kMixedFix,    // frames of one fix with different fix ids
  kIncomplete,  // FixInfo without the frames its content needs
  kCount_,
};
const char* to_string(InputReject r);

struct InputCounters {
  std::uint32_t gnss_fixes = 0;  // complete fixes delivered
  std::uint32_t headings = 0;    // headings delivered
  std::array<std::uint32_t, static_cast<std::size_t>(InputReject::kCount_)> rejected{};
  std::uint32_t total_rejected() const;
};

enum class InputEventKind : std::uint8_t {
  kIgnored,     // not an input frame of this node (other identifier, 29-bit): nothing to do
  kPending,     // a frame of a GNSS fix, stored until its FixInfo arrives
  kGnssFix,     // `gnss` holds a complete fix
  kHeadingFix,  // `heading` holds a heading
};

struct InputEvent {
  InputEventKind kind = InputEventKind::kIgnored;
  GnssFix gnss;
  HeadingFix heading;
};

/// True for a frame of an aiding input message (GNSS, heading) addressed to `node_id` with the
/// identifier groups `ids`: the frames InputDecoder takes; every other frame it ignores.
bool is_input_frame(const hal::CanFrame& f, std::uint8_t node_id, const IdBases& ids = {});

/// Decodes the input frames addressed to one node. A rejected frame comes back as an error
/// Status (kDataLoss: length or CRC; kOutOfRange: a value; kInvalidArgument: reserved bits or no
/// content; kFailedPrecondition: stale id, mixed ids, incomplete fix), counted by reason; the
/// partial fix it belonged to is dropped.
class InputDecoder {
 public:
  explicit InputDecoder(std::uint8_t node_id, const IdBases& ids = {})
      : node_id_(node_id), ids_(ids) {}

  [[nodiscard]] Result<InputEvent> add(const hal::CanFrame& f);

  const InputCounters& counters() const { return counters_; }
  /// Reason of the latest rejection (kNone when the latest frame was accepted).
  InputReject last_reject() const { return last_reject_; }

 private:
  Result<InputEvent> reject(InputReject why, ErrorCode code, const char* what);
  Result<InputEvent> add_gnss(const MessageDef& m, std::uint64_t p, std::uint8_t id);
  Result<InputEvent> add_heading(std::uint64_t p, std::uint8_t seq);

  std::uint8_t node_id_;
  IdBases ids_{};
  InputCounters counters_{};
  InputReject last_reject_ = InputReject::kNone;
  // The fix being assembled.
  GnssFix partial_{};
  bool partial_open_ = false;
  bool have_ne_ = false;
  bool have_d_ = false;
  bool have_vel_ = false;
  // Last accepted ids (-1: none yet).
  std::int16_t last_fix_id_ = -1;
  std::int16_t last_heading_seq_ = -1;
};

/// Host side: the four frames of a fix, in sending order (PositionNE, PositionD, Velocity,
/// FixInfo), CRC sealed. Parts the fix does not have are sent as not available. Values beyond a
/// signal's range saturate (σ rounds up: never smaller than stated).
std::array<hal::CanFrame, 4> encode_gnss_fix(const GnssFix& fix, std::uint8_t node_id,
                                             const IdBases& ids = {});
hal::CanFrame encode_heading_fix(const HeadingFix& h, std::uint8_t node_id,
                                 const IdBases& ids = {});

}  // namespace gfins::can
