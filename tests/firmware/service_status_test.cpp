// The service status line (systemd STATUS=): its text written out here from the format
// docs/deploy.md gives, the reporter sending it through the real SystemdWatchdog over the SdApi
// fake seam (what sd_notify would be handed), and the sample loop filling the StatusBoard.
#include "gfins/app/service_status.hpp"

#include <gtest/gtest.h>

#include <cerrno>
#include <string>
#include <vector>

#include "gfins/drivers/lnx/systemd_watchdog.hpp"
#include "sim_rig.hpp"
#include "support/fake_clock.hpp"

namespace gfins::app {
namespace {

std::string text_of(const StatusSnapshot& s, double rate_hz) {
  std::array<char, kServiceStatusMax> buf{};
  const std::size_t n = format_service_status(buf, s, rate_hz);
  EXPECT_EQ(n, std::char_traits<char>::length(buf.data()));
  return buf.data();
}

TEST(ServiceStatus, AHealthyNavigatingBoardSaysSoWithRateAndCalibration) {
  StatusSnapshot s;
  s.mode = can::Mode::kNavigating;
  s.calibrated = true;
  s.cal_id = 0x4fd264c0;
  s.samples = 123456;  // not in the line: it would change the text every second
  EXPECT_EQ(text_of(s, 500.0), "navigating at 500 Hz, calibration 4fd264c0; faults: none");
}

TEST(ServiceStatus, EveryNonZeroFaultCounterIsNamedInOrder) {
  StatusSnapshot s;
  s.mode = can::Mode::kAligning;
  s.calibrated = false;
  s.missed_edges = 12;
  s.can_tx_dropped = 452;
  s.can_rx_dropped = 7;
  s.stuck_mask = 0x05;
  EXPECT_EQ(text_of(s, 1000.0),
            "aligning (keep the board still) at 1000 Hz, UNCALIBRATED (nominal parameters); "
            "faults: missed data-ready edges 12, CAN tx dropped 452, CAN rx lost 7, stuck "
            "channels 0x05");
}

TEST(ServiceStatus, EachCounterAloneAppearsUnderItsName) {
  struct Case {
    std::uint32_t StatusSnapshot::*field;
    const char* text;
  };
  const std::vector<Case> cases = {
      {&StatusSnapshot::missed_edges, "faults: missed data-ready edges 3"},
      {&StatusSnapshot::drdy_timeouts, "faults: data-ready timeouts 3"},
      {&StatusSnapshot::crc_errors, "faults: ADC CRC errors 3"},
      {&StatusSnapshot::adc_resets, "faults: ADC resets 3"},
      {&StatusSnapshot::can_tx_dropped, "faults: CAN tx dropped 3"},
      {&StatusSnapshot::can_rx_dropped, "faults: CAN rx lost 3"},
      {&StatusSnapshot::bus_off_events, "faults: bus-off 3"},
      {&StatusSnapshot::loop_overruns, "faults: loop overruns 3"},
      {&StatusSnapshot::stuck_mask, "faults: stuck channels 0x03"},
  };
  for (const Case& c : cases) {
    StatusSnapshot s;
    s.mode = can::Mode::kNavigating;
    s.degraded = true;
    s.*c.field = 3;
    const std::string t = text_of(s, 2000.0);
    EXPECT_EQ(t, std::string("DEGRADED (navigating on a faulty input) at 2000 Hz, UNCALIBRATED "
                             "(nominal parameters); ") +
                     c.text)
        << t;
  }
}

TEST(ServiceStatus, TheLongestLineFitsAndAShortBufferIsCutAndTerminated) {
  StatusSnapshot s;
  s.mode = can::Mode::kNavigating;
  s.degraded = true;
  s.calibrated = true;
  s.cal_id = 0xffffffffu;
  for (auto* f : {&s.missed_edges, &s.drdy_timeouts, &s.crc_errors, &s.adc_resets,
                  &s.can_tx_dropped, &s.can_rx_dropped, &s.bus_off_events, &s.loop_overruns}) {
    *f = 4294967295u;
  }
  s.stuck_mask = 0x3f;
  const std::string full = text_of(s, 4000.0);
  EXPECT_LT(full.size() + 1, kServiceStatusMax);  // nothing cut at the real size
  EXPECT_NE(full.find("loop overruns 4294967295, stuck channels 0x3f"), std::string::npos);

  std::array<char, 16> small{};
  small.fill('x');
  EXPECT_EQ(format_service_status(small, s, 4000.0), small.size() - 1);
  EXPECT_EQ(std::string(small.data()), full.substr(0, small.size() - 1));
}

// libsystemd as SystemdWatchdog calls it: started by systemd (NOTIFY_SOCKET set), no watchdog,
// every state string handed to sd_notify recorded; `refuse` makes sd_notify fail.
class RecordingSd : public drivers::lnx::SdApi {
 public:
  int watchdog_enabled(std::uint64_t* usec) override {
    *usec = 0;
    return 0;
  }
  int notify(const char* state) override {
    if (refuse) return -ECONNREFUSED;
    sent.emplace_back(state);
    return 1;
  }
  bool has_notify_socket() override { return true; }
  std::vector<std::string> sent;
  bool refuse = false;
};

TEST(StatusReporter, SendsStatusThroughSdNotifyOnlyWhenTheLineChanges) {
  // Given the systemd backend over the recording seam and a board the loop filled
  RecordingSd sd;
  gfins::testing::FakeClock clock;
  auto wd = drivers::lnx::SystemdWatchdog::open(clock, sd);
  ASSERT_TRUE(wd.is_ok()) << wd.status().message();
  StatusBoard board;
  HealthCounters h;
  h.samples = 10;
  board.publish(can::Mode::kAligning, false, true, 0x1234abcd, h);
  StatusReporter reporter(*wd.value(), board, 500.0);

  // When it reports twice with nothing changed, then after an edge was missed
  ASSERT_TRUE(reporter.report_now().is_ok());
  h.samples = 510;  // only the sample count moved: the same line
  board.publish(can::Mode::kAligning, false, true, 0x1234abcd, h);
  ASSERT_TRUE(reporter.report_now().is_ok());
  h.missed_edges = 1;
  board.publish(can::Mode::kNavigating, false, true, 0x1234abcd, h);
  ASSERT_TRUE(reporter.report_now().is_ok());

  // Then sd_notify got two STATUS= assignments, each the whole line
  EXPECT_EQ(sd.sent, (std::vector<std::string>{
                         "STATUS=aligning (keep the board still) at 500 Hz, calibration 1234abcd; "
                         "faults: none",
                         "STATUS=navigating at 500 Hz, calibration 1234abcd; faults: missed "
                         "data-ready edges 1"}));
  EXPECT_EQ(reporter.sent(), 2u);
  EXPECT_STREQ(reporter.last_sent(),
               "navigating at 500 Hz, calibration 1234abcd; faults: missed data-ready edges 1");
}

TEST(StatusReporter, ARefusedNotificationIsCountedAndRetriedNextTime) {
  RecordingSd sd;
  gfins::testing::FakeClock clock;
  auto wd = drivers::lnx::SystemdWatchdog::open(clock, sd);
  ASSERT_TRUE(wd.is_ok());
  StatusBoard board;
  StatusReporter reporter(*wd.value(), board, 1000.0);
  sd.refuse = true;
  const Status s = reporter.report_now();
  EXPECT_EQ(s.code(), ErrorCode::kIoError);
  EXPECT_EQ(s.os_error(), ECONNREFUSED);
  EXPECT_EQ(reporter.failures(), 1u);
  EXPECT_EQ(reporter.sent(), 0u);
  sd.refuse = false;  // the same line is sent once the manager takes it
  ASSERT_TRUE(reporter.report_now().is_ok());
  EXPECT_EQ(sd.sent, (std::vector<std::string>{
                         "STATUS=starting (no sample yet) at 1000 Hz, UNCALIBRATED (nominal "
                         "parameters); faults: none"}));
}

TEST(StatusReporter, TheThreadReportsAtStartAndStopsWhenAsked) {
  RecordingSd sd;
  gfins::testing::FakeClock clock;
  auto wd = drivers::lnx::SystemdWatchdog::open(clock, sd);
  ASSERT_TRUE(wd.is_ok());
  StatusBoard board;
  StatusReporter reporter(*wd.value(), board, 500.0, std::chrono::milliseconds(1));
  reporter.start();
  // The first report is made before the thread's first wait; stop() joins the thread, so
  // reading what the seam recorded afterwards races with nothing.
  while (reporter.sent() == 0) std::this_thread::yield();
  reporter.stop();
  const std::size_t n = sd.sent.size();
  EXPECT_EQ(n, 1u);  // the line never changed: sent once however often the thread woke
  EXPECT_EQ(reporter.sent(), 1u);
}

TEST(StatusReporter, TheLoopFillsTheBoardWithItsModeCalibrationAndHealth) {
  // Given the simulated board with missing data-ready edges after the 1 s alignment
  sim_board::FaultPlan f;
  f.missing_edges = {1500, 1501};
  gfins::testing::SimRig rig("rest", 2.0, f);
  StatusBoard board;
  rig.loop->set_status_board(&board);
  rig.configure();
  // When the loop runs to the end
  rig.run();
  // Then the board holds what the loop itself reports
  const StatusSnapshot s = board.read();
  EXPECT_EQ(s.mode, can::Mode::kNavigating);
  EXPECT_EQ(s.mode, rig.loop->mode());
  EXPECT_TRUE(s.calibrated);
  EXPECT_EQ(s.cal_id, calib_file::cal_id_of(rig.factory));
  EXPECT_EQ(s.samples, rig.samples - 2);  // every edge but the two the plan removed
  EXPECT_EQ(s.missed_edges, 2u);
  EXPECT_EQ(s.crc_errors, 0u);
  EXPECT_EQ(s.can_tx_dropped, 0u);
}

}  // namespace
}  // namespace gfins::app
