// Text generated from the message table: the DBC file (docs/can/gfins.dbc) and the generated
// sections of the ICD (docs/can-interface.md: signal tables, bus budget). Tests fail when the
// committed files differ from what the table generates.
#pragma once

#include <cstdint>
#include <string>

#include "gfins/can/message_table.hpp"
#include "gfins/can/publisher.hpp"

namespace gfins::can_tool {

/// The rates a DBC's GenMsgCycleTime attributes state: the table's defaults at 1 kHz, or what a
/// configured board sends (gfins-can dbc --config).
struct DbcRates {
  double sample_rate_hz = can::kDefaultSampleRateHz;
  can::Dividers dividers = can::default_dividers();
};

/// The DBC of one node (identifiers = base + node_id). GenMsgCycleTime of each periodic message
/// is 1000 x divider / sample rate in whole milliseconds (at least 1); a message switched off
/// has none. `ids`: the identifier groups of the board (can.*_id_base; docs/can-interface.md,
/// "Identifiers").
std::string generate_dbc(std::uint8_t node_id = can::kDefaultNodeId, const DbcRates& rates = {},
                         const can::IdBases& ids = {});

/// Markdown: one table per message with every signal's type, factor, offset, unit, range,
/// not-available value and instant.
std::string generate_signal_tables();

/// Markdown: frames/s and worst-case share of the bit rate per message at the default dividers.
std::string generate_budget_table(double sample_rate_hz, std::uint32_t bit_rate);

/// Marker lines delimiting generated blocks in docs/can-interface.md.
inline constexpr const char* kSignalsBegin =
    "<!-- generated: signal tables (gfins-can-gen icd) -->";
inline constexpr const char* kSignalsEnd = "<!-- end of generated signal tables -->";
inline constexpr const char* kBudgetBegin = "<!-- generated: bus budget (gfins-can-gen budget) -->";
inline constexpr const char* kBudgetEnd = "<!-- end of generated bus budget -->";

}  // namespace gfins::can_tool

#include <cstdio>

namespace gfins::can_tool {

/// Writes a candump log of `seconds` of a synthetic, smoothly moving board (closed-form attitude,
/// velocity and position; filter σ, mode and aiding counters, one σ beyond its range at times, one
/// aiding kind never accepted) published by the real Publisher at the default dividers, sample rate
/// `sample_rate_hz`, node `node_id`, on interface "can0", log time starting at
/// drivers::lnx::kSimulatedLogEpochS (1700000000 s). Returns false when writing failed.
bool write_synthetic_log(std::FILE* out, double seconds, double sample_rate_hz,
                         std::uint8_t node_id);

}  // namespace gfins::can_tool
