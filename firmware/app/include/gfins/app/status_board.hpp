// What the service status line (systemd STATUS=, docs/deploy.md) is made of, handed from the
// sample loop to the thread that reports it. The loop writes it once per cycle with relaxed
// atomic stores (plain stores on x86-64 and AArch64: no lock, no allocation, no system call);
// the reporter thread reads it about once a second. Fields are read one by one, so a snapshot
// may mix counters of two adjacent cycles: harmless for a status line whose counters only grow.
#pragma once

#include <atomic>
#include <cstdint>

#include "gfins/app/health.hpp"
#include "gfins/can/epoch.hpp"

namespace gfins::app {

/// One reading of the board's state for the status line.
struct StatusSnapshot {
  can::Mode mode = can::Mode::kStartup;
  bool degraded = false;  // navigating on a faulty input (the HealthDegraded status bit)
  bool calibrated = false;
  std::uint32_t cal_id = 0;
  std::uint32_t samples = 0;
  std::uint32_t missed_edges = 0;
  std::uint32_t drdy_timeouts = 0;
  std::uint32_t crc_errors = 0;
  std::uint32_t adc_resets = 0;
  std::uint32_t stuck_mask = 0;
  std::uint32_t can_tx_dropped = 0;
  std::uint32_t can_rx_dropped = 0;
  std::uint32_t bus_off_events = 0;
  std::uint32_t loop_overruns = 0;
};

class StatusBoard {
 public:
  /// The loop's side: once per cycle.
  void publish(can::Mode mode, bool degraded, bool calibrated, std::uint32_t cal_id,
               const HealthCounters& h) {
    constexpr auto kR = std::memory_order_relaxed;
    mode_.store(static_cast<std::uint8_t>(mode), kR);
    degraded_.store(degraded, kR);
    calibrated_.store(calibrated, kR);
    cal_id_.store(cal_id, kR);
    samples_.store(h.samples, kR);
    missed_edges_.store(h.missed_edges, kR);
    drdy_timeouts_.store(h.drdy_timeouts, kR);
    crc_errors_.store(h.crc_errors, kR);
    adc_resets_.store(h.adc_resets, kR);
    stuck_mask_.store(h.stuck_mask, kR);
    can_tx_dropped_.store(h.can_tx_dropped, kR);
    can_rx_dropped_.store(h.can_rx_dropped, kR);
    bus_off_events_.store(h.bus_off_events, kR);
    loop_overruns_.store(h.loop_overruns, kR);
  }

  /// The reporter's side.
  StatusSnapshot read() const {
    constexpr auto kR = std::memory_order_relaxed;
    StatusSnapshot s;
    s.mode = static_cast<can::Mode>(mode_.load(kR));
    s.degraded = degraded_.load(kR);
    s.calibrated = calibrated_.load(kR);
    s.cal_id = cal_id_.load(kR);
    s.samples = samples_.load(kR);
    s.missed_edges = missed_edges_.load(kR);
    s.drdy_timeouts = drdy_timeouts_.load(kR);
    s.crc_errors = crc_errors_.load(kR);
    s.adc_resets = adc_resets_.load(kR);
    s.stuck_mask = stuck_mask_.load(kR);
    s.can_tx_dropped = can_tx_dropped_.load(kR);
    s.can_rx_dropped = can_rx_dropped_.load(kR);
    s.bus_off_events = bus_off_events_.load(kR);
    s.loop_overruns = loop_overruns_.load(kR);
    return s;
  }

 private:
  std::atomic<std::uint8_t> mode_{static_cast<std::uint8_t>(can::Mode::kStartup)};
  std::atomic<bool> degraded_{false};
  std::atomic<bool> calibrated_{false};
  std::atomic<std::uint32_t> cal_id_{0}, samples_{0}, missed_edges_{0}, drdy_timeouts_{0},
      crc_errors_{0}, adc_resets_{0}, stuck_mask_{0}, can_tx_dropped_{0}, can_rx_dropped_{0},
      bus_off_events_{0}, loop_overruns_{0};
  static_assert(std::atomic<std::uint32_t>::is_always_lock_free, "the loop must never lock");
  static_assert(std::atomic<std::uint8_t>::is_always_lock_free, "the loop must never lock");
};

}  // namespace gfins::app
