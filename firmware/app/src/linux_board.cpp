// The Linux board: the ADS131M06 on spidev, its data-ready line through libgpiod, SocketCAN or
// a candump log file, the configured watchdog.
#include <memory>
#include <string>

#include "boards.hpp"
#include "gfins/app/board.hpp"
#include "gfins/app/startup.hpp"
#include "gfins/drivers/ads131m06.hpp"
#include "gfins/drivers/lnx/error_text.hpp"
#include "gfins/drivers/lnx/monotonic_clock.hpp"
#include "gfins/drivers/lnx/spidev.hpp"
#include "gfins/drivers/qa1100_front_end.hpp"

namespace gfins::app {
namespace lnx = drivers::lnx;
namespace {

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

}  // namespace

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
  DataReadyResult drdy = open_data_ready(c);
  if (!drdy.line) {
    out.error = drdy.error;
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
      std::make_unique<AdcSource>(std::move(spi).value(), std::move(drdy.line), adc_cfg, lsb);
  if (const Status st = source->start(); !st.is_ok()) {
    out.error = lnx::describe("ADS131M06 on " + c.spi_device, st);
    return out;
  }
  b->source = std::move(source);
  if (std::string e = open_can_output(c, *b->clock, *b); !e.empty()) {
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

}  // namespace gfins::app
