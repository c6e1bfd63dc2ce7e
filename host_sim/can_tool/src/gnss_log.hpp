// gfins-can gnss: a scenario's simulated GNSS receiver (host_sim GnssModel) as the CAN
// interface's GNSS input frames, into a candump log or onto a live bus (docs/can-interface.md,
// "Aiding inputs").
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "gfins/can/aiding_input.hpp"
#include "gfins/hal/can_bus.hpp"
#include "gfins/host_sim/gnss_model.hpp"

namespace gfins::can_tool {

/// Writes every fix's four frames as candump lines on interface `iface`, stamped at the fix's
/// transmission time + `log_start_s`, at the board's identifier groups `ids`. False when writing
/// failed.
bool write_gnss_log(std::FILE* out, const std::vector<sim::GnssSample>& fixes,
                    const sim::GnssSpec& spec, std::uint8_t node_id, double log_start_s,
                    const std::string& iface = "can0", const can::IdBases& ids = {});

/// Sends the fixes on `bus`, each at its transmission time after the call (wall clock, steady);
/// returns the frames the bus refused.
std::uint64_t send_gnss_live(hal::CanBus& bus, const std::vector<sim::GnssSample>& fixes,
                             const sim::GnssSpec& spec, std::uint8_t node_id,
                             const can::IdBases& ids = {});

}  // namespace gfins::can_tool
