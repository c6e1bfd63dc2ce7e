// gfins-can hil: hardware-in-the-loop replay (docs/hil.md). Streams raw samples (a scenario
// through host_sim's sample source, or a .gfr recording with the aiding frames it holds) to
// gfins-fw --board hil over TCP, collects the CAN frames it publishes on the same connection,
// and compares them with a host-only run of the navigation core on the same samples and aiding.
#pragma once

#include <cstdint>
#include <ostream>
#include <string>

namespace gfins::can_tool {

struct HilOptions {
  std::string address = "127.0.0.1";
  int port = 7476;
  std::string scenario;          // name or .toml (one of scenario / recording)
  std::string scenario_dir;      // empty: the source tree's scenarios
  std::string recording;         // .gfr file
  double duration_s = 0;         // scenario: 0 = the scenario's duration
  std::string fw_config;         // the firmware's configuration file (empty: its defaults)
  int window = 32;               // samples in flight, unacknowledged
  int timeout_ms = 5000;         // longest silence of the board before the run is declared lost
  int abort_after = -1;          // test hook: reset the connection after sending this many samples
  int corrupt_at = -1;           // test hook: flip one bit of this sample's frame (bad CRC)
  std::int64_t drop_frame = -1;  // test hook: leave this aiding frame (0-based) off the link;
                                 // the host-only run still applies it
};

/// Exit codes of gfins-can hil (gfins-can --help, docs/hil.md): 0 every epoch arrived and
/// equals the core within quantisation; kHilExitBadInput a scenario, recording, configuration or
/// connection that cannot be used; kHilExitDifferent differences or an incomplete stream
/// (reported). Distinct from gfins-can's 1 (command-line error).
inline constexpr int kHilExitBadInput = 2;
inline constexpr int kHilExitDifferent = 8;

int run_hil(const HilOptions& o, std::ostream& out, std::ostream& err);

}  // namespace gfins::can_tool
