// The board the firmware runs on, built once at start-up; the sample loop only sees the
// interfaces. Boards are plug-ins: a BoardTable maps board.kind to the code that checks its
// configuration and builds it. The firmware registers its own boards, the Linux board (spidev,
// GPIO data-ready, SocketCAN) and the hardware-in-the-loop replay board (add_firmware_boards);
// the host build of gfins-fw adds the simulated board, which is host code (host_sim/board),
// through add_plugin_boards (docs/architecture.md, "Boards").
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "gfins/app/config.hpp"
#include "gfins/app/ports.hpp"
#include "gfins/calib_file/calibration_data.hpp"
#include "gfins/hal/can_bus.hpp"
#include "gfins/hal/clock.hpp"
#include "gfins/hal/data_ready.hpp"
#include "gfins/hal/watchdog.hpp"

namespace gfins::app {

/// How far a board with a known end (the simulated board running faster than real time) is.
struct BoardProgress {
  double fraction = 0.0;    // 0..1 of its samples delivered
  double duration_s = 0.0;  // the whole run, in the board's time
};

struct Board {
  // Declaration order is destruction order reversed: what others refer to comes first (the
  // simulated parts and the clock outlive the source and the bus, whose destructor flushes a
  // candump file with clock time).
  std::shared_ptr<void> keep_alive;  // objects the parts below refer to
  std::unique_ptr<hal::Clock> clock;
  std::unique_ptr<SampleSource> source;
  std::unique_ptr<hal::CanBus> bus;
  std::unique_ptr<EpochSink> sink;
  bool commands = false;  // the CAN command frames of the node are decoded and answered
  std::unique_ptr<hal::Watchdog> watchdog;             // null: none
  calib_file::CalibrationData defaults;                // nominal calibration of this board
  std::optional<calib_file::CalibrationData> factory;  // used when no file is configured
  std::function<bool()> finished = [] { return false; };
  /// Null: no known end (a real board), nothing to report.
  std::function<BoardProgress()> progress;
  /// Wall-clock seconds between two progress lines (set by the board that reports progress).
  double progress_interval_s = 5.0;
  /// SCHED_FIFO + mlockall as configured; returns a warning when not permitted ("" when done).
  std::function<std::string(const FwConfig&)> enter_realtime = [](const FwConfig&) {
    return std::string();
  };
  std::function<void()> close = [] {};
  /// After close(): writes what the CAN output still buffers and says what was lost ("" when
  /// every frame reached its destination). A candump log file that failed to take frames
  /// (disk full, /dev/full, EIO) makes the run end with exit code 1 (docs/firmware.md).
  std::function<std::string()> finish_output = [] { return std::string(); };
};

struct BoardResult {
  std::unique_ptr<Board> board;
  std::string error;
};

/// One kind of board (board.kind).
struct BoardEntry {
  BoardKind kind = BoardKind::kLinux;
  /// Checks of the configuration against the file system that only this board needs, run by
  /// preflight() before any other; "" when they pass, else "<origin>: key = value: why". Null:
  /// nothing to check.
  std::string (*check)(const FwConfig& c, const std::string& origin) = nullptr;
  BoardResult (*make)(const FwConfig& c) = nullptr;
};

/// The boards this gfins-fw can run on. Filled at start-up, read-only afterwards.
class BoardTable {
 public:
  /// Registers `e`; an entry of the same kind is replaced.
  void add(const BoardEntry& e);
  /// The entry of `kind`, or null when this build has no such board.
  const BoardEntry* find(BoardKind kind) const;

 private:
  std::vector<BoardEntry> entries_;
};

/// Registers the firmware's own boards: linux and hil.
void add_firmware_boards(BoardTable& t);

/// Registers the boards the executable links in from outside the firmware. Defined once per
/// executable by what the build links: host_sim/board (the simulated board, GFINS_SIM_BOARD=ON)
/// or firmware/app/src/no_plugin_boards.cpp (none: the board's own package).
void add_plugin_boards(BoardTable& t);

/// The board of c.board from `t`; board_not_built() when this build does not have it.
BoardResult make_board(const BoardTable& t, const FwConfig& c);

/// "board.kind = "sim": this gfins-fw is built without that board (...)".
std::string board_not_built(BoardKind kind);

// ---- Parts every board builds the same way -------------------------------------------------

/// SCHED_FIFO and mlockall as configured; a warning when they are not permitted, "" when done.
std::string enter_realtime(const FwConfig& c);

/// The CAN output into b.bus (and b.finish_output): a candump log file when can.log_file is set,
/// the SocketCAN interface otherwise. "" when opened, else what failed.
std::string open_can_output(const FwConfig& c, hal::Clock& clock, Board& b);

/// The configured watchdog into b.watchdog (none, systemd or /dev/watchdog). "" or what failed.
std::string open_watchdog(const FwConfig& c, hal::Clock& clock, Board& b);

/// The CAN protocol on b.bus: the epoch sink (publisher) and command handling.
void add_can_protocol(const FwConfig& c, Board& b);

/// The data-ready line of adc.gpio_chip / adc.drdy_line through libgpiod, as the Linux board
/// opens it; on failure the error names the chip and line.
struct DataReadyResult {
  std::unique_ptr<hal::DataReadyLine> line;
  std::string error;
};
DataReadyResult open_data_ready(const FwConfig& c);

/// "<what>: <status message>[: strerror]" (the Linux backends' error text).
std::string describe_status(const std::string& what, const Status& s);

}  // namespace gfins::app
