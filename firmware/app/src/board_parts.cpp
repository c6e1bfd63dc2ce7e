#include <algorithm>
#include <cmath>

#include "boards.hpp"
#include "gfins/app/board.hpp"
#include "gfins/app/publisher_sink.hpp"
#include "gfins/app/startup.hpp"
#include "gfins/drivers/lnx/candump.hpp"
#include "gfins/drivers/lnx/candump_file_bus.hpp"
#include "gfins/drivers/lnx/dev_watchdog.hpp"
#include "gfins/drivers/lnx/error_text.hpp"
#include "gfins/drivers/lnx/gpiod_data_ready.hpp"
#include "gfins/drivers/lnx/realtime.hpp"
#include "gfins/drivers/lnx/socket_can.hpp"
#include "gfins/drivers/lnx/systemd_watchdog.hpp"

namespace gfins::app {
namespace lnx = drivers::lnx;
namespace {

// /dev/watchdog timeout: long enough for a loaded start-up, short enough to restart a hung loop
// within a minute.
constexpr int kDevWatchdogTimeoutS = 10;

}  // namespace

void add_firmware_boards(BoardTable& t) {
  t.add(BoardEntry{BoardKind::kLinux, nullptr, make_linux_board});
  t.add(BoardEntry{BoardKind::kHil, nullptr, make_hil_board});
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

std::string open_can_output(const FwConfig& c, hal::Clock& clock, Board& b) {
  if (!c.can_log.empty()) {
    lnx::CandumpFileBusConfig bc;
    bc.path = c.can_log;
    bc.interface = c.can_interface;
    // File writes off the loop thread, except in fast pacing, whose output must be the same on
    // every run (a writer thread that falls behind drops frames: a matter of scheduling).
    bc.background_writer = !(c.board == BoardKind::kSim && c.pacing == Pacing::kFast);
    // The simulated board's clock starts at 0 with the scenario: its log starts at the documented
    // epoch of simulated logs. A board's clock is its own (CLOCK_MONOTONIC).
    if (c.board == BoardKind::kSim) bc.time_offset_ns = lnx::kSimulatedLogEpochS * 1000000000;
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
  // Receive filters (CAN_RAW_FILTER): the kernel passes the loop only the frames addressed to
  // this board, its command identifier and, when it takes them, its aiding inputs. The loop reads
  // at most two frames per sample, so other equipment's traffic on a shared bus (3,400 frames/s
  // of OxTS- and CANopen-like frames in the virtual board's stage ids) would otherwise fill the
  // socket's receive queue and push a command out (docs/can-interface.md, "Identifiers").
  static_assert(std::count_if(can::kMessages.begin(), can::kMessages.end(),
                              [](const can::MessageDef& m) {
                                return m.kind == can::MessageKind::kCommand ||
                                       m.kind == can::MessageKind::kInput;
                              }) <= static_cast<std::ptrdiff_t>(lnx::SocketCan::kMaxFilters),
                "one receive filter per message the board takes");
  std::array<lnx::CanFilter, lnx::SocketCan::kMaxFilters> filters{};
  std::size_t n_filters = 0;
  const LoopOptions loop = loop_options(c);  // the node, groups and inputs the loop will take
  for (const can::MessageDef& m : can::kMessages) {
    const bool wanted = m.kind == can::MessageKind::kCommand ||
                        (m.kind == can::MessageKind::kInput && loop.aiding_inputs);
    if (wanted) {
      filters[n_filters++] = lnx::CanFilter{can::can_id(m.id, loop.node_id, loop.ids),
                                            hal::CanFrame::kMaxStandardId, false};
    }
  }
  lnx::SocketCanConfig sc;
  sc.interface = c.can_interface;
  sc.filters = std::span<const lnx::CanFilter>(filters.data(), n_filters);
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
  b.sink =
      std::make_unique<PublisherSink>(*b.bus, node, bus_dividers(c), bus_budget(c), id_bases(c));
  b.commands = true;
}

DataReadyResult open_data_ready(const FwConfig& c) {
  // Falling edges (ADS131M06 DRDY is active low), sequence inferred from the kernel timestamps
  // against the nominal period; adc.drdy_line is an offset when all digits, else a name.
  lnx::GpiodDataReadyConfig dr;
  dr.chip = c.gpio_chip;
  if (c.drdy_line.find_first_not_of("0123456789") == std::string::npos) {
    dr.line_offset = std::stoi(c.drdy_line);
  } else {
    dr.line_name = c.drdy_line;
  }
  dr.nominal_period_ns = static_cast<std::int64_t>(std::llround(1e9 / c.sample_rate_hz));
  DataReadyResult out;
  auto line = lnx::GpiodDataReady::open(dr);
  if (!line.is_ok()) {
    out.error = lnx::describe(c.gpio_chip + " line " + c.drdy_line, line.status());
    return out;
  }
  out.line = std::move(line).value();
  return out;
}

std::string describe_status(const std::string& what, const Status& s) {
  return lnx::describe(what, s);
}

}  // namespace gfins::app
