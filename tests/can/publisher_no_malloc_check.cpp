// The publisher and the command codec run in the firmware's sample loop: no heap (every heap call
// of the process counted in the window, support/heap_counter.hpp).
#include <gtest/gtest.h>

#include "fake_bus.hpp"
#include "gfins/can/command.hpp"
#include "gfins/can/publisher.hpp"
#include "support/heap_counter.hpp"

namespace gfins::can {
namespace {

TEST(PublisherNoMalloc, PublishAndCommandsDoNotAllocate) {
  if (!gfins::testing::HeapCounter::available()) GTEST_SKIP() << "AddressSanitizer owns malloc";
  testing::ArrayBus<4096> bus;
  Publisher pub(bus, PublisherConfig{});
  ASSERT_TRUE(pub.set_divider(MessageId::kSensorsA, 10).is_ok());
  Epoch e;
  const hal::CanFrame cmd = encode_command(Command{}, 0);
  long allocations = 0;
  {
    const gfins::testing::HeapWindow window;
    for (std::uint32_t seq = 0; seq < 2000; ++seq) {
      e.nav.seq = seq;
      e.nav.v_n.x() = static_cast<float>(seq);  // saturates after 320: the flag path too
      pub.publish(e);
    }
    const DecodedCommand d = decode_command(cmd, 0);
    const hal::CanFrame r = encode_response(Response{1, d.command.token, ResultCode::kOk, 0}, 0);
    (void)r;
    allocations = window.allocations();
  }
  EXPECT_EQ(allocations, 0);
  EXPECT_GT(bus.count, 1000u);
}

}  // namespace
}  // namespace gfins::can
