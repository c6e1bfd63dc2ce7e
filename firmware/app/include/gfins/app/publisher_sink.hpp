// The board's epoch sink: the CAN protocol's Publisher (rate dividers + message table →
// hal::CanBus). Allocation-free, like everything the loop calls.
#pragma once

#include <cstdint>

#include "gfins/app/config.hpp"
#include "gfins/app/ports.hpp"
#include "gfins/can/epoch.hpp"
#include "gfins/can/publisher.hpp"

namespace gfins::app {

/// Publisher dividers from the configuration's [output] (index = can::MessageId), with the
/// filter's messages at the table's rates when aiding is on.
can::Dividers bus_dividers(const FwConfig& c);
/// The bus the configuration describes (adc.sample_rate_hz, can.bit_rate,
/// can.max_bus_load_percent): SetDivider is refused beyond it, as the configuration is.
can::BusBudget bus_budget(const FwConfig& c);
/// The identifier groups of the configuration (can.data_id_base, ...).
can::IdBases id_bases(const FwConfig& c);

class PublisherSink final : public EpochSink {
 public:
  PublisherSink(hal::CanBus& bus, std::uint8_t node_id, const can::Dividers& dividers,
                const can::BusBudget& budget = {}, const can::IdBases& ids = {});
  std::uint32_t publish(const can::Epoch& e) override;
  Status set_divider(std::size_t message, std::uint16_t divider) override;
  Status set_dividers(const std::array<std::uint16_t, kNumMessages>& dividers) override;
  const can::Publisher& publisher() const { return publisher_; }

 private:
  can::Publisher publisher_;
};

}  // namespace gfins::app
