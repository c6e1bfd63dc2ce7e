#include "gnss_log.hpp"

#include <chrono>
#include <cmath>
#include <thread>

#include "gfins/drivers/lnx/candump.hpp"
#include "gfins/host_sim/board/sim_board.hpp"

namespace gfins::can_tool {

bool write_gnss_log(std::FILE* out, const std::vector<sim::GnssSample>& fixes,
                    const sim::GnssSpec& spec, std::uint8_t node_id, double log_start_s,
                    const std::string& iface, const can::IdBases& ids) {
  for (const sim::GnssSample& s : fixes) {
    const auto t_us = static_cast<std::int64_t>(std::llround((log_start_s + s.t_send_s) * 1e6));
    for (const hal::CanFrame& f :
         can::encode_gnss_fix(sim_board::to_gnss_fix(s, spec), node_id, ids)) {
      char line[drivers::lnx::kMaxCandumpLine + 1];
      const std::size_t n = drivers::lnx::format_candump_line(
          std::span<char>(line, drivers::lnx::kMaxCandumpLine), t_us / 1000000,
          static_cast<std::uint32_t>(t_us % 1000000), iface.c_str(), f);
      if (n == 0) return false;
      line[n] = '\n';
      if (std::fwrite(line, 1, n + 1, out) != n + 1) return false;
    }
  }
  return std::fflush(out) == 0;
}

std::uint64_t send_gnss_live(hal::CanBus& bus, const std::vector<sim::GnssSample>& fixes,
                             const sim::GnssSpec& spec, std::uint8_t node_id,
                             const can::IdBases& ids) {
  std::uint64_t refused = 0;
  const auto start = std::chrono::steady_clock::now();
  for (const sim::GnssSample& s : fixes) {
    std::this_thread::sleep_until(start + std::chrono::duration_cast<std::chrono::nanoseconds>(
                                              std::chrono::duration<double>(s.t_send_s)));
    for (const hal::CanFrame& f :
         can::encode_gnss_fix(sim_board::to_gnss_fix(s, spec), node_id, ids)) {
      if (!bus.send(f).is_ok()) ++refused;
    }
  }
  return refused;
}

}  // namespace gfins::can_tool
