// The firmware's seams onto the CAN protocol (firmware/can): the epoch sink is the protocol's
// Publisher (rate dividers + message table → hal::CanBus), the command codec its
// decode_command / encode_response. Allocation-free, like everything the loop calls.
#pragma once

#include <cstdint>

#include "gfins/app/config.hpp"
#include "gfins/app/ports.hpp"
#include "gfins/can/epoch.hpp"
#include "gfins/can/publisher.hpp"

namespace gfins::app {

/// The protocol's epoch from the firmware's (mode, status bits and health mapped).
can::Epoch to_can_epoch(const Epoch& e);

/// Publisher dividers from the configuration's [output] (index = can::MessageId).
can::Dividers to_can_dividers(const FwConfig& c);

class CanEpochSink final : public EpochSink {
 public:
  CanEpochSink(hal::CanBus& bus, std::uint8_t node_id, const can::Dividers& dividers);
  std::uint32_t publish(const Epoch& e) override;
  Status set_divider(std::size_t message, std::uint16_t divider) override;
  const can::Publisher& publisher() const { return publisher_; }

 private:
  can::Publisher publisher_;
};

class CanCommandCodec final : public CommandCodec {
 public:
  explicit CanCommandCodec(std::uint8_t node_id) : node_id_(node_id) {}
  DecodedFrame decode(const hal::CanFrame& f) const override;
  std::size_t encode(const Response& r, std::array<hal::CanFrame, 24>& frames) const override;

 private:
  std::uint8_t node_id_;
};

}  // namespace gfins::app
