// The hardware-in-the-loop replay board (docs/hil.md): samples from the host over the replay
// link in place of the ADC, the CAN frames back on the same connection.
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

#include <spdlog/spdlog.h>

#include "boards.hpp"
#include "gfins/app/board.hpp"
#include "gfins/app/sample_clock.hpp"
#include "gfins/app/startup.hpp"
#include "gfins/drivers/ads131m06.hpp"
#include "gfins/drivers/lnx/error_text.hpp"
#include "gfins/drivers/lnx/file_parameter_store.hpp"
#include "gfins/drivers/lnx/hil_link.hpp"
#include "gfins/drivers/qa1100_front_end.hpp"

namespace gfins::app {
namespace lnx = drivers::lnx;
namespace {

constexpr std::int64_t kIdleWaitNs = 1000000000;

/// Samples from the host over the replay link, in place of the ADC. The loop's clock follows the
/// samples' edge times (driven by the sample index, never by the wall clock).
class HilSource final : public SampleSource {
 public:
  HilSource(lnx::HilServer& server, SampleClock& clock, double volts_per_count,
            double sample_rate_hz)
      : server_(server),
        clock_(clock),
        volts_per_count_(volts_per_count),
        period_ns_(static_cast<std::int64_t>(std::llround(1e9 / sample_rate_hz))) {}

 private:
  Result<RawSample> do_read_sample(std::int64_t timeout_ns) override {
    // Without a host there are no data-ready edges at all: wait a second per loop cycle instead
    // of a few sample periods, so the loop (and its log) ticks at 1 Hz until a host connects.
    const std::int64_t wait = server_.connected() ? timeout_ns : std::max(timeout_ns, kIdleWaitNs);
    Result<RawSample> r = server_.read_sample(wait);
    if (!r.is_ok()) return r;
    RawSample s = r.value();
    // A new connection is a new stream whose counter and time start again; the loop keeps its
    // state and counters, so it sees the new stream continue the old one one period later
    // (no false missed edges, no time going back). Its navigation is not reset (docs/hil.md).
    const std::uint32_t conn = server_.counters().connections;
    if (conn != connection_) {
      if (delivered_) {
        seq_offset_ = last_seq_ + 1u - s.seq;
        t_offset_ = last_t_ns_ + period_ns_ - s.t_ns;
      }
      connection_ = conn;
    }
    s.seq += seq_offset_;
    s.t_ns += t_offset_;
    last_seq_ = s.seq;
    last_t_ns_ = s.t_ns;
    delivered_ = true;
    clock_.set(s.t_ns);
    return s;
  }
  AdcCounters do_counters() const override {
    // A replay frame with a bad CRC is the link's version of an ADC frame CRC error; a dropped
    // connection shows as a read error of the loop (health: adc read errors).
    const lnx::HilCounters& h = server_.counters();
    return AdcCounters{h.crc_errors, 0, 0, 0};
  }
  double do_volts_per_count() const override { return volts_per_count_; }

  lnx::HilServer& server_;
  SampleClock& clock_;
  double volts_per_count_;
  std::int64_t period_ns_;
  std::uint32_t connection_ = 0;
  bool delivered_ = false;
  std::uint32_t last_seq_ = 0;
  std::int64_t last_t_ns_ = 0;
  std::uint32_t seq_offset_ = 0;
  std::int64_t t_offset_ = 0;
};

struct HilParts {
  std::unique_ptr<lnx::HilServer> server;
};

/// The QA-1100 front end's LSB at the sensor (the Linux board's): the replayed codes are that
/// chain's, so the nominal calibration is the same as on the board.
double hil_volts_per_count(const FwConfig& c, std::string& error) {
  drivers::Ads131m06Config adc_cfg;
  adc_cfg.sample_rate_hz = c.sample_rate_hz;
  const auto fe = drivers::Qa1100FrontEnd::create(drivers::Qa1100FrontEnd::Channels{}, adc_cfg);
  if (!fe.is_ok()) {
    error = std::string("QA-1100 front end: ") + fe.status().message();
    return 0.0;
  }
  return fe.value().volts_per_count(0);
}

}  // namespace

BoardResult make_hil_board(const FwConfig& c) {
  BoardResult out;
  const double lsb = hil_volts_per_count(c, out.error);
  if (!out.error.empty()) return out;
  lnx::HilServerConfig hc;
  hc.address = c.hil_address;
  hc.port = static_cast<std::uint16_t>(c.hil_port);
  auto server = lnx::HilServer::open(hc);
  if (!server.is_ok()) {
    out.error = lnx::describe("hil link on " + c.hil_address + ":" + std::to_string(c.hil_port),
                              server.status());
    return out;
  }
  auto parts = std::make_shared<HilParts>();
  parts->server = std::move(server).value();
  lnx::HilServer* srv = parts->server.get();
  if (!c.hil_port_file.empty()) {
    // Written whole under a temporary name, then renamed: a reader never sees half a number;
    // a device node or FIFO at the path is refused, not replaced.
    const std::string text = std::to_string(srv->port()) + "\n";
    const Status saved = lnx::save_file_atomically(c.hil_port_file, {text.data(), text.size()});
    if (!saved.is_ok()) {
      out.error = lnx::describe("hil.port_file = \"" + c.hil_port_file + "\"", saved);
      return out;
    }
  }
  spdlog::info("hil: waiting for gfins-can hil on {}:{}", c.hil_address, srv->port());
  auto b = std::make_unique<Board>();
  auto clock = std::make_unique<SampleClock>();
  b->source = std::make_unique<HilSource>(*srv, *clock, lsb, c.sample_rate_hz);
  b->clock = std::move(clock);
  b->finished = [srv] { return srv->finished(); };
  // The frames go back to the host on the replay connection (a hal::CanBus of the link); the
  // Board owns buses, so hand it a forwarding one.
  class LinkBus final : public hal::CanBus {
   public:
    explicit LinkBus(hal::CanBus& b) : b_(b) {}

   private:
    Status do_send(const hal::CanFrame& f) override { return b_.send(f); }
    Result<hal::CanFrame> do_receive(std::int64_t t) override { return b_.receive(t); }
    hal::CanBusState do_state() const override { return b_.state(); }
    hal::CanCounters do_counters() const override { return b_.counters(); }
    hal::CanBus& b_;
  };
  b->bus = std::make_unique<LinkBus>(srv->bus());
  add_can_protocol(c, *b);
  b->defaults = nominal_calibration(lsb);
  b->close = [srv] {
    const lnx::HilCounters& h = srv->counters();
    spdlog::info(
        "hil: {} connection(s), {} dropped, {} samples, {} CRC errors, {} bad frames, {} CAN "
        "frames sent, {} not sent, {} received from the host, {} lost{}",
        h.connections, h.drops, h.samples, h.crc_errors, h.frame_errors, h.can_sent, h.can_dropped,
        h.can_in, h.can_in_lost,
        srv->last_event()[0] == '\0' ? std::string()
                                     : std::string("; last event: ") + srv->last_event());
  };
  b->keep_alive = parts;
  out.board = std::move(b);
  return out;
}

}  // namespace gfins::app
