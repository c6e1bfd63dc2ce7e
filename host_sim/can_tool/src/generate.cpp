#include "generate.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <sstream>

#include "gfins/can/message_table.hpp"
#include "gfins/can/publisher.hpp"

namespace gfins::can_tool {
namespace {

using can::MessageDef;
using can::SignalDef;

constexpr const char* kNotAvailableName = "NotAvailable";

/// Shortest decimal text that reads back to the same double (DBC tools parse it exactly).
std::string num(double v) {
  char buf[400];
  // Fixed notation (no exponent: some DBC readers do not accept one), shortest round trip.
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed);
  return std::string(buf, r.ptr);
}

std::string mux_tag(const SignalDef& s) {
  if (s.mux == can::kMultiplexor) return " M";
  if (s.mux >= 0) return " m" + std::to_string(s.mux);
  return "";
}

std::string receiver(const MessageDef& m) {
  return m.kind == can::MessageKind::kCommand || m.kind == can::MessageKind::kInput ? "GFINS"
                                                                                    : "HOST";
}

std::string signal_comment(const SignalDef& s) {
  std::string c(s.comment);
  if (!s.unit.empty()) c += ". Unit: " + std::string(s.unit);
  c += ". Instant: " + std::string(s.instant);
  if (s.has_na) c += ". Not available: raw " + std::to_string(s.na_raw);
  if (s.overflow == can::Overflow::kWrap) {
    c += ". Wraps modulo 2^" + std::to_string(s.length);
  } else if (s.field != can::Field::kCrc && s.mux == can::kNotMultiplexed && s.values.empty()) {
    c += ". Saturates at [min|max]";
  }
  return c + ".";
}

std::string type_of(const SignalDef& s) {
  return std::string(s.is_signed ? "int" : "uint") + std::to_string(s.length);
}

}  // namespace

std::string generate_dbc(std::uint8_t node_id, const DbcRates& rates, const can::IdBases& ids) {
  // A message's identifier: its group's first one (configurable, can.*_id_base) + its offset in
  // the group + the node id.
  const auto id_of = [&](const MessageDef& m) { return can::can_id(m.id, node_id, ids); };
  std::ostringstream o;
  o << "VERSION \"gfins CAN interface, generated from firmware/can message_table.hpp, node "
    << int{node_id} << "\"\n\n\n";
  o << "NS_ :\n\tNS_DESC_\n\tCM_\n\tBA_DEF_\n\tBA_\n\tVAL_\n\tBA_DEF_DEF_\n\tSIG_VALTYPE_\n\n";
  o << "BS_:\n\n";
  o << "BU_: GFINS HOST GNSS\n\n\n";
  for (const MessageDef& m : can::kMessages) {
    const std::uint32_t id = id_of(m);
    o << "BO_ " << id << " " << m.name << ": " << int{can::kFrameLength} << " " << m.sender << "\n";
    for (const SignalDef& s : m.signals) {
      o << " SG_ " << s.name << mux_tag(s) << " : " << int{s.start_bit} << "|" << int{s.length}
        << "@1" << (s.is_signed ? "-" : "+") << " (" << num(s.factor) << "," << num(s.offset)
        << ") [" << num(s.min) << "|" << num(s.max) << "] \"" << s.unit << "\" " << receiver(m)
        << "\n";
    }
    o << "\n";
  }
  o << "\n";
  o << "CM_ BU_ GFINS \"Gyro-free INS board (six accelerometers)\";\n";
  o << "CM_ BU_ HOST \"Receiver of navigation frames, sender of commands\";\n";
  o << "CM_ BU_ GNSS \"GNSS receiver or aiding gateway: sender of the aiding input frames\";\n";
  for (const MessageDef& m : can::kMessages) {
    const std::uint32_t id = id_of(m);
    o << "CM_ BO_ " << id << " \"" << m.comment << ". Identifier 0x" << std::hex << id - node_id
      << std::dec << " + node id\";\n";
    for (const SignalDef& s : m.signals) {
      o << "CM_ SG_ " << id << " " << s.name << " \"" << signal_comment(s) << "\";\n";
    }
  }
  // Attributes (Vector's conventions): the bus type, each message's send type (data messages
  // cyclic at their divider, commands, responses and aiding inputs on event, a data message
  // switched off by its divider not sent) and the cycle time of the cyclic ones.
  o << "BA_DEF_ \"BusType\" STRING ;\n";
  o << "BA_DEF_ BO_ \"GenMsgSendType\" ENUM \"Cyclic\",\"Event\",\"NoMsgSendType\";\n";
  o << "BA_DEF_ BO_ \"GenMsgCycleTime\" INT 0 65535;\n";
  o << "BA_DEF_DEF_ \"BusType\" \"CAN\";\n";
  o << "BA_DEF_DEF_ \"GenMsgSendType\" \"NoMsgSendType\";\n";
  o << "BA_DEF_DEF_ \"GenMsgCycleTime\" 0;\n";
  o << "BA_ \"BusType\" \"CAN\";\n";
  constexpr int kCyclic = 0;
  constexpr int kEvent = 1;
  constexpr int kNotSent = 2;
  for (const MessageDef& m : can::kMessages) {
    const std::uint16_t divider = rates.dividers[static_cast<std::size_t>(m.id)];
    const int send = m.kind != can::MessageKind::kData ? kEvent : divider == 0 ? kNotSent : kCyclic;
    o << "BA_ \"GenMsgSendType\" BO_ " << id_of(m) << " " << send << ";\n";
  }
  for (const MessageDef& m : can::kMessages) {
    const std::uint16_t divider = rates.dividers[static_cast<std::size_t>(m.id)];
    if (m.kind != can::MessageKind::kData || divider == 0) continue;
    const double ms = 1000.0 * divider / rates.sample_rate_hz;
    o << "BA_ \"GenMsgCycleTime\" BO_ " << id_of(m) << " " << std::max<long>(1, std::lround(ms))
      << ";\n";
  }
  // Value descriptions: the enumerations, and the not-available raw code of every signal that has
  // one, so a DBC tool shows "NotAvailable" instead of a reading (Qw -1.00024).
  for (const MessageDef& m : can::kMessages) {
    for (const SignalDef& s : m.signals) {
      if (s.values.empty() && !s.has_na) continue;
      o << "VAL_ " << id_of(m) << " " << s.name;
      for (const can::ValueName& v : s.values) o << " " << v.raw << " \"" << v.name << "\"";
      if (s.has_na) o << " " << s.na_raw << " \"" << kNotAvailableName << "\"";
      o << " ;\n";
    }
  }
  return o.str();
}

std::string generate_signal_tables() {
  std::ostringstream o;
  for (const MessageDef& m : can::kMessages) {
    o << "#### " << m.name << " — 0x" << std::hex << std::uppercase << m.base_id << std::dec
      << " + node\n\n";
    o << m.comment << ". Default divider: ";
    if (m.kind == can::MessageKind::kInput) {
      o << "sent by the GNSS receiver or gateway, one fix at a time (not a board output)";
    } else if (m.kind != can::MessageKind::kData) {
      o << "on demand";
    } else if (m.default_divider == 0) {
      o << "off";
    } else {
      o << m.default_divider << " (" << num(can::kDefaultSampleRateHz / m.default_divider)
        << " Hz at 1 kHz)";
    }
    o << ".\n\n";
    o << "| signal | mux | bits | type | factor | offset | unit | range | N/A | on overflow | "
         "instant |\n";
    o << "|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const SignalDef& s : m.signals) {
      std::string mux = "";
      if (s.mux == can::kMultiplexor) mux = "selector";
      if (s.mux >= 0) mux = "= " + std::to_string(s.mux);
      std::string over = s.overflow == can::Overflow::kWrap ? "wraps" : "saturates";
      if (s.field == can::Field::kCrc) over = "—";
      o << "| " << s.name << " | " << mux << " | " << int{s.start_bit} << "–"
        << s.start_bit + s.length - 1 << " | " << type_of(s) << " | " << num(s.factor) << " | "
        << num(s.offset) << " | " << (s.unit.empty() ? "—" : std::string(s.unit)) << " | "
        << num(s.min) << " … " << num(s.max) << " | "
        << (s.has_na ? std::to_string(s.na_raw) : std::string("—")) << " | " << over << " | "
        << s.instant << " |\n";
    }
    bool any_enum = false;
    for (const SignalDef& s : m.signals) {
      if (s.values.empty()) continue;
      if (!any_enum) o << "\n";
      any_enum = true;
      o << "- " << s.name << ":";
      for (const can::ValueName& v : s.values) o << " " << v.raw << " = " << v.name << ";";
      o << "\n";
    }
    o << "\n";
  }
  return o.str();
}

std::string generate_budget_table(double sample_rate_hz, std::uint32_t bit_rate) {
  std::ostringstream o;
  const int bits = can::worst_case_frame_bits(can::kFrameLength);
  o << "| message | divider | frames/s | worst-case bits/s | share of " << bit_rate / 1000
    << " kbit/s |\n|---|---|---|---|---|\n";
  double total_frames = 0;
  double total_bits = 0;
  for (const MessageDef& m : can::kMessages) {
    if (m.kind != can::MessageKind::kData) continue;
    const double fps = m.default_divider == 0 ? 0.0 : sample_rate_hz / m.default_divider;
    total_frames += fps;
    total_bits += fps * bits;
    char share[32];
    std::snprintf(share, sizeof share, "%.2f %%", 100.0 * fps * bits / bit_rate);
    o << "| " << m.name << " | "
      << (m.default_divider == 0 ? std::string("off") : std::to_string(m.default_divider)) << " | "
      << num(fps) << " | " << num(fps * bits) << " | " << share << " |\n";
  }
  char share[32];
  std::snprintf(share, sizeof share, "%.2f %%", 100.0 * total_bits / bit_rate);
  o << "| **total** | | " << num(total_frames) << " | " << num(total_bits) << " | **" << share
    << "** |\n";
  return o.str();
}

}  // namespace gfins::can_tool

#include <cmath>

#include "gfins/can/publisher.hpp"
#include "gfins/drivers/lnx/candump.hpp"

namespace gfins::can_tool {
namespace {

/// hal::CanBus writing each frame as a candump line at the current sample's time.
class LogBus final : public hal::CanBus {
 public:
  explicit LogBus(std::FILE* out) : out_(out) {}
  std::int64_t t_us = 0;
  bool ok = true;

 private:
  Status do_send(const hal::CanFrame& f) override {
    char line[drivers::lnx::kMaxCandumpLine + 1];
    const std::size_t n = drivers::lnx::format_candump_line(
        std::span<char>(line, drivers::lnx::kMaxCandumpLine), t_us / 1000000,
        static_cast<std::uint32_t>(t_us % 1000000), "can0", f);
    line[n] = '\n';
    if (n == 0 || std::fwrite(line, 1, n + 1, out_) != n + 1) ok = false;
    return Status::ok();
  }
  Result<hal::CanFrame> do_receive(std::int64_t) override {
    return Status(ErrorCode::kTimeout, "log bus: write only");
  }
  hal::CanBusState do_state() const override { return hal::CanBusState::kErrorActive; }
  hal::CanCounters do_counters() const override { return {}; }
  std::FILE* out_;
};

}  // namespace

bool write_synthetic_log(std::FILE* out, double seconds, double sample_rate_hz,
                         std::uint8_t node_id) {
  LogBus bus(out);
  can::PublisherConfig cfg;
  cfg.node_id = node_id;
  can::Publisher pub(bus, cfg);
  const auto n = static_cast<std::uint64_t>(seconds * sample_rate_hz);
  constexpr std::int64_t kLogStartUs = drivers::lnx::kSimulatedLogEpochS * 1000000;
  can::Epoch e;
  e.mode = can::Mode::kNavigating;
  e.cal_id = 0x00C0FFEE;
  for (std::uint64_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / sample_rate_hz;
    e.nav.seq = static_cast<std::uint32_t>(i);
    e.nav.t_ns = static_cast<std::int64_t>(std::llround(t * 1e9)) + 5'000'000'000;
    e.nav.status = 0x9;  // aligned, compensated
    const double roll = 0.2 * std::sin(0.3 * t);
    const double pitch = 0.1 * std::sin(0.5 * t);
    const double yaw = 2.5 * std::sin(0.05 * t);
    const Eigen::Quaterniond q = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                                 Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                                 Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX());
    e.nav.q_nb = q.cast<float>();
    e.nav.w_b = nav::Vec3<double>(0.06 * std::cos(0.3 * t), 0.05 * std::cos(0.5 * t),
                                  0.125 * std::cos(0.05 * t))
                    .cast<float>();
    e.nav.wdot_b = nav::Vec3<double>(-0.018 * std::sin(0.3 * t), -0.025 * std::sin(0.5 * t),
                                     -0.00625 * std::sin(0.05 * t))
                       .cast<float>();
    e.nav.f_b =
        nav::Vec3<double>(0.5 * std::sin(0.1 * t), 0.3 * std::cos(0.1 * t), -9.81).cast<float>();
    e.nav.v_n = nav::Vec3<double>(10.0 * std::cos(0.01 * t), 10.0 * std::sin(0.01 * t),
                                  0.2 * std::sin(0.2 * t))
                    .cast<float>();
    e.nav.r_n = nav::Vec3<double>(1000.0 * std::sin(0.01 * t), 1000.0 * (1 - std::cos(0.01 * t)),
                                  -1.0 * (1 - std::cos(0.2 * t)))
                    .cast<float>();
    for (std::size_t k = 0; k < 6; ++k) {
      e.accel_mps2[k] = static_cast<float>(9.81 * std::sin(0.1 * t + static_cast<double>(k)));
    }
    e.health.adc_crc_errors = static_cast<std::uint32_t>(i / 100000);
    // A filter with GNSS and standstill aiding: σ that grow and shrink, counts that grow; no ZARU
    // update yet (its time since is not available), and a heading σ beyond its range at times
    // (sent as the maximum).
    can::Accuracy& a = e.accuracy;
    a.sigma_roll_rad = static_cast<float>(0.002 + 0.001 * std::sin(0.2 * t));
    a.sigma_pitch_rad = static_cast<float>(0.0025 + 0.001 * std::cos(0.2 * t));
    a.sigma_heading_rad = static_cast<float>(1.2 + 1.0 * std::sin(0.1 * t));
    a.sigma_vel_h_mps = static_cast<float>(0.05 + 0.02 * std::sin(0.3 * t));
    a.sigma_vel_v_mps = static_cast<float>(0.08 + 0.02 * std::cos(0.3 * t));
    a.sigma_pos_h_m = static_cast<float>(1.5 + 0.5 * std::sin(0.05 * t));
    a.sigma_pos_v_m = static_cast<float>(2.5 + 0.5 * std::cos(0.05 * t));
    a.filter_mode =
        std::fmod(t, 20.0) < 5.0 ? can::filter_mode::kStandstill : can::filter_mode::kGnss;
    for (std::size_t k = 0; k < can::kAidKindCount; ++k) {
      a.aiding[k].accepted = static_cast<std::uint32_t>(i / (100 * (k + 1)));
      a.aiding[k].rejected = static_cast<std::uint32_t>(i / (10000 * (k + 1)));
      a.aiding[k].since_accepted_s = static_cast<float>(std::fmod(t, 1.0 + static_cast<double>(k)));
    }
    a.aiding[1].since_accepted_s = can::kNoValue;
    bus.t_us = kLogStartUs + static_cast<std::int64_t>(std::llround(t * 1e6));
    pub.publish(e);
    if (!bus.ok) return false;
  }
  return true;
}

}  // namespace gfins::can_tool
