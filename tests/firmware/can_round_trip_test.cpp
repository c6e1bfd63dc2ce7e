// The simulated board's CAN output, decoded (docs/can-interface.md): every data frame's CRC is
// valid, its counter ties it to its epoch, and every navigation value equals the NavState the
// loop handed to the publisher within that signal's quantisation (factor/2, or the documented
// limit for a clipped value). And each command, valid and malformed, as frames in and response
// frames out.
#include <gtest/gtest.h>
#include <unistd.h>

#include <optional>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>

#include "gfins/app/reload_worker.hpp"
#include "gfins/calib_file/calibration_file.hpp"
#include "gfins/can/command.hpp"
#include "gfins/can/message_table.hpp"
#include "gfins/can/signal_codec.hpp"
#include "sim_rig.hpp"

namespace gfins::app {
namespace {

using testing::SimRig;

// The value a signal should carry for an epoch, read here from the NavState and the firmware's
// epoch (not from the publisher's own field accessor) for every navigation and health field.
double expected_value(const can::Epoch& e, const can::SignalDef& s) {
  const auto& n = e.nav;
  const int i = s.index;
  // A navigation group the epoch does not stand behind (aligning) goes out as not available.
  constexpr double kNa = std::numeric_limits<double>::quiet_NaN();
  switch (s.field) {
    case can::Field::kQuaternion:
    case can::Field::kEuler:
      if (!e.valid.attitude) return kNa;
      break;
    case can::Field::kRate:
      if (!e.valid.rate) return kNa;
      break;
    case can::Field::kAngularAccel:
      if (!e.valid.angular_accel) return kNa;
      break;
    case can::Field::kAccel:
      if (!e.valid.accel) return kNa;
      break;
    case can::Field::kVelocity:
      if (!e.valid.velocity) return kNa;
      break;
    case can::Field::kPosition:
      if (!e.valid.position) return kNa;
      break;
    default:
      break;
  }
  switch (s.field) {
    case can::Field::kVelocity:
      return static_cast<double>(n.v_n(i));
    case can::Field::kPosition:
      return static_cast<double>(n.r_n(i));
    case can::Field::kRate:
      return static_cast<double>(n.w_b(i));
    case can::Field::kAngularAccel:
      return static_cast<double>(n.wdot_b(i));
    case can::Field::kAccel:
      return static_cast<double>(n.f_b(i));
    case can::Field::kQuaternion: {
      const float c[4] = {n.q_nb.w(), n.q_nb.x(), n.q_nb.y(), n.q_nb.z()};
      return (n.q_nb.w() < 0 ? -1.0 : 1.0) *
             static_cast<double>(c[i]);  // the bus carries the w >= 0 one
    }
    case can::Field::kSensorAccel:
      return static_cast<double>(e.accel_mps2[static_cast<std::size_t>(i)]);
    case can::Field::kCalId:
      return e.cal_id;
    case can::Field::kMissedEdges:
      return e.health.missed_drdy_edges;
    case can::Field::kAdcCrcErrors:
      return e.health.adc_crc_errors;
    case can::Field::kAdcResets:
      return e.health.adc_resets;
    case can::Field::kSaturatedSamples:
      return e.health.saturated_samples;
    case can::Field::kCanTxDropped:
      return e.health.can_tx_dropped;
    case can::Field::kBusOffEvents:
      return e.health.bus_off_events;
    case can::Field::kLoopOverruns:
      return e.health.loop_overruns;
    case can::Field::kStatusFlags: {
      // The publisher flags an epoch whose navigation values went out as not available
      // (docs/can-interface.md, StatusFlags bit 5): every group while aligning.
      const can::Validity& v = e.valid;
      const bool any_na =
          !(v.attitude && v.rate && v.angular_accel && v.accel && v.velocity && v.position);
      return can::epoch_field(e, s.field, s.index) +
             (any_na ? static_cast<double>(can::status_bits::kCanNotAvailable) : 0.0);
    }
    default:  // Euler angles, mode, time: the protocol's own mapping
      return can::epoch_field(e, s.field, s.index);
  }
}

TEST(CanOutput, DecodedFramesEqualTheNavStateWithinQuantisation) {
  SimRig rig("rest", 3.0);
  rig.configure();
  rig.run();
  const auto frames = rig.bus->sent();
  ASSERT_GT(frames.size(), 1000u);
  std::size_t epoch_index = 0, compared = 0;
  const can::Epoch* current = nullptr;
  std::int64_t last_counter = -1;
  for (const hal::CanFrame& f : frames) {
    std::uint8_t node = 0;
    const can::MessageDef* m = can::find_message(f.id, &node);
    ASSERT_NE(m, nullptr) << std::hex << f.id;
    ASSERT_EQ(node, SimRig::kNode);
    ASSERT_TRUE(can::crc_ok(f)) << m->name;
    const std::uint64_t p = can::payload_of(f);
    std::int64_t counter = -1;
    for (const auto& s : m->signals) {
      if (s.field == can::Field::kCounter)
        counter = static_cast<std::int64_t>(can::extract_bits(p, s));
    }
    if (m->id == can::MessageId::kEpoch) {
      // The epoch frame opens an epoch: find it by its 16-bit sample count, in order.
      const auto& sc = m->signals[can::signal_index(*m, "SampleCount")];
      const auto count = static_cast<std::uint32_t>(can::extract_bits(p, sc));
      const auto& epochs = rig.recording->epochs();
      while (epoch_index < epochs.size() && (epochs[epoch_index].nav.seq & 0xFFFFu) != count) {
        ++epoch_index;
      }
      ASSERT_LT(epoch_index, epochs.size()) << "no epoch with sample count " << count;
      current = &epochs[epoch_index];
      if (last_counter >= 0) {
        EXPECT_EQ(counter, (last_counter + 1) % 16);  // continuous
      }
      last_counter = counter;
    }
    ASSERT_NE(current, nullptr);
    EXPECT_EQ(counter, last_counter) << m->name << ": counter ties the frame to its epoch";
    for (const auto& s : m->signals) {
      if (s.field == can::Field::kCounter || s.field == can::Field::kCrc) continue;
      const std::uint64_t bits = can::extract_bits(p, s);
      const double x = expected_value(*current, s);
      if (s.overflow == can::Overflow::kWrap) {
        const double m2 = std::ldexp(1.0, s.length);
        double want = std::fmod(std::floor((x - s.offset) / s.factor + 0.5), m2);
        if (want < 0) want += m2;
        EXPECT_EQ(static_cast<double>(bits), want) << m->name << "." << s.name;
      } else if (std::isnan(x)) {
        // Not available (a filter σ while no filter runs): the N/A code, decoded as NaN.
        EXPECT_TRUE(std::isnan(can::decode_signal(s, bits))) << m->name << "." << s.name;
      } else {
        const double got = can::decode_signal(s, bits);
        const double clipped = std::clamp(x, s.min, s.max);
        // round to nearest: at most half a step (a σ rounds up: less than one step), plus the
        // float→double rounding of the value
        const double step = s.round_up ? s.factor : 0.5 * s.factor;
        EXPECT_LE(std::abs(got - clipped), step * (1 + 1e-9) + 1e-9 * std::abs(x))
            << m->name << "." << s.name << " seq " << current->nav.seq;
      }
      ++compared;
    }
  }
  EXPECT_GT(compared, 5000u);  // 300 epochs of about 24 signals each
}

// ---- Commands as frames ---------------------------------------------------------------------

// Sequence numbers for the configuration-changing commands these tests send: each frame gets the
// next one, so only a test that means to repeat a number does (docs/can-interface.md, "Sequence
// numbers"). Every test starts a new board, whose last number is 0.
std::uint16_t next_sequence() {
  static std::uint16_t n = 0;
  return ++n;
}

// A board with its identifier groups moved (can.*_id_base; docs/can-interface.md, "Identifiers")
// to data 0x300, inputs 0x2A0, command 0x700, response 0x710: the identifiers asked below are
// written out here from those bases and the ICD's offsets (GfinsEpoch first of the data group,
// the command and the response the only ones of theirs), not computed by the codec.
TEST(CanIdentifiers, ABoardWithMovedGroupsAnswersAndSendsOnlyThere) {
  SimRig rig("rest", 3.0);
  rig.move_ids({0x300, 0x2A0, 0x700, 0x710});
  rig.configure();
  rig.run_cycles(1500);
  ASSERT_EQ(rig.loop->mode(), can::Mode::kNavigating);
  const can::IdBases moved{{0x300, 0x2A0, 0x700, 0x710}};
  can::Command ask;
  ask.opcode = can::Opcode::kReportCalibrationId;
  ask.token = 41;
  // The stock command identifier 0x601 carries other equipment's traffic now (an OxTS RT frame
  // lands there): a frame there, even a valid gfins command, draws no answer at all.
  const hal::CanFrame stock = can::encode_command(ask, SimRig::kNode);
  ASSERT_EQ(stock.id, 0x601u);
  const std::uint32_t done = rig.loop->health().commands;
  rig.bus->clear_sent();
  ASSERT_TRUE(rig.bus->inject_rx(stock));
  hal::CanFrame foreign{};  // an OxTS-like frame: 8 bytes that are no gfins command at all
  foreign.id = 0x601;
  foreign.len = 8;
  foreign.data = {0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77, 0x88};
  ASSERT_TRUE(rig.bus->inject_rx(foreign));
  rig.run_cycles(4);
  for (const hal::CanFrame& f : rig.bus->sent()) {
    EXPECT_FALSE(f.id >= 0x680 && f.id <= 0x68F) << "a response at the stock identifiers";
    EXPECT_FALSE(f.id >= 0x710 && f.id <= 0x71F) << "an answer to a frame that is not ours";
  }
  EXPECT_EQ(rig.loop->health().commands, done);
  EXPECT_EQ(rig.loop->health().command_errors, 0u);
  // The same command at 0x701 is answered at 0x711 (status part, then the calibration id).
  const hal::CanFrame ours = can::encode_command(ask, SimRig::kNode, moved);
  ASSERT_EQ(ours.id, 0x701u);
  rig.bus->clear_sent();
  ASSERT_TRUE(rig.bus->inject_rx(ours));
  rig.run_cycles(12);  // the answer, and an epoch (divider 10) at least
  int answers = 0;
  bool epoch_at_moved = false, anything_at_stock = false;
  for (const hal::CanFrame& f : rig.bus->sent()) {
    if (f.id == 0x711) {
      const auto r = can::decode_response(f, moved);
      ASSERT_TRUE(r.is_ok()) << r.status().message();
      EXPECT_EQ(r->token, 41);
      ++answers;
    }
    if (f.id == 0x301) epoch_at_moved = true;
    // Nothing at the stock data identifiers 0x101..0x20F of node 1 or the stock responses.
    if ((f.id >= 0x100 && f.id <= 0x20F) || (f.id >= 0x680 && f.id <= 0x68F)) {
      anything_at_stock = true;
    }
  }
  EXPECT_EQ(answers, 2);
  EXPECT_TRUE(epoch_at_moved);
  EXPECT_FALSE(anything_at_stock);
  EXPECT_EQ(rig.loop->health().commands, done + 1);
}

class CanCommands : public ::testing::Test {
 protected:
  void SetUp() override {
    rig_ = std::make_unique<SimRig>("rest", 10.0);
    // One file per test and process: ctest runs the cases of this fixture in parallel, and a
    // shared name let one case's save land in another's reload.
    const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = std::filesystem::temp_directory_path() / ("gfins_fw_cal_" + std::string(info->name()) +
                                                      "_" + std::to_string(::getpid()) + ".toml");
    rig_->config.calibration_file = path_.string();
    // The board runs on its factory calibration: a reload must be of the same device.
    worker_ = std::make_unique<ReloadWorker>(
        calibration_reloader(rig_->config, std::nullopt, rig_->factory.device_id));
    rig_->loop->set_reload_worker(worker_.get());
    rig_->configure();
    rig_->run_cycles(1500);
    ASSERT_EQ(rig_->loop->mode(), can::Mode::kNavigating);
  }
  void TearDown() override { std::filesystem::remove(path_); }

  // Sends one frame to the board, runs `cycles` cycles, returns the responses decoded.
  std::vector<can::ResponseFrame> round_trip(const hal::CanFrame& f, std::uint32_t cycles = 2) {
    rig_->bus->clear_sent();
    EXPECT_TRUE(rig_->bus->inject_rx(f));
    return round_trip_cycles(cycles, false);
  }
  // Runs `cycles` cycles and returns the responses sent in them.
  std::vector<can::ResponseFrame> round_trip_cycles(std::uint32_t cycles, bool clear = true) {
    if (clear) rig_->bus->clear_sent();
    rig_->run_cycles(cycles);
    std::vector<can::ResponseFrame> out;
    for (const hal::CanFrame& r : rig_->bus->sent()) {
      const auto d = can::decode_response(r);
      if (d.is_ok()) out.push_back(d.value());
    }
    return out;
  }
  std::vector<can::ResponseFrame> send(can::Command c, std::uint32_t cycles = 2) {
    c.sequence = next_sequence();
    return round_trip(can::encode_command(c, SimRig::kNode), cycles);
  }
  // A reload command: the cycle that reads it posts the request to the worker thread (the loop
  // never waits for file I/O); the first cycle after the worker is done answers. Ordering, not
  // timing: the test waits for the worker, whatever the machine's speed.
  std::vector<can::ResponseFrame> reload(std::uint8_t token, bool forced = false) {
    can::Command c = cmd(can::Opcode::kReloadCalibration, token);
    c.forced = forced;
    auto r = send(c, 1);
    worker_->wait_settled();
    auto more = round_trip_cycles(1);
    r.insert(r.end(), more.begin(), more.end());
    return r;
  }
  static const can::ResponseFrame* part(const std::vector<can::ResponseFrame>& v, int p) {
    for (const auto& r : v) {
      if (r.part == p) return &r;
    }
    return nullptr;
  }
  // Frames of message `m` the board sends in the next `cycles` samples (its divider at work).
  std::size_t frames_per(can::MessageId m, std::uint32_t cycles) {
    rig_->bus->clear_sent();
    rig_->run_cycles(cycles);
    std::size_t n = 0;
    for (const hal::CanFrame& f : rig_->bus->sent()) {
      const can::MessageDef* d = can::find_message(f.id, nullptr);
      if (d != nullptr && d->id == m) ++n;
    }
    return n;
  }
  static can::Command cmd(can::Opcode op, std::uint8_t token) {
    can::Command c;
    c.opcode = op;
    c.token = token;
    c.sequence = next_sequence();
    return c;
  }

  std::unique_ptr<SimRig> rig_;
  std::unique_ptr<ReloadWorker> worker_;
  std::filesystem::path path_;
};

TEST_F(CanCommands, Realign) {
  can::Command c = cmd(can::Opcode::kRealign, 11);
  c.heading_rad = 0.25f;
  const auto r = send(c);
  ASSERT_NE(part(r, 0), nullptr);
  EXPECT_EQ(part(r, 0)->result, can::ResultCode::kOk);
  EXPECT_EQ(part(r, 0)->token, 11);
  EXPECT_EQ(rig_->loop->mode(), can::Mode::kAligning);
  EXPECT_NEAR(rig_->loop->pipeline().config().heading_rad, 0.25f, 1e-3f);  // heading signal step
}

TEST_F(CanCommands, ResetNavigation) {
  const auto r = send(cmd(can::Opcode::kResetNavigation, 12));
  ASSERT_NE(part(r, 0), nullptr);
  EXPECT_EQ(part(r, 0)->result, can::ResultCode::kOk);
  EXPECT_EQ(rig_->loop->mode(), can::Mode::kAligning);
}

TEST_F(CanCommands, SetCompensatorValidAndOutOfRange) {
  can::Command c = cmd(can::Opcode::kSetCompensator, 13);
  c.compensator = nav::CompensatorKind::kExact;
  auto r = send(c);
  ASSERT_NE(part(r, 0), nullptr);
  EXPECT_EQ(part(r, 0)->result, can::ResultCode::kOk);
  EXPECT_EQ(rig_->loop->pipeline().config().compensator, nav::CompensatorKind::kExact);
  c.compensator = static_cast<nav::CompensatorKind>(3);  // beyond none/paper/exact
  r = send(c);
  ASSERT_NE(part(r, 0), nullptr);
  EXPECT_EQ(part(r, 0)->result, can::ResultCode::kOutOfRange);
  EXPECT_EQ(rig_->loop->pipeline().config().compensator, nav::CompensatorKind::kExact);
}

TEST_F(CanCommands, SetDividerValidAndAgainstTheTableRules) {
  can::Command c = cmd(can::Opcode::kSetDivider, 14);
  c.message = can::MessageId::kEuler;
  c.divider = 40;
  auto r = send(c);
  ASSERT_NE(part(r, 0), nullptr);
  EXPECT_EQ(part(r, 0)->result, can::ResultCode::kOk);
  EXPECT_EQ(part(r, 0)->value, 40u);
  EXPECT_EQ(frames_per(can::MessageId::kEuler, 400), 10u);  // every 40 samples now
  c.divider = 15;  // not a multiple of the epoch divider (10)
  r = send(c);
  ASSERT_NE(part(r, 0), nullptr);
  EXPECT_EQ(part(r, 0)->result, can::ResultCode::kOutOfRange);
  // ... and the refused divider changed nothing: still every 40 samples, not every 15 or 20.
  EXPECT_EQ(frames_per(can::MessageId::kEuler, 400), 10u);
}

TEST_F(CanCommands, ReportCalibrationId) {
  const auto r = send(cmd(can::Opcode::kReportCalibrationId, 15));
  ASSERT_NE(part(r, 0), nullptr);
  ASSERT_NE(part(r, 1), nullptr);
  EXPECT_EQ(part(r, 0)->result, can::ResultCode::kOk);
  EXPECT_EQ(part(r, 1)->cal_id, calib_file::cal_id_of(rig_->factory));
}

TEST_F(CanCommands, CaptureSendsTheResultFrames) {
  can::Command c = cmd(can::Opcode::kStartCapture, 16);
  c.pose = 5;
  c.samples = 300;
  const auto r = send(c, 310);
  ASSERT_NE(part(r, 0), nullptr);
  EXPECT_EQ(part(r, 0)->result, can::ResultCode::kOk);
  can::CaptureAssembler a;
  for (const auto& f : r) a.add(f);
  ASSERT_TRUE(a.complete());
  EXPECT_EQ(a.result().pose, 5);
  EXPECT_EQ(a.result().samples, 300);
  for (std::size_t j = 0; j < 6; ++j) {
    EXPECT_EQ(a.result().channels[j].count, 300);
    EXPECT_FALSE(a.result().channels[j].motion);
    // The frames carry what the loop computed, within the signal's quantisation.
    const auto& mine = rig_->loop->last_capture().channels[j];
    EXPECT_NEAR(a.result().channels[j].mean_counts, mine.mean_counts,
                std::max(1.0, 1e-6 * std::abs(static_cast<double>(mine.mean_counts))));
  }
}

TEST_F(CanCommands, ReloadGoodFileThenBadFileKeepsTheLastGood) {
  // Given a valid calibration file of this board (the factory one, recalibrated: a new date and
  // a slightly different bias, so a new calibration id)
  calib_file::CalibrationData d = rig_->factory;
  d.created_utc = "2026-01-01T00:00:00Z";
  d.sensors[0].bias_g += 1e-5;
  ASSERT_NE(calib_file::cal_id_of(d), calib_file::cal_id_of(rig_->factory));
  ASSERT_TRUE(calib_file::save_calibration_file(path_, d).is_ok());
  auto r = reload(17);
  ASSERT_NE(part(r, 0), nullptr);
  EXPECT_EQ(part(r, 0)->result, can::ResultCode::kOk);
  ASSERT_NE(part(r, 1), nullptr);
  EXPECT_EQ(part(r, 1)->cal_id, calib_file::cal_id_of(d));
  EXPECT_EQ(rig_->loop->cal_id(), calib_file::cal_id_of(d));
  // When the file is then corrupted (truncated) and reloaded
  {
    std::FILE* f = std::fopen(path_.c_str(), "w");
    std::fputs("[calibration\n", f);
    std::fclose(f);
  }
  r = reload(18);
  // Then the board answers "failed" and keeps the last good calibration
  ASSERT_NE(part(r, 0), nullptr);
  EXPECT_EQ(part(r, 0)->result, can::ResultCode::kFailed);
  EXPECT_EQ(rig_->loop->cal_id(), calib_file::cal_id_of(d));
}

// Another board's calibration file put at this board's path, reloaded mid-navigation: refused
// with Result 12 (OtherDevice, the ICD's value), counted, the calibration in use stays; sent
// forced, it is taken. Oracle: the ids and biases the test writes.
TEST_F(CanCommands, ReloadOfAnotherBoardsFileIsRefusedUnlessForced) {
  const std::uint32_t before = rig_->loop->cal_id();
  const std::uint32_t refused = rig_->loop->health().command_errors;
  const std::uint32_t done = rig_->loop->health().commands;
  calib_file::CalibrationData other = rig_->factory;
  other.device_id = "other-board-9";
  other.sensors[1].bias_g += 2e-5;  // another board: another calibration id
  ASSERT_TRUE(calib_file::save_calibration_file(path_, other).is_ok());
  auto r = reload(21);
  ASSERT_NE(part(r, 0), nullptr);
  EXPECT_EQ(static_cast<int>(part(r, 0)->result), 12);
  EXPECT_EQ(rig_->loop->cal_id(), before);
  EXPECT_TRUE(rig_->loop->calibrated());
  EXPECT_EQ(rig_->loop->health().command_errors, refused + 1);
  EXPECT_EQ(rig_->loop->health().last_refusal, 12);
  EXPECT_EQ(rig_->loop->health().commands, done) << "a refused reload is not also done";
  r = reload(22, true);
  ASSERT_NE(part(r, 0), nullptr);
  EXPECT_EQ(part(r, 0)->result, can::ResultCode::kOk);
  EXPECT_EQ(rig_->loop->health().commands, done + 1);
  EXPECT_EQ(rig_->loop->cal_id(), calib_file::cal_id_of(other));
}

// A configuration-changing frame sent again (a log replayed onto the bus, canplayer) is refused
// with Result 11 (Replayed) and the last number taken, counted, and changes nothing; the next
// number is taken. A refused command takes its number too: sent again it is a replay.
TEST_F(CanCommands, AReplayedCommandIsRefusedAndCounted) {
  can::Command c = cmd(can::Opcode::kSetCompensator, 23);
  c.compensator = nav::CompensatorKind::kExact;
  c.sequence = 500;
  const hal::CanFrame frame = can::encode_command(c, SimRig::kNode);
  auto r = round_trip(frame);
  ASSERT_NE(part(r, 0), nullptr);
  ASSERT_EQ(part(r, 0)->result, can::ResultCode::kOk);
  // The board's compensator is changed behind the frame's back; the replay must not undo it.
  c.compensator = nav::CompensatorKind::kNone;
  c.sequence = 501;
  r = round_trip(can::encode_command(c, SimRig::kNode));
  ASSERT_EQ(part(r, 0)->result, can::ResultCode::kOk);
  const std::uint32_t done = rig_->loop->health().commands;
  r = round_trip(frame);
  ASSERT_NE(part(r, 0), nullptr);
  EXPECT_EQ(static_cast<int>(part(r, 0)->result), 11);
  EXPECT_EQ(part(r, 0)->value, 501u);
  EXPECT_EQ(rig_->loop->pipeline().config().compensator, nav::CompensatorKind::kNone);
  EXPECT_EQ(rig_->loop->health().commands_replayed, 1u);
  EXPECT_EQ(rig_->loop->health().last_refusal, 11);
  EXPECT_EQ(rig_->loop->health().commands, done);
  // An equal number is a replay as well; a lower one too.
  c.sequence = 501;
  r = round_trip(can::encode_command(c, SimRig::kNode));
  EXPECT_EQ(static_cast<int>(part(r, 0)->result), 11);
  c.sequence = 7;
  r = round_trip(can::encode_command(c, SimRig::kNode));
  EXPECT_EQ(static_cast<int>(part(r, 0)->result), 11);
  EXPECT_EQ(rig_->loop->health().commands_replayed, 3u);
  // A command refused for its argument takes its number: the same frame again is a replay.
  can::Command bad = cmd(can::Opcode::kSetDivider, 24);
  bad.message = can::MessageId::kEuler;
  bad.divider = 15;  // not a multiple of the epoch divider
  bad.sequence = 600;
  r = round_trip(can::encode_command(bad, SimRig::kNode));
  EXPECT_EQ(part(r, 0)->result, can::ResultCode::kOutOfRange);
  r = round_trip(can::encode_command(bad, SimRig::kNode));
  EXPECT_EQ(static_cast<int>(part(r, 0)->result), 11);
  // Commands that change nothing carry no number and are never replays; ReportCalibrationId's
  // status Value is the last number taken, for a host that does not track them.
  for (int i = 0; i < 2; ++i) {
    r = round_trip(can::encode_command(cmd(can::Opcode::kReportCalibrationId, 25), SimRig::kNode));
    EXPECT_EQ(part(r, 0)->result, can::ResultCode::kOk);
    EXPECT_EQ(part(r, 0)->value, 600u);
  }
  // The next number is taken.
  c.sequence = 601;
  r = round_trip(can::encode_command(c, SimRig::kNode));
  EXPECT_EQ(part(r, 0)->result, can::ResultCode::kOk);
  // What the bus says: GfinsCommandCounters (base 0x200 + node, 1 Hz) decoded from its frame
  // bytes as the ICD lays them out: done bytes 0-1, refused 2-3, replays byte 4, last refusal
  // byte 5, settings source byte 6 bits 0-1.
  rig_->bus->clear_sent();
  rig_->run_cycles(1000);
  std::optional<hal::CanFrame> counters;  // sent() returns a copy: keep the frame, not a pointer
  for (const hal::CanFrame& f : rig_->bus->sent()) {
    if (f.id == 0x200u + SimRig::kNode) counters = f;
  }
  ASSERT_TRUE(counters.has_value()) << "GfinsCommandCounters within a second";
  const auto u16 = [&](std::size_t at) {
    return counters->data[at] | (counters->data[at + 1] << 8);
  };
  EXPECT_EQ(u16(0), static_cast<int>(rig_->loop->health().commands & 0xFFFFu));
  EXPECT_EQ(u16(2), static_cast<int>(rig_->loop->health().command_errors & 0xFFFFu));
  EXPECT_EQ(counters->data[4], 4);      // four replays
  EXPECT_EQ(counters->data[5], 11);     // the last refusal: Replayed
  EXPECT_EQ(counters->data[6] & 3, 0);  // no settings store: the configuration's settings
}

TEST_F(CanCommands, MalformedFramesGetErrorResponsesAndChangeNothing) {
  const auto before = rig_->loop->pipeline().config().compensator;
  const std::uint32_t cmd_errors = rig_->loop->health().command_errors;
  can::Command c = cmd(can::Opcode::kSetCompensator, 19);
  c.compensator = nav::CompensatorKind::kExact;
  hal::CanFrame bad_crc = can::encode_command(c, SimRig::kNode);
  bad_crc.data[7] ^= 0x5A;
  auto r = round_trip(bad_crc);
  ASSERT_NE(part(r, 0), nullptr);
  EXPECT_EQ(part(r, 0)->result, can::ResultCode::kBadCrc);
  hal::CanFrame short_frame = can::encode_command(c, SimRig::kNode);
  short_frame.len = 5;
  r = round_trip(short_frame);
  ASSERT_NE(part(r, 0), nullptr);
  EXPECT_EQ(part(r, 0)->result, can::ResultCode::kBadLength);
  EXPECT_EQ(rig_->loop->pipeline().config().compensator, before);
  EXPECT_EQ(rig_->loop->health().command_errors, cmd_errors + 2);
  // A command for another node is not answered.
  r = round_trip(can::encode_command(c, SimRig::kNode + 1));
  EXPECT_EQ(part(r, 0), nullptr);
  EXPECT_EQ(rig_->loop->pipeline().config().compensator, before);
}

// ---- Every opcode, malformed, as frames on the simulated board
// -----------------------------------

// What a command could change on the board, read through the loop's public state and its bus
// output (the dividers at work).
struct BoardState {
  can::Mode mode{};
  nav::PipelinePhase phase{};
  float heading_rad = 0;
  nav::CompensatorKind compensator{};
  std::uint32_t cal_id = 0;
  bool capture_active = false;
  std::uint32_t commands = 0;  // commands carried out (health)
  bool operator==(const BoardState&) const = default;
};

// A command frame, valid but for what `edit` does to its bytes; the CRC is recomputed afterwards
// unless the edit is the CRC itself. Layout (docs/can-interface.md, GfinsCommand): byte 0
// opcode, 1 token, arguments little-endian from byte 2, byte 7 CRC-8.
hal::CanFrame edited(can::Command c, void (*edit)(hal::CanFrame&), bool reseal = true) {
  c.sequence = next_sequence();
  hal::CanFrame f = can::encode_command(c, SimRig::kNode);
  edit(f);
  if (reseal) can::seal_frame(f);
  return f;
}

class CanMalformedCommands : public CanCommands {
 protected:
  // Samples over which the Euler frames are counted: 5 at the default divider 20, 2 or 3 at 40,
  // 6 or 7 at 15 (docs/can-interface.md, default dividers): any divider change shows.
  static constexpr std::uint32_t kRateWindow = 100;
  BoardState state() const {
    const SampleLoop& l = *rig_->loop;
    return {l.mode(),
            l.pipeline().phase(),
            l.pipeline().config().heading_rad,
            l.pipeline().config().compensator,
            l.cal_id(),
            l.capture_active(),
            l.health().commands};
  }
  // Sends `f`; expects exactly one response, status part, with `want` and the frame's token,
  // one more command error, and no change of the board's state or its output rates.
  void expect_refused(const hal::CanFrame& f, can::ResultCode want, const std::string& what) {
    SCOPED_TRACE(what);
    const BoardState before = state();
    const std::uint32_t errors = rig_->loop->health().command_errors;
    const std::size_t euler = frames_per(can::MessageId::kEuler, kRateWindow);
    const auto r = round_trip(f);
    ASSERT_EQ(r.size(), 1u);
    EXPECT_EQ(r[0].part, can::kPartStatus);
    EXPECT_EQ(static_cast<int>(r[0].result), static_cast<int>(want));
    if (f.len >= 2) {
      EXPECT_EQ(r[0].token, f.data[1]);
    }
    EXPECT_EQ(rig_->loop->health().command_errors, errors + 1);
    EXPECT_EQ(state(), before);
    EXPECT_EQ(frames_per(can::MessageId::kEuler, kRateWindow), euler);  // dividers unchanged
  }
};

// The ResultCode values the ICD documents (docs/can-interface.md, "Commands and responses"),
// written here rather than taken from the codec's enum.
constexpr auto kBadLength = static_cast<can::ResultCode>(2);
constexpr auto kBadCrc = static_cast<can::ResultCode>(3);
constexpr auto kOutOfRange = static_cast<can::ResultCode>(4);
constexpr auto kMalformed = static_cast<can::ResultCode>(5);
constexpr auto kUnknownOpcode = static_cast<can::ResultCode>(1);
constexpr auto kBusy = static_cast<can::ResultCode>(6);

TEST_F(CanMalformedCommands, EveryOpcodeWithABadCrcBadLengthOrStrayBitsChangesNothing) {
  for (int op = 1; op <= 9; ++op) {
    can::Command c = cmd(static_cast<can::Opcode>(op), static_cast<std::uint8_t>(0x30 + op));
    c.heading_rad = 1.0f;  // valid arguments: only the edit makes the frame wrong
    c.compensator = nav::CompensatorKind::kPaper;
    c.message = can::MessageId::kEuler;
    c.divider = 40;
    c.pose = 2;
    c.samples = 100;
    const std::string name = "opcode " + std::to_string(op);
    expect_refused(edited(
                       c, [](hal::CanFrame& f) { f.data[7] ^= 0x5A; }, false),
                   kBadCrc, name + ", CRC");
    expect_refused(edited(c, [](hal::CanFrame& f) { f.len = 7; }), kBadLength, name + ", 7 bytes");
    // A bit the opcode does not use (ICD): byte 6 for the two without a sequence number (bytes
    // 5-6 carry it for the others), bit 39 (byte 4, bit 7) for those whose arguments end before
    // it. SetDivider uses every bit: message, divider and sequence fill bytes 2-6.
    if (op == 5 || op == 6) {
      expect_refused(edited(c, [](hal::CanFrame& f) { f.data[6] = 0x01; }), kMalformed,
                     name + ", stray bit in byte 6");
    } else if (op != 4) {
      expect_refused(edited(c, [](hal::CanFrame& f) { f.data[4] |= 0x80; }), kMalformed,
                     name + ", stray bit 39");
    }
  }
}

TEST_F(CanMalformedCommands, UnknownOpcodesChangeNothing) {
  for (const int op : {0, 11, 0x7F, 0xFF}) {
    hal::CanFrame f{};
    f.id = 0x600 + SimRig::kNode;  // GfinsCommand, 0x600 + node
    f.len = 8;
    f.data[0] = static_cast<std::uint8_t>(op);
    f.data[1] = 0x44;
    can::seal_frame(f);
    expect_refused(f, kUnknownOpcode, "opcode " + std::to_string(op));
  }
}

TEST_F(CanMalformedCommands, ArgumentsOutOfTheirRangeChangeNothing) {
  can::Command c = cmd(can::Opcode::kRealign, 0x51);
  // Heading int16 × 1e-4 rad in [-π, π] at bytes 2-3: -32768 is the not-available code, 32767
  // is 3.2767 rad > π.
  expect_refused(edited(c, [](hal::CanFrame& f) { f.data[2] = 0x00, f.data[3] = 0x80; }),
                 kOutOfRange, "realign, heading N/A");
  expect_refused(edited(c, [](hal::CanFrame& f) { f.data[2] = 0xFF, f.data[3] = 0x7F; }),
                 kOutOfRange, "realign, heading 3.2767 rad");
  c = cmd(can::Opcode::kSetCompensator, 0x52);  // byte 2: 0 none, 1 paper, 2 exact
  expect_refused(edited(c, [](hal::CanFrame& f) { f.data[2] = 3; }), kOutOfRange, "compensator 3");
  c = cmd(can::Opcode::kSetDivider, 0x53);  // byte 2 message 0..13, bytes 3-4 divider
  expect_refused(edited(c, [](hal::CanFrame& f) { f.data[2] = 14, f.data[3] = 10; }), kOutOfRange,
                 "divider of message 14");
  expect_refused(edited(c, [](hal::CanFrame& f) { f.data[2] = 1, f.data[3] = 10; }), kOutOfRange,
                 "divider of GfinsStatus (follows GfinsEpoch)");
  expect_refused(edited(c, [](hal::CanFrame& f) { f.data[2] = 3, f.data[3] = 15; }), kOutOfRange,
                 "Euler divider 15, not a multiple of the epoch's 10");
  expect_refused(edited(c, [](hal::CanFrame& f) { f.data[2] = 0, f.data[3] = 7; }), kOutOfRange,
                 "epoch divider 7: the others are no longer multiples of it");
  c = cmd(can::Opcode::kStartCapture, 0x54);  // byte 2 pose 0..63, bytes 3-4 N 1..65535
  expect_refused(edited(c, [](hal::CanFrame& f) { f.data[2] = 64, f.data[3] = 100; }), kOutOfRange,
                 "capture pose 64");
  expect_refused(edited(c, [](hal::CanFrame& f) { f.data[2] = 3; }), kOutOfRange,
                 "capture of 0 samples");
}

TEST_F(CanMalformedCommands, ASecondCaptureWhileOneRunsIsBusy) {
  can::Command c = cmd(can::Opcode::kStartCapture, 0x61);
  c.pose = 1;
  c.samples = 5000;  // 5 s at 1 kHz: still running during the checks below
  auto r = send(c);
  ASSERT_NE(part(r, 0), nullptr);
  ASSERT_EQ(part(r, 0)->result, can::ResultCode::kOk);
  ASSERT_TRUE(rig_->loop->capture_active());
  c.token = 0x62;
  c.pose = 2;
  expect_refused(can::encode_command(c, SimRig::kNode), kBusy, "second capture");
}

}  // namespace
}  // namespace gfins::app
