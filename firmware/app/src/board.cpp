#include "board.hpp"

#include <filesystem>

#include "gfins/app/can_adapters.hpp"
#include "gfins/app/startup.hpp"
#include "gfins/drivers/ads131m06.hpp"
#include "gfins/drivers/lnx/candump_file_bus.hpp"
#include "gfins/drivers/lnx/dev_watchdog.hpp"
#include "gfins/drivers/lnx/error_text.hpp"
#include "gfins/drivers/lnx/gpiod_data_ready.hpp"
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

// Named scenarios: next to the installed program (../share/gfins/scenarios), else the source
// tree's (a build that was not installed).
std::string scenario_dir(const FwConfig& c) {
  if (!c.sim_scenario_dir.empty()) return c.sim_scenario_dir;
  std::error_code ec;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const auto installed = exe.parent_path().parent_path() / "share" / "gfins" / "scenarios";
    if (std::filesystem::is_directory(installed, ec)) return installed.string();
  }
  return GFINS_SCENARIO_DIR;
}

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
    auto bus = lnx::CandumpFileBus::open(bc, clock);
    if (!bus.is_ok()) return lnx::describe(c.can_log, bus.status());
    b.bus = std::move(bus).value();
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
};

BoardResult make_sim_board(const FwConfig& c) {
  BoardResult out;
  const auto parsed = sim::load_scenario(c.sim_scenario, scenario_dir(c));
  if (!parsed.is_ok()) {
    out.error = parsed.error().message;
    return out;
  }
  const sim::Scenario s = parsed.value();
  if (s.rate_hz != c.sample_rate_hz) {
    out.error = "scenario " + s.name + " runs at " + std::to_string(s.rate_hz) +
                " Hz but adc.sample_rate_hz is " + std::to_string(c.sample_rate_hz);
    return out;
  }
  const double duration = c.sim_duration_s > 0 ? c.sim_duration_s : s.duration_s;
  auto parts = std::make_shared<SimParts>();
  parts->stream = sim_board::make_scenario_stream(s);
  if (!parts->stream) {
    out.error = "scenario " + s.name + ": its trajectory cannot be built";
    return out;
  }
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
    b->clock = std::make_unique<sim_board::SteadyClock>();
  }
  const auto samples = static_cast<std::uint32_t>(std::llround(duration * s.rate_hz)) + 1;
  auto source = std::make_unique<sim_board::SimSampleSource>(
      *parts->stream, *parts->adc, *b->clock, sample_clock,
      fast ? sim_board::Pacing::kFast : sim_board::Pacing::kRealTime, s.rate_hz, samples);
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
  // Real-time pacing measures latency: give it the board's real-time set-up too.
  if (!fast) b->enter_realtime = enter_realtime;
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
    return AdcCounters{d.crc_errors, d.missed_edges, d.extra_edges, d.chip_resets};
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
  lnx::GpiodDataReadyConfig dr;
  dr.chip = c.gpio_chip;
  if (c.drdy_line.find_first_not_of("0123456789") == std::string::npos) {
    dr.line_offset = std::stoi(c.drdy_line);
  } else {
    dr.line_name = c.drdy_line;
  }
  dr.nominal_period_ns = static_cast<std::int64_t>(std::llround(1e9 / c.sample_rate_hz));
  auto drdy = lnx::GpiodDataReady::open(dr);
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

}  // namespace

BoardResult make_board(const FwConfig& c) {
  return c.board == BoardKind::kSim ? make_sim_board(c) : make_linux_board(c);
}

}  // namespace gfins::app
