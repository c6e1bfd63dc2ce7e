#include "board.hpp"

#include <filesystem>
#include <fstream>

#include <spdlog/spdlog.h>

#include "gfins/app/can_adapters.hpp"
#include "gfins/app/startup.hpp"
#include "gfins/drivers/ads131m06.hpp"
#include "gfins/drivers/lnx/candump_file_bus.hpp"
#include "gfins/drivers/lnx/dev_watchdog.hpp"
#include "gfins/drivers/lnx/error_text.hpp"
#include "gfins/drivers/lnx/gpiod_data_ready.hpp"
#include "gfins/drivers/lnx/hil_link.hpp"
#include "gfins/drivers/lnx/monotonic_clock.hpp"
#include "gfins/drivers/lnx/realtime.hpp"
#include "gfins/drivers/lnx/socket_can.hpp"
#include "gfins/drivers/lnx/spidev.hpp"
#include "gfins/drivers/lnx/systemd_watchdog.hpp"
#include "gfins/drivers/qa1100_front_end.hpp"
#include "gfins/host_sim/scenario.hpp"
#include "gfins/sim_board/sim_board.hpp"

namespace gfins::app {
namespace lnx = drivers::lnx;
namespace {

// /dev/watchdog timeout: long enough for a loaded start-up, short enough to restart a hung loop
// within a minute.
constexpr int kDevWatchdogTimeoutS = 10;

std::string enter_realtime(const FwConfig& c) {
  std::string warn;
  if (c.rt_priority > 0) {
    if (const Status s = lnx::set_fifo_priority(c.rt_priority); !s.is_ok()) {
      warn += lnx::describe("SCHED_FIFO priority " + std::to_string(c.rt_priority), s) +
              " — running at normal priority, expect more latency (grant CAP_SYS_NICE or "
              "LimitRTPRIO in the service unit). ";
    }
  }
  if (c.lock_memory) {
    if (const Status s = lnx::lock_memory(); !s.is_ok()) {
      warn += lnx::describe("mlockall", s) +
              " — memory not locked, page faults may delay the loop (grant CAP_IPC_LOCK or "
              "LimitMEMLOCK=infinity).";
    }
  }
  return warn;
}

// The CAN output: a candump log file when can.log_file is set, the SocketCAN interface otherwise.
std::string open_bus(const FwConfig& c, hal::Clock& clock, Board& b) {
  if (!c.can_log.empty()) {
    lnx::CandumpFileBusConfig bc;
    bc.path = c.can_log;
    bc.interface = c.can_interface;
    // File writes off the loop thread, except in fast pacing, whose output must be the same on
    // every run (a writer thread that falls behind drops frames: a matter of scheduling).
    bc.background_writer = !(c.board == BoardKind::kSim && c.pacing == Pacing::kFast);
    auto bus = lnx::CandumpFileBus::open(bc, clock);
    if (!bus.is_ok()) return lnx::describe(c.can_log, bus.status());
    lnx::CandumpFileBus* file = bus.value().get();
    b.bus = std::move(bus).value();
    b.finish_output = [file, path = c.can_log] {
      (void)file->flush();  // a failure is counted in write_errors() and reported below
      if (file->write_errors() == 0) return std::string();
      const hal::CanCounters k = file->counters();
      return lnx::describe("can.log_file = " + quote_text(path), file->last_error()) + "; " +
             std::to_string(k.tx_dropped) + " of " + std::to_string(k.tx_frames + k.tx_dropped) +
             " frames not written (" + std::to_string(file->write_errors()) + " failed writes)";
    };
    return "";
  }
  lnx::SocketCanConfig sc;
  sc.interface = c.can_interface;
  auto bus = lnx::SocketCan::open(sc);
  if (!bus.is_ok()) return lnx::describe(c.can_interface, bus.status());
  b.bus = std::move(bus).value();
  return "";
}

std::string open_watchdog(const FwConfig& c, hal::Clock& clock, Board& b) {
  if (c.watchdog == WatchdogKind::kSystemd) {
    auto wd = lnx::SystemdWatchdog::open(clock);
    if (!wd.is_ok()) return lnx::describe("systemd watchdog", wd.status());
    b.watchdog = std::move(wd).value();
  } else if (c.watchdog == WatchdogKind::kDevice) {
    auto wd = lnx::DevWatchdog::open(c.watchdog_device, kDevWatchdogTimeoutS);
    if (!wd.is_ok()) return lnx::describe(c.watchdog_device, wd.status());
    b.watchdog = std::move(wd).value();
  }
  return "";
}

void add_can_protocol(const FwConfig& c, Board& b) {
  const auto node = static_cast<std::uint8_t>(c.node_id);
  b.sink = std::make_unique<CanEpochSink>(*b.bus, node, to_can_dividers(c));
  b.codec = std::make_unique<CanCommandCodec>(node);
}

// ---- Simulated board ----------------------------------------------------------------------

struct SimParts {
  std::unique_ptr<sim_board::SensorStream> stream;
  std::unique_ptr<sim_board::ChipAdc> adc;
  std::unique_ptr<hal::DataReadyLine> drdy;  // pacing "gpio" only
};

/// The data-ready line of adc.gpio_chip / adc.drdy_line (an offset when all digits, else a name),
/// as the Linux board opens it: falling edges (ADS131M06 DRDY is active low), sequence inferred
/// from the kernel timestamps against the nominal period.
Result<std::unique_ptr<lnx::GpiodDataReady>> open_drdy(const FwConfig& c) {
  lnx::GpiodDataReadyConfig dr;
  dr.chip = c.gpio_chip;
  if (c.drdy_line.find_first_not_of("0123456789") == std::string::npos) {
    dr.line_offset = std::stoi(c.drdy_line);
  } else {
    dr.line_name = c.drdy_line;
  }
  dr.nominal_period_ns = static_cast<std::int64_t>(std::llround(1e9 / c.sample_rate_hz));
  return lnx::GpiodDataReady::open(dr);
}

BoardResult make_sim_board(const FwConfig& c) {
  BoardResult out;
  // Named scenarios: sim.scenario_dir when set, else found relative to this program
  // ($GFINS_SCENARIO_DIR, PREFIX/share/gfins/scenarios, PREFIX/share/gfins-fw/scenarios: the
  // gfins-fw package carries its own copy; gfins/host_sim/data_paths.hpp).
  const auto parsed = c.sim_scenario_dir.empty()
                          ? sim::load_scenario(c.sim_scenario)
                          : sim::load_scenario(c.sim_scenario, c.sim_scenario_dir);
  if (!parsed.is_ok()) {
    out.error = parsed.error().message;
    return out;
  }
  const sim::Scenario& s = parsed.value();
  if (s.rate_hz != c.sample_rate_hz) {
    out.error = "scenario " + s.name + " runs at " + std::to_string(s.rate_hz) +
                " Hz but adc.sample_rate_hz is " + std::to_string(c.sample_rate_hz);
    return out;
  }
  const double duration = c.sim_duration_s > 0 ? c.sim_duration_s : s.duration_s;
  auto parts = std::make_shared<SimParts>();
  auto stream = sim_board::make_scenario_stream(s);
  if (!stream.is_ok()) {
    out.error = stream.error().message;
    return out;
  }
  parts->stream = std::move(stream).value();
  parts->adc = std::make_unique<sim_board::ChipAdc>(s.rate_hz);
  if (const Status st = parts->adc->start(); !st.is_ok()) {
    out.error = std::string("simulated ADC start: ") + st.message();
    return out;
  }
  auto b = std::make_unique<Board>();
  const bool fast = c.pacing == Pacing::kFast;
  sim_board::SampleClock* sample_clock = nullptr;
  if (fast) {
    auto clock = std::make_unique<sim_board::SampleClock>();
    sample_clock = clock.get();
    b->clock = std::move(clock);
  } else {
    // CLOCK_MONOTONIC: the clock of the kernel's GPIO edge timestamps too.
    b->clock = std::make_unique<sim_board::SteadyClock>();
  }
  const auto samples = static_cast<std::uint32_t>(std::llround(duration * s.rate_hz)) + 1;
  std::unique_ptr<sim_board::SimSampleSource> source;
  if (c.pacing == Pacing::kGpio) {
    auto drdy = open_drdy(c);
    if (!drdy.is_ok()) {
      out.error = lnx::describe(c.gpio_chip + " line " + c.drdy_line, drdy.status());
      return out;
    }
    parts->drdy = std::move(drdy).value();
    source = std::make_unique<sim_board::SimSampleSource>(*parts->stream, *parts->adc, *b->clock,
                                                          *parts->drdy, samples);
  } else {
    source = std::make_unique<sim_board::SimSampleSource>(
        *parts->stream, *parts->adc, *b->clock, sample_clock,
        fast ? sim_board::Pacing::kFast : sim_board::Pacing::kRealTime, s.rate_hz, samples);
  }
  const sim_board::SimSampleSource* src = source.get();
  b->finished = [src] { return src->finished(); };
  b->source = std::move(source);
  if (std::string e = open_bus(c, *b->clock, *b); !e.empty()) {
    out.error = e;
    return out;
  }
  add_can_protocol(c, *b);
  // Uncalibrated defaults: the nominal chain (no misalignment, nominal scale factors, no bias).
  // The factory calibration: the scenario's true parameters.
  b->factory = sim_board::scenario_calibration(s, parts->adc->volts_per_count());
  b->defaults = *b->factory;
  for (auto& sensor : b->defaults.sensors) {
    sensor.bias_g = 0.0;
    sensor.location_error_m = {0.0, 0.0, 0.0};
  }
  b->defaults.beta = {};
  b->defaults.alpha = {};
  b->defaults.compensator = nav::CompensatorKind::kNone;
  // Real-time and GPIO pacing run against the wall clock: give them the board's real-time
  // set-up and its watchdog too (the service unit's WatchdogSec on the virtual board).
  if (!fast) {
    b->enter_realtime = enter_realtime;
    if (std::string e = open_watchdog(c, *b->clock, *b); !e.empty()) {
      out.error = e;
      return out;
    }
  }
  b->close = [bus = b->bus.get()] { bus->service(); };
  b->keep_alive = parts;
  out.board = std::move(b);
  return out;
}

// ---- Linux board ------------------------------------------------------------------------------

/// The ADS131M06 driver as the loop's sample source.
class AdcSource final : public SampleSource {
 public:
  AdcSource(std::unique_ptr<hal::SpiDevice> spi, std::unique_ptr<hal::DataReadyLine> drdy,
            const drivers::Ads131m06Config& c, double volts_per_count)
      : spi_(std::move(spi)),
        drdy_(std::move(drdy)),
        driver_(*spi_, *drdy_, c),
        volts_per_count_(volts_per_count) {}
  Status start() { return driver_.start(); }

 private:
  Result<RawSample> do_read_sample(std::int64_t timeout_ns) override {
    return driver_.read_sample(timeout_ns);
  }
  AdcCounters do_counters() const override {
    const drivers::Ads131m06Counters& d = driver_.counters();
    // Resets met as a register re-verification mismatch count too (docs/faults.md).
    return AdcCounters{d.crc_errors, d.missed_edges, d.extra_edges,
                       d.chip_resets + d.register_mismatches};
  }
  double do_volts_per_count() const override { return volts_per_count_; }

  std::unique_ptr<hal::SpiDevice> spi_;
  std::unique_ptr<hal::DataReadyLine> drdy_;
  drivers::Ads131m06 driver_;
  double volts_per_count_;
};

// "/dev/spidevB.C" → bus B, chip select C.
bool parse_spidev(const std::string& path, unsigned& bus, unsigned& cs) {
  const std::string prefix = "/dev/spidev";
  if (path.rfind(prefix, 0) != 0) return false;
  const std::string rest = path.substr(prefix.size());
  const auto dot = rest.find('.');
  if (dot == std::string::npos || dot == 0 || dot + 1 == rest.size()) return false;
  const auto digits = [](const std::string& t) {
    return !t.empty() && t.size() < 4 && t.find_first_not_of("0123456789") == std::string::npos;
  };
  if (!digits(rest.substr(0, dot)) || !digits(rest.substr(dot + 1))) return false;
  bus = static_cast<unsigned>(std::stoul(rest.substr(0, dot)));
  cs = static_cast<unsigned>(std::stoul(rest.substr(dot + 1)));
  return true;
}

BoardResult make_linux_board(const FwConfig& c) {
  BoardResult out;
  auto b = std::make_unique<Board>();
  auto clock = lnx::MonotonicClock::open();
  if (!clock.is_ok()) {
    out.error = lnx::describe("monotonic clock", clock.status());
    return out;
  }
  b->clock = std::move(clock).value();

  lnx::SpidevConfig spi_cfg;
  if (!parse_spidev(c.spi_device, spi_cfg.bus, spi_cfg.chip_select)) {
    out.error = "adc.spi_device = \"" + c.spi_device + "\": expected /dev/spidevB.C";
    return out;
  }
  auto spi = lnx::Spidev::open(spi_cfg);
  if (!spi.is_ok()) {
    out.error = lnx::describe(c.spi_device, spi.status());
    return out;
  }
  auto drdy = open_drdy(c);
  if (!drdy.is_ok()) {
    out.error = lnx::describe(c.gpio_chip + " line " + c.drdy_line, drdy.status());
    return out;
  }
  drivers::Ads131m06Config adc_cfg;
  adc_cfg.sample_rate_hz = c.sample_rate_hz;
  const auto fe = drivers::Qa1100FrontEnd::create(drivers::Qa1100FrontEnd::Channels{}, adc_cfg);
  if (!fe.is_ok()) {
    out.error = std::string("QA-1100 front end: ") + fe.status().message();
    return out;
  }
  const double lsb = fe.value().volts_per_count(0);
  auto source =
      std::make_unique<AdcSource>(std::move(spi).value(), std::move(drdy).value(), adc_cfg, lsb);
  if (const Status st = source->start(); !st.is_ok()) {
    out.error = lnx::describe("ADS131M06 on " + c.spi_device, st);
    return out;
  }
  b->source = std::move(source);
  if (std::string e = open_bus(c, *b->clock, *b); !e.empty()) {
    out.error = e;
    return out;
  }
  add_can_protocol(c, *b);
  if (std::string e = open_watchdog(c, *b->clock, *b); !e.empty()) {
    out.error = e;
    return out;
  }
  b->defaults = nominal_calibration(lsb);
  b->enter_realtime = enter_realtime;
  b->close = [bus = b->bus.get()] { bus->service(); };
  out.board = std::move(b);
  return out;
}

// ---- Hardware-in-the-loop replay board (docs/hil.md) -----------------------------------------

constexpr std::int64_t kIdleWaitNs = 1000000000;

/// Samples from the host over the replay link, in place of the ADC. The loop's clock follows the
/// samples' edge times (driven by the sample index, never by the wall clock).
class HilSource final : public SampleSource {
 public:
  HilSource(lnx::HilServer& server, sim_board::SampleClock& clock, double volts_per_count,
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
  sim_board::SampleClock& clock_;
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
    // Written whole under a temporary name, then renamed: a reader never sees half a number.
    const std::string tmp = c.hil_port_file + ".tmp";
    {
      std::ofstream f(tmp, std::ios::trunc);
      f << srv->port() << "\n";
      if (!f) {
        out.error = "hil.port_file = \"" + c.hil_port_file + "\": cannot be written";
        return out;
      }
    }
    std::error_code ec;
    std::filesystem::rename(tmp, c.hil_port_file, ec);
    if (ec) {
      out.error = "hil.port_file = \"" + c.hil_port_file + "\": " + ec.message();
      return out;
    }
  }
  spdlog::info("hil: waiting for gfins-can hil on {}:{}", c.hil_address, srv->port());
  auto b = std::make_unique<Board>();
  auto clock = std::make_unique<sim_board::SampleClock>();
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
        "frames sent, {} not sent{}",
        h.connections, h.drops, h.samples, h.crc_errors, h.frame_errors, h.can_sent, h.can_dropped,
        srv->last_event()[0] == '\0' ? std::string()
                                     : std::string("; last event: ") + srv->last_event());
  };
  b->keep_alive = parts;
  out.board = std::move(b);
  return out;
}

}  // namespace

BoardResult make_board(const FwConfig& c) {
  if (c.board == BoardKind::kHil) return make_hil_board(c);
  return c.board == BoardKind::kSim ? make_sim_board(c) : make_linux_board(c);
}

}  // namespace gfins::app
