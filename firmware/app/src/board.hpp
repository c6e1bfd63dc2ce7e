// The board the firmware runs on: the Linux board (spidev, GPIO data-ready, SocketCAN) or the
// simulated one. Built once at start-up; the sample loop only sees the interfaces.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "gfins/app/config.hpp"
#include "gfins/app/ports.hpp"
#include "gfins/calib_file/calibration_data.hpp"
#include "gfins/hal/can_bus.hpp"
#include "gfins/hal/clock.hpp"
#include "gfins/hal/watchdog.hpp"

namespace gfins::app {

struct Board {
  // Declaration order is destruction order reversed: what others refer to comes first (the
  // simulated parts and the clock outlive the source and the bus, whose destructor flushes a
  // candump file with clock time).
  std::shared_ptr<void> keep_alive;  // objects the parts below refer to
  std::unique_ptr<hal::Clock> clock;
  std::unique_ptr<SampleSource> source;
  std::unique_ptr<hal::CanBus> bus;
  std::unique_ptr<EpochSink> sink;
  std::unique_ptr<CommandCodec> codec;                 // null: commands not handled
  std::unique_ptr<hal::Watchdog> watchdog;             // null: none
  calib_file::CalibrationData defaults;                // nominal calibration of this board
  std::optional<calib_file::CalibrationData> factory;  // used when no file is configured
  std::function<bool()> finished = [] { return false; };
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

BoardResult make_board(const FwConfig& c);

}  // namespace gfins::app
