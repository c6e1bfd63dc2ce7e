// Data-ready line seam: the ADC's DRDY pin on a GPIO line. One edge = one conversion ready.
//
// Every edge carries the kernel's timestamp (CLOCK_MONOTONIC, taken in the interrupt handler,
// so scheduling latency does not move it) and a sequence number. A jump of the sequence number
// by more than one means edges were missed (libgpiod's gpiosim tests and PX4's drivers detect
// lost samples the same way). Backends whose kernel interface has no sequence number (libgpiod
// 1.6 uses the v1 uAPI) infer it from the timestamps and the nominal period, and say so.
#pragma once

#include <cstdint>

#include "gfins/status/status.hpp"

namespace gfins::hal {

struct DataReadyEdge {
  std::int64_t t_ns = 0;  // edge time, CLOCK_MONOTONIC ns (sample-clock time in simulation)
  std::uint32_t seq = 0;  // edge sequence number; consecutive edges differ by exactly 1
};

class DataReadyLine {
 public:
  virtual ~DataReadyLine() = default;

  /// Waits for the next rising edge for at most `timeout_ns` (0 = poll). kTimeout when none
  /// came; kInvalidArgument for a negative timeout; kIoError / kUnavailable from the backend.
  [[nodiscard]] Result<DataReadyEdge> wait_edge(std::int64_t timeout_ns) {
    if (timeout_ns < 0) {
      return Status(ErrorCode::kInvalidArgument, "data-ready: negative timeout");
    }
    return do_wait_edge(timeout_ns);
  }

 private:
  virtual Result<DataReadyEdge> do_wait_edge(std::int64_t timeout_ns) = 0;
};

}  // namespace gfins::hal
