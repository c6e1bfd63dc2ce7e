#include "gfins/app/publisher_sink.hpp"

#include <algorithm>
#include <array>

namespace gfins::app {

static_assert(kNumMessages == static_cast<std::size_t>(can::MessageId::kCommand),
              "[output] names one divider per data message of the CAN table, in its order");

namespace {

// The messages whose divider the board derives from the epoch's instead of taking it from
// [output]: the filter's accuracy and aiding counters (with aiding on) and the command counters
// (always), at the table's rates rounded up to a multiple of the epoch divider, as every message
// must be (the largest such multiple within kMaxDivider when that is less).
constexpr std::array<can::MessageId, 3> kDerived = {
    can::MessageId::kAccuracy, can::MessageId::kAidingCounters, can::MessageId::kCommandCounters};

void follow_epoch(can::Dividers& d, bool aiding) {
  const std::uint32_t epoch = std::max<std::uint32_t>(d[0], 1);
  for (const can::MessageId id : kDerived) {
    const bool on = aiding || id == can::MessageId::kCommandCounters;
    const std::uint32_t table = can::message(id).default_divider;
    const std::uint32_t up = (table + epoch - 1) / epoch * epoch;
    const std::uint32_t fit = kMaxDivider / epoch * epoch;
    d[static_cast<std::size_t>(id)] = on ? static_cast<std::uint16_t>(std::min(up, fit)) : 0;
  }
}

}  // namespace

can::Dividers bus_dividers(const FwConfig& c) {
  can::Dividers d{};
  for (std::size_t m = 0; m < kNumMessages; ++m) d[m] = c.dividers[m];
  follow_epoch(d, c.aiding);
  return d;
}

can::BusBudget bus_budget(const FwConfig& c) {
  return can::BusBudget{c.sample_rate_hz, static_cast<std::uint32_t>(c.can_bit_rate),
                        c.max_bus_load_percent / 100.0};
}

can::IdBases id_bases(const FwConfig& c) {
  can::IdBases b;
  for (std::size_t g = 0; g < can::kIdGroupCount; ++g) {
    b.base[g] = static_cast<std::uint16_t>(c.id_bases[g]);
  }
  return b;
}

double worst_case_bus_load(const FwConfig& c) { return bus_budget(c).load(bus_dividers(c)); }

PublisherSink::PublisherSink(hal::CanBus& bus, std::uint8_t node_id, const can::Dividers& dividers,
                             const can::BusBudget& budget, const can::IdBases& ids)
    : publisher_(bus, can::PublisherConfig{node_id, ids, dividers, budget}) {}

std::uint32_t PublisherSink::publish(const can::Epoch& e) {
  const can::PublisherCounters before = publisher_.counters();
  publisher_.publish(e);
  const can::PublisherCounters& after = publisher_.counters();
  return (after.frames_sent - before.frames_sent) + (after.send_failures - before.send_failures);
}

Status PublisherSink::set_divider(std::size_t message, std::uint16_t divider) {
  if (message >= kNumMessages) return Status(ErrorCode::kOutOfRange, "no such data message");
  const auto status = static_cast<std::size_t>(can::MessageId::kStatus);
  if (message == status) {
    return Status(ErrorCode::kInvalidArgument, "can: the Status divider follows the Epoch's");
  }
  std::array<std::uint16_t, kNumMessages> d{};
  for (std::size_t m = 0; m < kNumMessages; ++m) d[m] = publisher_.dividers()[m];
  d[message] = divider;
  // Changing the epoch divider moves the status frame with it.
  if (message == 0) d[status] = divider;
  return set_dividers(d);
}

Status PublisherSink::set_dividers(const std::array<std::uint16_t, kNumMessages>& dividers) {
  can::Dividers d = publisher_.dividers();
  const bool aiding = d[static_cast<std::size_t>(can::MessageId::kAccuracy)] != 0;
  for (std::size_t m = 0; m < kNumMessages; ++m) d[m] = dividers[m];
  // The derived messages follow a new epoch divider instead of blocking it.
  follow_epoch(d, aiding);
  return publisher_.set_dividers(d);
}

}  // namespace gfins::app
