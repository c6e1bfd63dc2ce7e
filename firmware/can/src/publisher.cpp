#include "gfins/can/publisher.hpp"

#include <cmath>
#include <limits>

#include "gfins/can/signal_codec.hpp"

namespace gfins::can {
namespace {

constexpr std::size_t idx(MessageId m) { return static_cast<std::size_t>(m); }

/// ZYX Euler angles (roll, pitch, yaw) of q_nb, rad: the usual aerospace sequence for a
/// body-to-NED rotation (yaw about z_n, then pitch, then roll). Pitch clamps the asin argument
/// against rounding just beyond ±1.
double euler_angle(const nav::Quat<float>& qf, std::uint8_t axis) {
  const auto w = static_cast<double>(qf.w());
  const auto x = static_cast<double>(qf.x());
  const auto y = static_cast<double>(qf.y());
  const auto z = static_cast<double>(qf.z());
  switch (axis) {
    case 0:
      return std::atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y));
    case 1:
      return std::asin(std::clamp(2.0 * (w * y - z * x), -1.0, 1.0));
    default:
      return std::atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z));
  }
}

double vec(const nav::Vec3<float>& v, std::uint8_t i) { return static_cast<double>(v[i]); }

/// False when `field` belongs to a navigation group the epoch marks invalid.
bool group_valid(const Validity& v, Field field) {
  switch (field) {
    case Field::kQuaternion:
    case Field::kEuler:
      return v.attitude;
    case Field::kRate:
      return v.rate;
    case Field::kAngularAccel:
      return v.angular_accel;
    case Field::kAccel:
      return v.accel;
    case Field::kVelocity:
      return v.velocity;
    case Field::kPosition:
      return v.position;
    default:
      return true;
  }
}

constexpr double kNotAvailable = std::numeric_limits<double>::quiet_NaN();

/// Whether a clipped or not-available value of `field` flags the epoch (StatusFlags bits 4, 5):
/// the navigation values and sensor outputs do. A σ does not: without a filter it is not
/// available by design, and one beyond its range is sent as the maximum, which reads "at least".
bool flags_epoch(Field field) {
  switch (field) {
    case Field::kSigmaAttitude:
    case Field::kSigmaVelocity:
    case Field::kSigmaPosition:
    case Field::kAidSinceAccepted:
      return false;
    default:
      return true;
  }
}

}  // namespace

Status check_dividers(const Dividers& d) {
  const std::uint16_t epoch = d[idx(MessageId::kEpoch)];
  // The epoch and status frames say that the board is alive and how it is: never off (a SetDivider
  // of 0 for the epoch would leave a silent board on the bus).
  if (epoch == 0) {
    return Status(ErrorCode::kOutOfRange, "can: the Epoch divider cannot be 0 (never off)");
  }
  if (d[idx(MessageId::kStatus)] != epoch) {
    return Status(ErrorCode::kInvalidArgument, "can: the Status divider must equal the Epoch's");
  }
  for (const MessageDef& m : kMessages) {
    const std::uint16_t v = d[idx(m.id)];
    if (m.kind != MessageKind::kData) {
      if (v != 0) return Status(ErrorCode::kInvalidArgument, "can: commands are not periodic");
      continue;
    }
    if (v == 0) continue;
    if (v > kMaxDivider) {
      return Status(ErrorCode::kOutOfRange, "can: a divider must be at most 10000 (kMaxDivider)");
    }
    if (epoch == 0 || v % epoch != 0) {
      return Status(ErrorCode::kInvalidArgument,
                    "can: a divider must be a multiple of the Epoch divider");
    }
  }
  return Status::ok();
}

double worst_case_bits_per_s(const Dividers& d, double sample_rate_hz) {
  double bits = 0.0;
  for (const MessageDef& m : kMessages) {
    const std::uint16_t v = d[idx(m.id)];
    if (m.kind != MessageKind::kData || v == 0) continue;
    bits += sample_rate_hz / v * worst_case_frame_bits(kFrameLength);
  }
  return bits;
}

namespace {

Status check_budget(const Dividers& d, const BusBudget& b) {
  if (!(b.load(d) <= b.max_load)) {
    return Status(ErrorCode::kResourceExhausted,
                  "can: the worst-case bus load of these dividers exceeds the budget");
  }
  return Status::ok();
}

}  // namespace

Status check_config(const PublisherConfig& c) {
  if (c.node_id > kMaxNodeId) return Status(ErrorCode::kInvalidArgument, "can: node id > 15");
  if (!id_bases_valid(c.ids)) {
    return Status(ErrorCode::kInvalidArgument,
                  "can: the identifier groups overlap or leave the 11-bit range");
  }
  if (const Status s = check_dividers(c.dividers); !s.is_ok()) return s;
  return check_budget(c.dividers, c.budget);
}

double epoch_field(const Epoch& e, Field field, std::uint8_t index) {
  const nav::NavState<float>& n = e.nav;
  // An invalid group is "not available" (the signal's N/A code), whatever the state holds.
  if (!group_valid(e.valid, field)) return kNotAvailable;
  switch (field) {
    case Field::kTimeUs:
      // Floor division keeps the µs of a negative scenario time consistent with its ns.
      return static_cast<double>(n.t_ns >= 0 ? n.t_ns / 1000 : -((-n.t_ns + 999) / 1000));
    case Field::kSampleCount:
      return static_cast<double>(n.seq);
    case Field::kMode:
      return static_cast<double>(e.mode);
    case Field::kStatusFlags:
      return static_cast<double>((e.status_bits | (n.status & status_bits::kNavStatusMask)) &
                                 status_bits::kAllBits);
    case Field::kCalId:
      return static_cast<double>(e.cal_id);
    case Field::kQuaternion: {
      // q and -q are the same rotation; the bus carries the one with w >= 0.
      const double sign = n.q_nb.w() < 0.0f ? -1.0 : 1.0;
      const double c[4] = {static_cast<double>(n.q_nb.w()), static_cast<double>(n.q_nb.x()),
                           static_cast<double>(n.q_nb.y()), static_cast<double>(n.q_nb.z())};
      return sign * c[index & 3u];
    }
    case Field::kEuler:
      return euler_angle(n.q_nb, index);
    case Field::kRate:
      return vec(n.w_b, index);
    case Field::kAngularAccel:
      return vec(n.wdot_b, index);
    case Field::kAccel:
      return vec(n.f_b, index);
    case Field::kVelocity:
      return vec(n.v_n, index);
    case Field::kPosition:
      return vec(n.r_n, index);
    case Field::kSensorAccel:
      return static_cast<double>(e.accel_mps2[index % 6u]);
    case Field::kMissedEdges:
      return e.health.missed_drdy_edges;
    case Field::kAdcCrcErrors:
      return e.health.adc_crc_errors;
    case Field::kAdcResets:
      return e.health.adc_resets;
    case Field::kStuckMask:
      return e.health.stuck_channel_mask & 0x3Fu;
    case Field::kSaturatedSamples:
      return e.health.saturated_samples;
    case Field::kCanTxDropped:
      return e.health.can_tx_dropped;
    case Field::kBusOffEvents:
      return e.health.bus_off_events;
    case Field::kLoopOverruns:
      return e.health.loop_overruns;
    case Field::kLogDropped:
      return e.health.log_dropped;
    case Field::kSigmaAttitude: {
      const float s[3] = {e.accuracy.sigma_roll_rad, e.accuracy.sigma_pitch_rad,
                          e.accuracy.sigma_heading_rad};
      return static_cast<double>(s[index % 3u]);
    }
    case Field::kSigmaVelocity:
      return static_cast<double>(index == 0 ? e.accuracy.sigma_vel_h_mps
                                            : e.accuracy.sigma_vel_v_mps);
    case Field::kSigmaPosition:
      return static_cast<double>(index == 0 ? e.accuracy.sigma_pos_h_m : e.accuracy.sigma_pos_v_m);
    case Field::kFilterMode:
      return e.accuracy.filter_mode & 0x0Fu;
    case Field::kAidKind:
      return index;
    case Field::kAidAccepted:
      return e.accuracy.aiding[index % kAidKindCount].accepted;
    case Field::kAidRejected:
      return e.accuracy.aiding[index % kAidKindCount].rejected;
    case Field::kAidSinceAccepted:
      return static_cast<double>(e.accuracy.aiding[index % kAidKindCount].since_accepted_s);
    case Field::kCmdAccepted:
      return e.commands.done;
    case Field::kCmdRefused:
      return e.commands.refused;
    case Field::kCmdReplayed:
      return e.commands.replayed;
    case Field::kCmdLastRefusal:
      return e.commands.last_refusal;
    case Field::kSettingsSource:
      return e.commands.settings_source;
    default:
      return 0.0;
  }
}

std::uint8_t selector_count(const MessageDef& m) {
  int n = 0;
  for (const SignalDef& s : m.signals) n = std::max(n, s.mux + 1);
  return static_cast<std::uint8_t>(n);
}

hal::CanFrame encode_data_frame(const MessageDef& m, const Epoch& e, std::uint8_t node_id,
                                std::uint8_t counter, std::uint32_t* saturated,
                                std::uint32_t* unavailable, std::uint8_t selector,
                                const IdBases& ids) {
  hal::CanFrame f;
  f.id = can_id(m.id, node_id, ids);
  f.len = kFrameLength;
  std::uint64_t p = 0;
  for (const SignalDef& s : m.signals) {
    if (s.field == Field::kCrc) continue;
    if (s.field == Field::kCounter) {
      p = insert_bits(p, s, counter);
      continue;
    }
    if (s.mux == kMultiplexor) {
      p = insert_bits(p, s, selector);
      continue;
    }
    if (s.mux >= 0 && s.mux != selector) continue;  // another selector's signal
    const EncodedSignal enc = encode_signal(s, epoch_field(e, s.field, s.index));
    p = insert_bits(p, s, enc.bits);
    if (!flags_epoch(s.field)) continue;
    if (enc.saturated && saturated != nullptr) ++*saturated;
    if (enc.not_available && unavailable != nullptr) ++*unavailable;
  }
  set_payload(f, p);
  seal_frame(f);
  return f;
}

Publisher::Publisher(hal::CanBus& bus, const PublisherConfig& c) : bus_(&bus) {
  init_status_ = check_config(c);
  if (init_status_.is_ok()) {
    node_id_ = c.node_id;
    ids_ = c.ids;
    dividers_ = c.dividers;
    budget_ = c.budget;
  } else {
    dividers_ = default_dividers();
  }
}

void Publisher::publish(const Epoch& e) {
  const std::uint16_t epoch_div = dividers_[idx(MessageId::kEpoch)];
  if (epoch_div == 0 || e.nav.seq % epoch_div != 0) return;

  // Build every frame first so the status frame (sent second) can flag a value of this epoch
  // that saturated in a later frame.
  std::array<hal::CanFrame, kMessageCount> frames{};
  std::size_t n = 2;  // slots 0 and 1: GfinsEpoch, GfinsStatus
  std::uint32_t saturated = 0;
  std::uint32_t unavailable = 0;
  for (const MessageDef& m : kMessages) {
    if (m.kind != MessageKind::kData || m.id == MessageId::kEpoch || m.id == MessageId::kStatus) {
      continue;
    }
    const std::uint16_t d = dividers_[idx(m.id)];
    if (d == 0 || e.nav.seq % d != 0) continue;
    // A multiplexed message sends its selector values in turn, one per frame.
    std::uint8_t& sel = selector_[idx(m.id)];
    frames[n++] = encode_data_frame(m, e, node_id_, counter_, &saturated, &unavailable, sel, ids_);
    const std::uint8_t count = selector_count(m);
    if (count > 0) sel = static_cast<std::uint8_t>((sel + 1u) % count);
  }
  frames[0] = encode_data_frame(message(MessageId::kEpoch), e, node_id_, counter_, &saturated,
                                &unavailable, 0, ids_);
  Epoch flagged = e;
  if (saturated != 0) flagged.status_bits |= status_bits::kCanSaturated;
  if (unavailable != 0) flagged.status_bits |= status_bits::kCanNotAvailable;
  frames[1] = encode_data_frame(message(MessageId::kStatus), flagged, node_id_, counter_,
                                &saturated, &unavailable, 0, ids_);

  for (std::size_t i = 0; i < n; ++i) {
    if (bus_->send(frames[i]).is_ok()) {
      ++counters_.frames_sent;
    } else {
      ++counters_.send_failures;
    }
  }
  counters_.saturated_values += saturated;
  counters_.unavailable_values += unavailable;
  ++counters_.epochs;
  counter_ = static_cast<std::uint8_t>((counter_ + 1u) & 0x0Fu);
}

Status Publisher::set_divider(MessageId m, std::uint16_t divider) {
  Dividers d = dividers_;
  d[idx(m)] = divider;
  // Changing the epoch divider moves the status frame with it.
  if (m == MessageId::kEpoch) d[idx(MessageId::kStatus)] = divider;
  if (m == MessageId::kStatus) {
    return Status(ErrorCode::kInvalidArgument, "can: the Status divider follows the Epoch's");
  }
  return set_dividers(d);
}

Status Publisher::set_dividers(const Dividers& d) {
  Status s = check_dividers(d);
  if (s.is_ok()) s = check_budget(d, budget_);
  if (s.is_ok()) dividers_ = d;
  return s;
}

}  // namespace gfins::can
