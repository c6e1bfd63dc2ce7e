#include "gfins/app/publisher_sink.hpp"

#include <algorithm>

namespace gfins::app {

static_assert(kNumMessages == static_cast<std::size_t>(can::MessageId::kCommand),
              "[output] names one divider per data message of the CAN table, in its order");

can::Dividers bus_dividers(const FwConfig& c) {
  can::Dividers d{};
  for (std::size_t m = 0; m < kNumMessages; ++m) d[m] = c.dividers[m];
  // With aiding on, the filter's accuracy and aiding counters go out at the table's rates
  // (GfinsAccuracy 5 Hz, GfinsAidingCounters 2.5 Hz at 1 kHz), rounded up to a multiple of the
  // epoch divider as every message must be; without a filter they have nothing to say.
  const std::uint32_t epoch = std::max<std::uint32_t>(c.dividers[0], 1);
  // The command counters (1 Hz at 1 kHz) go out on every board: they say where the CAN settings
  // came from even when no command was sent.
  for (const can::MessageId id : {can::MessageId::kAccuracy, can::MessageId::kAidingCounters,
                                  can::MessageId::kCommandCounters}) {
    const std::uint32_t table = can::message(id).default_divider;
    const std::uint32_t div = (table + epoch - 1) / epoch * epoch;
    const bool on = c.aiding || id == can::MessageId::kCommandCounters;
    d[static_cast<std::size_t>(id)] =
        on ? static_cast<std::uint16_t>(std::min<std::uint32_t>(div, kMaxDivider)) : 0;
  }
  return d;
}

can::BusBudget bus_budget(const FwConfig& c) {
  return can::BusBudget{c.sample_rate_hz, static_cast<std::uint32_t>(c.can_bit_rate),
                        c.max_bus_load_percent / 100.0};
}

double worst_case_bus_load(const FwConfig& c) { return bus_budget(c).load(bus_dividers(c)); }

PublisherSink::PublisherSink(hal::CanBus& bus, std::uint8_t node_id, const can::Dividers& dividers,
                             const can::BusBudget& budget)
    : publisher_(bus, can::PublisherConfig{node_id, dividers, budget}) {}

std::uint32_t PublisherSink::publish(const can::Epoch& e) {
  const can::PublisherCounters before = publisher_.counters();
  publisher_.publish(e);
  const can::PublisherCounters& after = publisher_.counters();
  return (after.frames_sent - before.frames_sent) + (after.send_failures - before.send_failures);
}

Status PublisherSink::set_divider(std::size_t message, std::uint16_t divider) {
  if (message >= kNumMessages) return Status(ErrorCode::kOutOfRange, "no such data message");
  return publisher_.set_divider(static_cast<can::MessageId>(message), divider);
}

Status PublisherSink::set_dividers(const std::array<std::uint16_t, kNumMessages>& dividers) {
  can::Dividers d = publisher_.dividers();
  for (std::size_t m = 0; m < kNumMessages; ++m) d[m] = dividers[m];
  return publisher_.set_dividers(d);
}

}  // namespace gfins::app
