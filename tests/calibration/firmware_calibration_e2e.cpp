// Calibrating a board end to end through the firmware and the CAN commands (docs/calibration.md,
// "Calibrating a board through the firmware"), on the simulated board:
//
//   scenario calibration-board (known SF, bias, misalignment, location errors; 12 poses of
//   Tables 2/3 with turns between them, then a verification pose; 24.8° latitude)
//     → sensor model → ADS131M06 chip model → real driver → gfins::app::SampleLoop (the firmware)
//     ⇄ CAN command/response frames over an in-memory wire ⇄
//   gfins-can calibrate's capture sequence (host_sim/can_tool capture_sequence, the production
//   host code) → means CSV → the gfins-calibrate executable → calibration file → installed by
//   rename → ReloadCalibration command → GfinsStatus.CalId → verification pose → gfins-calibrate
//   --verify.
//
// Both sides are the production code; only the wire is simulated: a pair of hal::CanBus ends
// whose host end runs the board's loop while the host waits for a frame (single thread, the
// board's time advances only while the host waits, and stands still while the reload worker
// thread loads a file: deterministic, no sleeps).
//
// Oracle: the scenario's true parameters (the TOML file), independent of the solvers. The file
// states SF in V per local g and biases in local g; the scenario states SF in V per standard g
// and biases in m/s². Both are compared in SI: SF/g (V per m/s²) and b·g (m/s²), angles in degrees.
#include <gtest/gtest.h>

#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <cstdlib>
#include <deque>
#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>
#include <random>
#include <sstream>
#include <string>

#include "calibrate.hpp"
#include "capture_sequence.hpp"
#include "command_client.hpp"
#include "csv.hpp"
#include "gfins/app/config.hpp"
#include "gfins/app/epoch_sinks.hpp"
#include "gfins/app/publisher_sink.hpp"
#include "gfins/app/reload_worker.hpp"
#include "gfins/app/sample_loop.hpp"
#include "gfins/app/startup.hpp"
#include "gfins/calib_file/calibration_file.hpp"
#include "gfins/host_sim/board/sim_board.hpp"
#include "gfins/host_sim/scenario.hpp"
#include "gfins/nav_core/gravity.hpp"
#include "support/run_cli.hpp"
#include "support/sim_chain.hpp"

namespace gfins {
namespace {

using can_tool::PlanPose;
using can_tool::Refusal;
using can_tool::SequenceIo;
using can_tool::SequenceOptions;
using can_tool::SequenceResult;

// Recovered parameter vs truth: |est − true| ≤ kSigmas·σ (σ the file's stated 1σ). 24
// parameters (6 SF, 6 biases, 12 angles); for a Gaussian estimator with honest σ the chance that
// any one exceeds 5σ is 24 · 5.7e-7 = 1.4e-5 per seed (two-sided tail of 5σ: 5.7e-7).
constexpr double kSigmas = 5.0;
// Samples per pose: with 0.5 mg noise per sample (the scenario) the mean of a pose has σ =
// 0.5 mg/√2000 = 11 µg, so a 0.18 % scale error (wrong gravity) is ~100σ on every sensor.
constexpr std::uint16_t kSamples = 2000;
constexpr std::uint8_t kNode = 3;

// ---- The wire: two hal::CanBus ends ---------------------------------------------------------

struct Wire {
  std::deque<hal::CanFrame> to_board, to_host;
  hal::CanFrame last_status{};  // the last GfinsStatus frame the board sent
  bool have_status = false;
};

class BoardEnd final : public hal::CanBus {
 public:
  explicit BoardEnd(Wire& w) : w_(w) {}

 private:
  Status do_send(const hal::CanFrame& f) override {
    if (f.id == 0x110u + kNode && !f.extended) {  // GfinsStatus of this node (can-interface.md)
      w_.last_status = f;
      w_.have_status = true;
    }
    w_.to_host.push_back(f);
    ++c_.tx_frames;
    return Status::ok();
  }
  Result<hal::CanFrame> do_receive(std::int64_t /*timeout_ns*/) override {
    if (w_.to_board.empty()) return Status(ErrorCode::kTimeout, "wire: nothing for the board");
    const hal::CanFrame f = w_.to_board.front();
    w_.to_board.pop_front();
    ++c_.rx_frames;
    return f;
  }
  hal::CanBusState do_state() const override { return hal::CanBusState::kErrorActive; }
  hal::CanCounters do_counters() const override { return c_; }
  Wire& w_;
  hal::CanCounters c_{};
};

/// The host's end: while the host waits for a frame, the board runs (one loop cycle per sample
/// period of the wait), so a wait of T ns gives the board at most T ns of its own time.
class HostEnd final : public hal::CanBus {
 public:
  HostEnd(Wire& w, std::function<bool()> board_step, std::int64_t period_ns)
      : w_(w), step_(std::move(board_step)), period_ns_(period_ns) {}

 private:
  Status do_send(const hal::CanFrame& f) override {
    w_.to_board.push_back(f);
    return Status::ok();
  }
  Result<hal::CanFrame> do_receive(std::int64_t timeout_ns) override {
    std::int64_t cycles = std::max<std::int64_t>(1, timeout_ns / period_ns_);
    while (w_.to_host.empty() && cycles-- > 0) {
      if (!step_()) break;  // the scenario is over: nothing more will come
    }
    if (w_.to_host.empty()) return Status(ErrorCode::kTimeout, "wire: nothing for the host");
    const hal::CanFrame f = w_.to_host.front();
    w_.to_host.pop_front();
    return f;
  }
  hal::CanBusState do_state() const override { return hal::CanBusState::kErrorActive; }
  hal::CanCounters do_counters() const override { return {}; }
  Wire& w_;
  std::function<bool()> step_;
  std::int64_t period_ns_;
};

// ---- The simulated board with the firmware's loop, CAN codec and reload worker --------------

/// Passes samples through, keeping every 10th one's codes when asked (the optional figure).
class TraceSource final : public app::SampleSource {
 public:
  explicit TraceSource(app::SampleSource& inner) : inner_(inner) {}
  struct Point {
    double t_s;
    std::array<std::int32_t, 6> counts;
  };
  bool record = false;
  std::vector<Point> points;

 private:
  Result<RawSample> do_read_sample(std::int64_t timeout_ns) override {
    Result<RawSample> r = inner_.read_sample(timeout_ns);
    if (record && r.is_ok() && r.value().seq % 10 == 0) {
      points.push_back({static_cast<double>(r.value().t_ns) * 1e-9, r.value().counts});
    }
    return r;
  }
  app::AdcCounters do_counters() const override { return inner_.counters(); }
  double do_volts_per_count() const override { return inner_.volts_per_count(); }
  app::SampleSource& inner_;
};

struct Board {
  explicit Board(const std::filesystem::path& cal_file, const sim_board::FaultPlan& faults = {},
                 const std::string& scenario = "calibration-board") {
    const auto p = sim::load_scenario(scenario, GFINS_SCENARIO_DIR);
    if (!p.is_ok()) throw std::runtime_error(p.error().message);
    s = p.value();
    config.board = app::BoardKind::kSim;
    config.node_id = kNode;
    config.calibration_file = cal_file.string();
    samples = static_cast<std::uint32_t>(std::llround(s.duration_s * s.rate_hz)) + 1;
    test::SimChain chain = test::make_sim_chain(s, clock, samples, faults);
    stream = std::move(chain.stream);
    adc = std::move(chain.adc);
    source = std::move(chain.source);
    tap = std::make_unique<TraceSource>(*source);
    tap->record = std::getenv("GFINS_CAL_E2E_OUT") != nullptr;
    period_ns = std::llround(1e9 / s.rate_hz);
    board_bus = std::make_unique<BoardEnd>(wire);
    host_bus = std::make_unique<HostEnd>(
        wire, [this] { return step(); }, period_ns);
    sink = std::make_unique<app::PublisherSink>(*board_bus, kNode, app::bus_dividers(config));
    log = std::make_unique<app::FwLogQueue>();
    // No file yet: the nominal chain (what a new board runs with), calibration id 0.
    const auto cal =
        app::load_calibration(config, app::nominal_calibration(adc->volts_per_count()));
    // The reload worker is a thread: on a board, how many epochs a reload takes depends on the
    // file system. Here its load waits for the loop step that requested it to end, and step()
    // waits for the load to finish: a reload requested in step k always applies in step k + 1,
    // so every capture after it starts at the same epoch on every run.
    reload = std::make_unique<app::ReloadWorker>(
        [this, load = app::calibration_reloader(config)](const app::ReloadRequest& c) {
          {
            std::unique_lock<std::mutex> lock(gate_mutex);
            gate_cv.wait(lock, [this] { return !in_step; });
          }
          return load(c);
        });
    loop = std::make_unique<app::SampleLoop>(*tap, *board_bus, *sink, clock, *log);
    loop->set_commands(true);
    loop->set_reload_worker(reload.get());
    if (const Status st = loop->configure(cal.set, app::loop_options(config)); !st.is_ok()) {
      throw std::runtime_error(st.message());
    }
  }
  bool step() {
    if (source->finished()) return false;
    {
      const std::lock_guard<std::mutex> lock(gate_mutex);
      in_step = true;
    }
    (void)loop->step();
    {
      const std::lock_guard<std::mutex> lock(gate_mutex);
      in_step = false;
      gate_cv.notify_all();
    }
    reload->wait_settled();  // board time stands still while a reload runs
    app::LogRecord r;
    while (log->pop(r)) {
    }
    return true;
  }
  /// Board time of the next sample, s.
  double now_s() const { return static_cast<double>(source->next_seq()) / s.rate_hz; }
  void run_until(double t_s) {
    while (now_s() < t_s && step()) {
    }
  }
  SequenceOptions options() const {
    SequenceOptions o;
    o.node_id = kNode;
    o.samples = kSamples;
    o.sample_rate_hz = s.rate_hz;
    o.adc_lsb_v = adc->volts_per_count();
    o.retries = 0;
    return o;
  }

  sim::Scenario s;
  app::FwConfig config;
  std::uint32_t samples = 0;
  std::int64_t period_ns = 0;
  Wire wire;
  std::unique_ptr<sim_board::SensorStream> stream;
  std::unique_ptr<sim_board::ChipAdc> adc;
  app::SampleClock clock;
  std::unique_ptr<sim_board::SimSampleSource> source;
  std::unique_ptr<TraceSource> tap;
  std::unique_ptr<BoardEnd> board_bus;
  std::unique_ptr<HostEnd> host_bus;
  std::unique_ptr<app::PublisherSink> sink;
  std::unique_ptr<app::FwLogQueue> log;
  std::mutex gate_mutex;  // in_step, between step() and the reload worker's load
  std::condition_variable gate_cv;
  bool in_step = false;
  std::unique_ptr<app::ReloadWorker> reload;
  std::unique_ptr<app::SampleLoop> loop;
};

struct TempDir {
  TempDir() {
    std::random_device rd;
    path = std::filesystem::temp_directory_path() /
           ("gfins-cal-e2e-" + std::to_string(rd()) + std::to_string(rd()));
    std::filesystem::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
  std::filesystem::path path;
};

void write(const std::filesystem::path& p, const std::string& text) {
  std::ofstream f(p, std::ios::binary);
  f << text;
}

// ---- The oracle: the scenario's truth against a calibration file ---------------------------

struct TruthCheck {
  double max_z = 0;  // largest |est − true|/σ
  std::string worst;
  std::vector<std::pair<std::string, double>> z;  // every (est − true)/σ, signed
  bool ok() const { return max_z <= kSigmas; }
};

TruthCheck compare_with_truth(const calib_file::CalibrationData& d, const sim::Scenario& s) {
  TruthCheck c;
  const auto z = [&c](double est, double truth, double sigma, const std::string& what) {
    c.z.emplace_back(what.substr(0, what.find(' ', what.find(' ') + 1)), (est - truth) / sigma);
    const double v = std::abs(est - truth) / sigma;
    if (!(v <= c.max_z)) {  // NaN counts as the worst
      c.max_z = std::isfinite(v) ? v : 1e300;
      c.worst = what + ": estimated " + std::to_string(est) + ", true " + std::to_string(truth) +
                ", 1σ " + std::to_string(sigma);
    }
  };
  const double g_cal = d.gravity_mps2;
  for (std::size_t j = 0; j < 6; ++j) {
    const auto& e = d.sensors[j];
    const std::string n = "a" + std::to_string(j + 1);
    // The sensor model's SF is V per standard g (sensor_model.hpp: a_g = s/9.80665).
    z(e.scale_v_per_g / g_cal, s.scale_v_per_g[j] / nav::kStandardGravity,
      e.scale_sigma_v_per_g / g_cal, "SF " + n + " (V per m/s²)");
    z(e.bias_g * g_cal, s.bias_mps2[j], e.bias_sigma_g * g_cal, "bias " + n + " (m/s²)");
  }
  constexpr double kDegPerRad = 180.0 / 3.14159265358979323846;
  const std::array<const char*, 6> names{"xy", "xz", "yx", "yz", "zx", "zy"};  // Table 6 order
  for (std::size_t i = 0; i < 6; ++i) {
    z(d.beta.angle_deg[i], s.misalignment.orientation.beta[i] * kDegPerRad,
      d.beta.angle_sigma_deg[i], std::string("dbeta ") + names[i] + " (deg)");
    z(d.alpha.angle_deg[i], s.misalignment.orientation.alpha[i] * kDegPerRad,
      d.alpha.angle_sigma_deg[i], std::string("dalpha ") + names[i] + " (deg)");
  }
  return c;
}

std::uint32_t status_cal_id(const hal::CanFrame& f) {
  // GfinsStatus: StatusFlags bits 0..19, CalId bits 20..51, little-endian (can-interface.md).
  std::uint64_t v = 0;
  for (int b = 7; b >= 0; --b) v = (v << 8) | f.data[static_cast<std::size_t>(b)];
  return static_cast<std::uint32_t>((v >> 20) & 0xFFFFFFFFu);
}
std::uint32_t status_flags(const hal::CanFrame& f) {
  return static_cast<std::uint32_t>(f.data[0] | (f.data[1] << 8) | ((f.data[2] & 0x0F) << 16));
}
constexpr std::uint32_t kNominalCalibrationBit = 1u << 9;  // can-interface.md, status flags

std::string run_calibrate(const std::vector<std::string>& args, const std::filesystem::path& dir,
                          int& exit_code) {
  const test::CliResult r = test::run_tool(GFINS_CALIBRATE_EXE, args, dir);
  exit_code = r.exit_code;
  return r.output;
}

TEST(FirmwareCalibration, ABoardWithKnownErrorsIsCalibratedThroughTheCanCommands) {
  TempDir dir;
  const auto installed = dir.path / "calibration.toml";
  Board b(installed);
  ASSERT_EQ(b.s.trajectory.kind, "calibration_poses");

  // 1. The twelve poses, waited for automatically (probes until still in the expected pose).
  std::vector<PlanPose> plan = can_tool::tables23_plan();
  SequenceOptions o = b.options();
  o.wait = can_tool::WaitMode::kAuto;
  std::vector<std::string> notes;
  std::vector<double> capture_end_s;
  SequenceIo io;
  io.note = [&](const std::string& s) {
    notes.push_back(s);
    capture_end_s.push_back(b.now_s());
  };
  const SequenceResult seq = can_tool::run_capture_sequence(*b.host_bus, plan, o, io);
  ASSERT_TRUE(seq.ok) << seq.error;
  ASSERT_EQ(seq.captures.size(), 12u);
  EXPECT_EQ(seq.refused, 0);  // auto mode captures only once the board is still in the pose
  for (const auto& c : seq.captures) {
    for (const auto& ch : c.result.channels) EXPECT_EQ(ch.count, kSamples);
  }
  // Every capture lies inside its pose's dwell: pose k is held over [4.5 k, 4.5 k + 3] s; the
  // twelfth ends inside the last one's.
  EXPECT_GT(b.now_s(), 11 * 4.5 + kSamples / b.s.rate_hz);
  EXPECT_LT(b.now_s(), 11 * 4.5 + 3.0);
  std::printf("12 poses captured by board time %.3f s\n", b.now_s());

  const auto means = dir.path / "means.csv";
  const auto poses = dir.path / "poses.csv";
  const auto paper_means = dir.path / "means-paper.csv";
  write(means, can_tool::means_csv(seq.captures, o.adc_lsb_v, false));
  write(poses, can_tool::poses_csv(plan));
  write(paper_means, can_tool::means_csv(seq.captures, o.adc_lsb_v, true));

  // 2. gfins-calibrate, general route (every sensor in every pose, stated σ), at the site's
  // latitude: the file is written atomically next to the installed one, then renamed over it.
  char lsb_text[40];
  std::snprintf(lsb_text, sizeof lsb_text, "%.17g", o.adc_lsb_v);
  const auto fresh = dir.path / "calibration.toml.new";
  int rc = -1;
  std::string out = run_calibrate(
      {"--means", means.string(), "--poses", poses.string(), "--latitude", "24.8", "--height", "50",
       "--device-id", "sim-board-1", "--adc-lsb", lsb_text, "-o", fresh.string()},
      dir.path, rc);
  ASSERT_EQ(rc, 0) << out;
  const auto cal = calib_file::load_calibration_file(fresh);
  ASSERT_TRUE(cal.is_ok()) << cal.status().message();
  const TruthCheck truth = compare_with_truth(cal.value(), b.s);
  EXPECT_TRUE(truth.ok()) << "worst: " << truth.worst << " (" << truth.max_z << " σ)";
  std::printf("general route: largest |error|/σ over 24 parameters %.2f (%s)\n", truth.max_z,
              truth.worst.c_str());

  // The paper route (Tables 4/5 layout, eqs. (17)/(18) + least squares) on the same captures.
  out = run_calibrate(
      {"--means", paper_means.string(), "--latitude", "24.8", "--height", "50", "--device-id",
       "sim-board-1", "--adc-lsb", lsb_text, "-o", (dir.path / "paper.toml").string()},
      dir.path, rc);
  ASSERT_EQ(rc, 0) << out;
  const auto paper = calib_file::load_calibration_file(dir.path / "paper.toml");
  ASSERT_TRUE(paper.is_ok());
  const TruthCheck paper_truth = compare_with_truth(paper.value(), b.s);
  EXPECT_TRUE(paper_truth.ok()) << "worst: " << paper_truth.worst;
  std::printf("paper route: largest |error|/σ %.2f (%s)\n", paper_truth.max_z,
              paper_truth.worst.c_str());

  // Negative controls: the same check fails for a wrong pose order and for a wrong gravity.
  {
    // Poses 1 and 3 (T2.1, T2.3) swapped in the poses file: the means are attributed to the
    // wrong attitudes. The solver's verdict is no longer good, and forced, the file is far off.
    std::vector<PlanPose> swapped = plan;
    std::swap(swapped[0].f_b_g, swapped[2].f_b_g);
    const auto swapped_poses = dir.path / "poses-swapped.csv";
    write(swapped_poses, can_tool::poses_csv(swapped));
    out = run_calibrate({"--means", means.string(), "--poses", swapped_poses.string(), "--latitude",
                         "24.8", "--height", "50", "--device-id", "sim-board-1", "--adc-lsb",
                         lsb_text, "-o", (dir.path / "swapped.toml").string()},
                        dir.path, rc);
    EXPECT_EQ(rc, 3) << "a wrong pose order must not give a good verdict:\n" << out;
    out = run_calibrate({"--means", means.string(), "--poses", swapped_poses.string(), "--latitude",
                         "24.8", "--height", "50", "--device-id", "sim-board-1", "--adc-lsb",
                         lsb_text, "--force", "-o", (dir.path / "swapped.toml").string()},
                        dir.path, rc);
    // Forced, either the file layer refuses the result (angles beyond the ±10° small-angle
    // domain: exit 4) or the file it writes fails the truth check.
    if (rc == 4) {
      EXPECT_NE(out.find("not saved"), std::string::npos) << out;
      std::printf("wrong pose order: forced file refused by the file checks\n");
    } else {
      ASSERT_EQ(rc, 0) << out;
      const auto bad = calib_file::load_calibration_file(dir.path / "swapped.toml");
      ASSERT_TRUE(bad.is_ok());
      const TruthCheck c = compare_with_truth(bad.value(), b.s);
      EXPECT_FALSE(c.ok()) << "the truth check cannot tell a wrong pose order";
      std::printf("wrong pose order: largest |error|/σ %.3g (%s)\n", c.max_z, c.worst.c_str());
    }
  }
  {
    // Standard gravity instead of the site's 9.7891 m/s²: every V/g is right in V per local g,
    // but the file converts with the wrong g, 0.18 % off: ~100σ on the scale factors.
    out = run_calibrate({"--means", means.string(), "--poses", poses.string(), "--gravity",
                         "9.80665", "--device-id", "sim-board-1", "--adc-lsb", lsb_text, "-o",
                         (dir.path / "wrong-g.toml").string()},
                        dir.path, rc);
    ASSERT_EQ(rc, 0) << out;
    const auto bad = calib_file::load_calibration_file(dir.path / "wrong-g.toml");
    ASSERT_TRUE(bad.is_ok());
    const TruthCheck c = compare_with_truth(bad.value(), b.s);
    EXPECT_FALSE(c.ok()) << "the truth check cannot tell a wrong gravity";
    std::printf("wrong gravity: largest |error|/σ %.3g (%s)\n", c.max_z, c.worst.c_str());
  }

  // Optional data for docs/figures/calibration-e2e.png (scripts/plot_calibration_e2e.py).
  if (const char* fig = std::getenv("GFINS_CAL_E2E_OUT"); fig != nullptr) {
    const std::filesystem::path d(fig);
    std::ofstream t(d / "trace.csv");
    t << "t_s,v1,v2,v3,v4,v5,v6\n";
    for (const auto& p : b.tap->points) {
      t << p.t_s;
      for (const std::int32_t c : p.counts) t << "," << c * o.adc_lsb_v;
      t << "\n";
    }
    std::ofstream c(d / "captures.csv");
    c << "label,t_start_s,t_end_s\n";
    for (std::size_t i = 0; i < seq.captures.size() && i < capture_end_s.size(); ++i) {
      c << seq.captures[i].pose.label << "," << capture_end_s[i] - kSamples / b.s.rate_hz << ","
        << capture_end_s[i] << "\n";
    }
    std::ofstream zf(d / "z.csv");
    zf << "route,parameter,z\n";
    for (const auto& [k, v] : truth.z) zf << "general," << k << "," << v << "\n";
    for (const auto& [k, v] : paper_truth.z) zf << "paper," << k << "," << v << "\n";
    const auto wrong = calib_file::load_calibration_file(dir.path / "wrong-g.toml");
    if (wrong.is_ok()) {
      for (const auto& [k, v] : compare_with_truth(wrong.value(), b.s).z) {
        zf << "standard gravity," << k << "," << v << "\n";
      }
    }
  }

  // 3. Install: rename over the configured file (atomic), then ReloadCalibration on CAN.
  ASSERT_TRUE(b.wire.have_status);
  EXPECT_EQ(status_cal_id(b.wire.last_status), 0u);
  EXPECT_NE(status_flags(b.wire.last_status) & kNominalCalibrationBit, 0u);
  std::filesystem::rename(fresh, installed);
  const std::uint32_t expected_id = calib_file::cal_id_of(cal.value());
  ASSERT_NE(expected_id, 0u);
  can::Command reload;
  reload.opcode = can::Opcode::kReloadCalibration;
  reload.token = 0xA5;
  reload.sequence = 1;  // the board's first configuration-changing command of this session
  const can_tool::CommandOutcome r =
      can_tool::run_command(*b.host_bus, reload, kNode, can_tool::CommandTimeouts{});
  ASSERT_EQ(r.kind, can_tool::CommandOutcome::Kind::kOk) << r.text;
  EXPECT_EQ(r.status.cal_id, expected_id) << r.text;
  b.run_until(b.now_s() + 0.05);  // a few epochs
  EXPECT_EQ(status_cal_id(b.wire.last_status), expected_id);
  EXPECT_EQ(status_flags(b.wire.last_status) & kNominalCalibrationBit, 0u);
  EXPECT_EQ(b.loop->cal_id(), expected_id);
  std::printf("installed and reloaded: GfinsStatus.CalId 0x%08X\n",
              status_cal_id(b.wire.last_status));

  // 4. The verification pose (the scenario's 13th: a 30° tilt, not one of the twelve).
  std::string error;
  const auto vplan = can_tool::plan_from_rows(
      {{13,
        {b.s.trajectory.extra_poses_g[0].x(), b.s.trajectory.extra_poses_g[0].y(),
         b.s.trajectory.extra_poses_g[0].z()}}},
      error);
  ASSERT_EQ(vplan.size(), 1u) << error;
  o.first_token = 100;
  const SequenceResult vseq = can_tool::run_capture_sequence(*b.host_bus, vplan, o, io);
  ASSERT_TRUE(vseq.ok) << vseq.error;
  const auto vmeans = dir.path / "verify.csv";
  const auto vposes = dir.path / "verify-poses.csv";
  write(vmeans, can_tool::means_csv(vseq.captures, o.adc_lsb_v, false));
  write(vposes, can_tool::poses_csv(vplan));
  out = run_calibrate(
      {"--verify", installed.string(), "--means", vmeans.string(), "--poses", vposes.string()},
      dir.path, rc);
  EXPECT_EQ(rc, 0) << out;
  EXPECT_NE(out.find("verification passed"), std::string::npos) << out;
  std::printf("%s", out.c_str());
  // The check can fail: the same capture declared as a 25° tilt instead of 30° (a jig 5° off)
  // is far outside the residuals' σ (5° on a sensor at ~45° to gravity: ~60 mg ≫ 15 µg).
  const double t25 = 25.0 * 3.14159265358979323846 / 180.0;
  const auto wrong_jig = dir.path / "verify-poses-25.csv";
  write(wrong_jig, "attitude,fx_g,fy_g,fz_g\n13,0," + std::to_string(std::sin(t25)) + "," +
                       std::to_string(-std::cos(t25)) + "\n");
  out = run_calibrate(
      {"--verify", installed.string(), "--means", vmeans.string(), "--poses", wrong_jig.string()},
      dir.path, rc);
  EXPECT_EQ(rc, 3) << out;
  EXPECT_NE(out.find("verification failed"), std::string::npos) << out;
}

// ---- Refusals: a pose that moved, saturated or is not the expected one ----------------------

TEST(FirmwareCalibration, APoseThatMovedIsRefusedNamingTheChannels) {
  TempDir dir;
  Board b(dir.path / "calibration.toml");
  const auto plan = can_tool::tables23_plan();
  SequenceOptions o = b.options();
  o.samples = 1000;
  SequenceIo io;
  // The operator says "ready" while the board is still turning from pose 1 to pose 2 (the turn
  // runs 3.0 .. 4.5 s): the capture spans the end of the turn.
  io.await_pose = [&b](const PlanPose&, std::size_t, std::size_t, bool) {
    b.run_until(3.2);
    return true;
  };
  const std::vector<PlanPose> one{plan[1]};
  const SequenceResult r = can_tool::run_capture_sequence(*b.host_bus, one, o, io);
  ASSERT_FALSE(r.ok);
  EXPECT_EQ(r.stop, SequenceResult::Stop::kRefused);
  std::printf("%s\n", r.error.c_str());
  EXPECT_NE(r.error.find("pose 2 (T2.2) refused: the board moved"), std::string::npos) << r.error;
  EXPECT_NE(r.error.find(" mg"), std::string::npos) << r.error;
  EXPECT_NE(r.error.find("still limit"), std::string::npos) << r.error;
}

TEST(FirmwareCalibration, ASaturatedChannelIsRefusedNamingIt) {
  TempDir dir;
  sim_board::FaultPlan f;
  f.saturated_channel = 2;  // a3 at full scale for 0.5 s inside pose 1's dwell
  f.saturated_from = 1200;
  f.saturated_until = 1700;
  Board b(dir.path / "calibration.toml", f);
  const auto plan = can_tool::tables23_plan();
  SequenceOptions o = b.options();
  o.samples = 1000;
  SequenceIo io;
  io.await_pose = [&b](const PlanPose&, std::size_t, std::size_t, bool) {
    b.run_until(1.0);
    return true;
  };
  const std::vector<PlanPose> one{plan[0]};
  const SequenceResult r = can_tool::run_capture_sequence(*b.host_bus, one, o, io);
  ASSERT_FALSE(r.ok);
  EXPECT_EQ(r.stop, SequenceResult::Stop::kRefused);
  std::printf("%s\n", r.error.c_str());
  EXPECT_NE(r.error.find("pose 1 (T2.1) refused: saturated: channel(s) a3 reached"),
            std::string::npos)
      << r.error;
}

TEST(FirmwareCalibration, AWrongPoseOrderIsRefusedNamingThePoseItReadsLike) {
  TempDir dir;
  Board b(dir.path / "calibration.toml");
  auto plan = can_tool::tables23_plan();
  std::swap(plan[0], plan[1]);  // the plan says T2.2 first; the board is put in T2.1 first
  SequenceOptions o = b.options();
  o.samples = 500;
  SequenceIo io;
  io.await_pose = [&b](const PlanPose&, std::size_t i, std::size_t, bool) {
    b.run_until(4.5 * static_cast<double>(i) + 0.5);  // the board's own schedule
    return true;
  };
  const SequenceResult r = can_tool::run_capture_sequence(*b.host_bus, plan, o, io);
  ASSERT_FALSE(r.ok);
  EXPECT_EQ(r.stop, SequenceResult::Stop::kRefused);
  std::printf("%s\n", r.error.c_str());
  EXPECT_TRUE(r.captures.empty());
  EXPECT_NE(r.error.find("pose 2 (T2.2) refused: the board is not in this pose"), std::string::npos)
      << r.error;
  EXPECT_NE(r.error.find("it reads like pose 1 (T2.1): wrong pose order?"), std::string::npos)
      << r.error;
}

TEST(FirmwareCalibration, AutoModeGivesUpOnAPoseTheBoardNeverTakes) {
  TempDir dir;
  Board b(dir.path / "calibration.toml");
  std::string error;
  // The face "z down": not one of the scenario's poses (0.45 g from the nearest on a3).
  const auto plan = can_tool::plan_from_rows({{1, {0.0, 0.0, -1.0}}}, error);
  ASSERT_EQ(plan.size(), 1u) << error;
  SequenceOptions o = b.options();
  o.wait = can_tool::WaitMode::kAuto;
  o.pose_timeout_s = 2.0;  // board time: ten probes of 0.2 s
  const SequenceResult r = can_tool::run_capture_sequence(*b.host_bus, plan, o, SequenceIo{});
  ASSERT_FALSE(r.ok);
  EXPECT_EQ(r.stop, SequenceResult::Stop::kNotReached);
  EXPECT_NE(r.error.find("pose 1 (P1) not reached after 2 s of probing; last probe: pose 1 (P1) "
                         "refused: the board is not in this pose"),
            std::string::npos)
      << r.error;
  EXPECT_NEAR(b.now_s(), 2.0, 0.1);  // it probed for the time asked, no longer
}

TEST(FirmwareCalibration, PosesOfTheTablesAreFarApartComparedWithThePoseTolerance) {
  // The pose check can tell the twelve poses apart: on the Table 1 axes any two differ by more
  // than twice the tolerance on some channel (computed here from the vectors, cos 45° = 0.7071).
  const auto plan = can_tool::tables23_plan();
  const SequenceOptions o;
  const double k = 1.0 / std::sqrt(2.0);
  const double theta[6][3] = {{k, k, 0}, {k, 0, k}, {0, k, k}, {0, -k, k}, {-k, 0, k}, {-k, k, 0}};
  double closest = 1e9;
  for (std::size_t a = 0; a < plan.size(); ++a) {
    for (std::size_t c = a + 1; c < plan.size(); ++c) {
      double d = 0;
      for (const auto& t : theta) {
        double x = 0;
        for (std::size_t i = 0; i < 3; ++i) x += t[i] * (plan[a].f_b_g[i] - plan[c].f_b_g[i]);
        d = std::max(d, std::abs(x));
      }
      closest = std::min(closest, d);
    }
  }
  EXPECT_GT(closest, 2.0 * o.pose_tolerance_g);
  // Poses 60° apart, e.g. (−1, 0, 1)/√2 and (0, 1, 1)/√2: a1 = (1, 1, 0)/√2 reads −1/2 and +1/2.
  EXPECT_NEAR(closest, 1.0, 1e-12);
}

// ---- gfins-can calibrate: bad input is named before anything is sent ------------------------

TEST(GfinsCanCalibrate, BadInputIsNamedWithItsExitStatus) {
  TempDir dir;
  const auto run = [&dir](const std::vector<std::string>& args) {
    return test::run_tool(GFINS_CAN_EXE, args, dir.path);
  };
  const std::vector<std::string> base{"calibrate",
                                      "--iface",
                                      "gfinsnone0",
                                      "--adc-lsb",
                                      "1.1916160583496094e-06",
                                      "-o",
                                      (dir.path / "m.csv").string()};
  const auto with = [&base](std::vector<std::string> extra) {
    std::vector<std::string> a = base;
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  };
  // A pose of 2 g is not a pose at rest: exit 1, the file and line named.
  write(dir.path / "bad-poses.csv", "attitude,fx_g,fy_g,fz_g\n1,0,0,-1\n4,0,0,2\n");
  test::CliResult r = run(with({"--poses", (dir.path / "bad-poses.csv").string()}));
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("bad-poses.csv:3: |f| = 2"), std::string::npos) << r.output;
  // The paper layout belongs to the Tables 2/3 plan.
  write(dir.path / "poses.csv", "attitude,fx_g,fy_g,fz_g\n1,0,0,-1\n2,0,0,1\n");
  r = run(with({"--poses", (dir.path / "poses.csv").string(), "--layout", "paper"}));
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("--layout paper is the Tables 2/3 plan's"), std::string::npos)
      << r.output;
  r = run(with({"--nominal-sf", "1.3", "1.2"}));
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("--nominal-sf takes 1 or 6 values"), std::string::npos) << r.output;
  // A rate-table plan: a run with a zero rate, a zero axis, a short line are named by line;
  // --poses with --rate-table is refused; a good plan reaches the (missing) interface.
  const std::vector<std::pair<std::string, std::string>> bad_plans = {
      {"0,1,0,0,0", "line 2 ('0,1,0,0,0'): rate_rad_s must be in (0, 100] rad/s"},
      {"1,0,0,0,4", "line 2 ('1,0,0,0,4'): the axis pointing up must be a non-zero vector"},
      {"2,0,1,4", "line 2 ('2,0,1,4'): 4 fields, expected 5"},
      {"3,1,1,0,x", "line 2 ('3,1,1,0,x'): field 5 'x' is not a number"}};
  for (const auto& [row, message] : bad_plans) {
    write(dir.path / "plan.csv", "mounting,axis_x,axis_y,axis_z,rate_rad_s\n" + row + "\n");
    r = run(with({"--rate-table", (dir.path / "plan.csv").string()}));
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_NE(r.output.find("plan.csv: " + message), std::string::npos) << r.output;
  }
  write(dir.path / "plan.csv", "mounting,axis_x,axis_y,axis_z,rate_rad_s\n0,1,0,0,4\n");
  r = run(with({"--rate-table", (dir.path / "plan.csv").string(), "--layout", "all"}));
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("--rate-table captures location runs"), std::string::npos) << r.output;
  r = run(with({"--rate-table", (dir.path / "plan.csv").string()}));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("cannot open CAN interface 'gfinsnone0'"), std::string::npos) << r.output;
  // No such interface: exit 2, the interface named; nothing written.
  r = run(base);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("cannot open CAN interface 'gfinsnone0'"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir.path / "m.csv"));
}

TEST(FirmwareCalibration, ThePoseSequenceHoldsEachPoseStillAndTurnsSmoothly) {
  const auto p = sim::load_scenario("calibration-board", GFINS_SCENARIO_DIR);
  ASSERT_TRUE(p.is_ok()) << p.error().message;
  const sim::TrajectorySpec& spec = p.value().trajectory;
  const auto traj = sim::make_trajectory(spec);
  ASSERT_TRUE(traj.is_ok());
  const auto poses = sim::calibration_pose_vectors(spec);
  ASSERT_EQ(poses.size(), 13u);
  const double period = spec.dwell_s + spec.transition_s;
  // Mid-dwell of every pose: at rest, and the body senses the pose's specific force: R_nb f̂_b is
  // "up" (−z of NED). Rotations of unit vectors: exact to rounding (1e-12).
  for (std::size_t k = 0; k < poses.size(); ++k) {
    const sim::TruthState x = traj.value()->at(period * static_cast<double>(k) + 1.5);
    EXPECT_LT((x.q_nb * poses[k].normalized() - sim::Vec3d(0, 0, -1)).norm(), 1e-12) << k;
    EXPECT_EQ(x.w_b.norm(), 0.0) << k;
  }
  // Inside a turn, ω from the jets equals the finite difference of the attitude,
  // ω ≈ 2 vec(q* ⊗ (q(t+h) − q(t−h))/2h), to O(h²) (h = 1e-5 s: ~1e-8 rad/s here).
  const double t = spec.dwell_s + 0.6 * spec.transition_s;
  const double h = 1e-5;
  const sim::TruthState x = traj.value()->at(t);
  const sim::Quatd qp = traj.value()->at(t + h).q_nb, qm = traj.value()->at(t - h).q_nb;
  sim::Quatd dq;
  dq.coeffs() = (qp.coeffs() - qm.coeffs()) / (2 * h);
  const sim::Vec3d w_fd = 2.0 * (x.q_nb.conjugate() * dq).vec();
  EXPECT_GT(x.w_b.norm(), 0.1);  // turning (60° in 1.5 s peaks near 1.3 rad/s)
  EXPECT_LT((w_fd - x.w_b).norm(), 1e-6);
  // Minimum jerk: ω and ω̇ vanish where a turn ends.
  const sim::TruthState end = traj.value()->at(period);
  EXPECT_LT(end.w_b.norm(), 1e-9);
  EXPECT_LT(end.wdot_b.norm(), 1e-6);
}

// ---- Location calibration: rate-table runs captured through the firmware -------------------
//
// The five mountings of docs/calibration.md §5 (board axes x, y, z and the two face diagonals
// pointing up, table axis vertical through the array centre) at 2, 6 and 10 rad/s: the set that
// makes every component of Δρ observable. Each run is the simulated board (calibration-board's
// sensors: SF, bias, orientation and location errors, its 24.8° site) spinning at a constant
// rate; the host's StartCapture (capture_once, the code of gfins-can calibrate --rate-table)
// averages whole revolutions through the firmware, and location_run_row writes the row
// gfins-calibrate --location-runs reads. The base calibration is the one a user has: the twelve
// poses captured through the firmware and solved by gfins-calibrate (base_through_firmware), so
// its SF, biases and angles carry their own errors, which the stated σ of Δρ must include.

// Δρ recovered vs truth: |est − true| ≤ kLocationSigmas·σ, σ the file's stated 1σ. 18
// components, Gaussian with honest σ: P(any beyond 5σ) = 18 · 5.7e-7 = 1e-5 (false failure).
constexpr double kLocationSigmas = 5.0;
// Coverage of the truth by the stated covariance: χ² = Σ_j e_jᵀ C_j⁻¹ e_j over the six sensors
// (e_j = Δρ_j estimated − true, C_j the stated 3×3 covariance, runs + base; sensors independent
// with the axis through the centre) is χ² with 18 dof. Bounds: its 1e-4 and 1 − 1e-4 quantiles
// (computed from the regularised incomplete gamma function), so a correct σ fails with
// probability 2e-4; σ stated 3× too small (χ² ≈ 160) or 3× too large (χ² ≈ 2) fails.
constexpr double kChi2Low = 3.555;
constexpr double kChi2High = 49.19;
// Samples per capture: whole revolutions totalling about 6 s at 1 kHz. σ of a 10 rad/s run's
// mean is 0.5 mg/√6000 = 6.3e-5 m/s², i.e. 0.6 µm of Δρ at ω² = 100 s⁻²; the truth's Δρ
// (0.1–1.2 mm) is hundreds of σ away from 0, so a solver writing Δρ = 0 fails.
constexpr double kRunTargetSamples = 6000.0;
constexpr std::array<double, 3> kRatesRadS{2.0, 6.0, 10.0};

struct Mounting {
  int number;
  std::array<double, 3> up_b;  // body axis pointing up (unit)
};
const std::array<Mounting, 5> kMountings{{{0, {1, 0, 0}},
                                          {1, {0, 1, 0}},
                                          {2, {0, 0, 1}},
                                          {3, {M_SQRT1_2, M_SQRT1_2, 0}},
                                          {4, {M_SQRT1_2, 0, M_SQRT1_2}}}};

/// The scenario of one run: calibration-board's sensors, the board spinning about `up_b` with
/// `up_b` pointing up (−z of NED), for `duration_s`.
std::string rate_table_scenario(const sim::Scenario& truth, const Mounting& m, double rate,
                                double duration_s) {
  // Euler angles (ZYX) of the attitude that points up_b up, checked against the core's own
  // conversion below.
  const Eigen::Vector3d up(m.up_b[0], m.up_b[1], m.up_b[2]);
  const Eigen::Quaterniond q = Eigen::Quaterniond::FromTwoVectors(up, Eigen::Vector3d(0, 0, -1));
  const Eigen::Matrix3d r = q.toRotationMatrix();
  const double roll = std::atan2(r(2, 1), r(2, 2));
  const double pitch = -std::asin(std::clamp(r(2, 0), -1.0, 1.0));
  const double yaw = std::atan2(r(1, 0), r(0, 0));
  if ((nav::quat_from_euler(roll, pitch, yaw) * up - Eigen::Vector3d(0, 0, -1)).norm() > 1e-9) {
    throw std::runtime_error("rate_table_scenario: Euler angles do not point the axis up");
  }
  constexpr double kDeg = 180.0 / M_PI;
  std::string t;
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "[scenario]\nduration_s = %.6f\nrate_hz = %.1f\nseed = %d\n"
                "[gravity]\nmodel = \"normal\"\nlatitude_deg = %.17g\nheight_m = %.17g\n"
                "[trajectory]\nkind = \"rate_table\"\naxis_b = [%.17g, %.17g, %.17g]\n"
                "rate_dps = %.17g\neuler_deg = [%.17g, %.17g, %.17g]\n",
                duration_s, truth.rate_hz, 100 + 10 * m.number + static_cast<int>(rate),
                truth.latitude_rad * kDeg, truth.height_m, up.x(), up.y(), up.z(), rate * kDeg,
                roll * kDeg, pitch * kDeg, yaw * kDeg);
  t += buf;
  const auto list = [](const auto& get, std::size_t n) {
    std::string l = "[";
    for (std::size_t i = 0; i < n; ++i) {
      char b[40];
      std::snprintf(b, sizeof b, "%s%.17g", i ? ", " : "", get(i));
      l += b;
    }
    return l + "]";
  };
  const auto& o = truth.misalignment.orientation;
  t += "[sensors]\nmodel = \"paper\"\nnoise_mg = 0.5\norientation = \"custom\"\n";
  t += "beta_deg = " + list([&](std::size_t i) { return o.beta[i] * kDeg; }, 6) + "\n";
  t += "alpha_deg = " + list([&](std::size_t i) { return o.alpha[i] * kDeg; }, 6) + "\n";
  t += "scale_v_per_g = " + list([&](std::size_t i) { return truth.scale_v_per_g[i]; }, 6) + "\n";
  t += "bias_mps2 = " + list([&](std::size_t i) { return truth.bias_mps2[i]; }, 6) + "\n";
  t += "location_error_mm = " +
       list([&](std::size_t i) { return truth.misalignment.drho_b[i / 3](i % 3) * 1e3; }, 18) +
       "\n[compensator]\nkind = \"exact\"\n";
  return t;
}

/// The base calibration as a user makes it: the twelve poses of Tables 2/3 captured through the
/// firmware (the board of `scenario`, auto wait) and solved by gfins-calibrate's general route
/// at the scenario's site; returns the file's path.
std::filesystem::path base_through_firmware(const std::filesystem::path& dir) {
  Board b(dir / "none.toml");
  const std::vector<PlanPose> plan = can_tool::tables23_plan();
  SequenceOptions o = b.options();
  o.wait = can_tool::WaitMode::kAuto;
  const SequenceResult seq = can_tool::run_capture_sequence(*b.host_bus, plan, o, SequenceIo{});
  if (!seq.ok || seq.captures.size() != plan.size()) {
    ADD_FAILURE() << "base capture: " << seq.error;
    return {};
  }
  write(dir / "base-means.csv", can_tool::means_csv(seq.captures, o.adc_lsb_v, false));
  write(dir / "base-poses.csv", can_tool::poses_csv(plan));
  char lsb_text[40];
  std::snprintf(lsb_text, sizeof lsb_text, "%.17g", o.adc_lsb_v);
  char lat_text[40];
  std::snprintf(lat_text, sizeof lat_text, "%.17g", b.s.latitude_rad * 180.0 / M_PI);
  char height_text[40];
  std::snprintf(height_text, sizeof height_text, "%.17g", b.s.height_m);
  int rc = -1;
  const std::string out = run_calibrate(
      {"--means", (dir / "base-means.csv").string(), "--poses", (dir / "base-poses.csv").string(),
       "--latitude", lat_text, "--height", height_text, "--device-id", "sim-board-1", "--adc-lsb",
       lsb_text, "-o", (dir / "base.toml").string()},
      dir, rc);
  if (rc != 0) {
    ADD_FAILURE() << "base calibration: exit " << rc << "\n" << out;
    return {};
  }
  return dir / "base.toml";
}

/// Captures every run of `mountings` through the firmware; the --location-runs CSV (header +
/// one row per run).
std::string capture_location_runs(const std::filesystem::path& dir, const sim::Scenario& truth,
                                  const std::vector<Mounting>& mountings, double& adc_lsb) {
  std::string csv = can_tool::location_runs_header();
  for (const Mounting& m : mountings) {
    for (const double rate : kRatesRadS) {
      // Whole revolutions nearest kRunTargetSamples (what capture_rate_table_run asks for).
      const double n = static_cast<double>(
          can_tool::whole_revolution_samples(rate, truth.rate_hz, kRunTargetSamples));
      const double duration = n / truth.rate_hz + 2.0;
      const auto scen = dir / ("m" + std::to_string(m.number) + "-r" +
                               std::to_string(static_cast<int>(rate)) + ".toml");
      write(scen, rate_table_scenario(truth, m, rate, duration));
      Board b(dir / "none.toml", {}, scen.string());
      EXPECT_EQ(b.s.trajectory.kind, "rate_table");
      SequenceOptions o = b.options();
      o.samples = static_cast<std::uint16_t>(kRunTargetSamples);
      adc_lsb = o.adc_lsb_v;
      std::uint8_t token = 1;
      const can_tool::RateTableCapture c = can_tool::capture_rate_table_run(
          *b.host_bus, can_tool::RateTableRun{m.number, m.up_b, rate}, o, token);
      if (!c.ok) {
        ADD_FAILURE() << c.error;
        return {};
      }
      // Whole turns: N·ω/(2π f_s) within half a sample's angle of a whole number (>= 1) of turns.
      const double per_sample_turns = rate / (2.0 * M_PI * truth.rate_hz);
      const double turns = static_cast<double>(c.samples) * per_sample_turns;
      EXPECT_GE(turns, 1.0);
      EXPECT_LE(std::abs(turns - std::round(turns)), 0.5 * per_sample_turns);
      EXPECT_EQ(c.result.channels[0].count, c.samples);
      // A constant rotation about the vertical is a constant specific force in body axes: the
      // firmware's static-pose motion flag must not fire.
      EXPECT_EQ(c.note, "");
      csv += c.row;
    }
  }
  return csv;
}

struct LocationCheck {
  double max_z = 0;
  std::string worst;
};
LocationCheck compare_location(const calib_file::CalibrationData& d, const sim::Scenario& s) {
  LocationCheck c;
  for (std::size_t j = 0; j < 6; ++j) {
    for (std::size_t k = 0; k < 3; ++k) {
      const double est = d.sensors[j].location_error_m[k];
      const double truth = s.misalignment.drho_b[j](static_cast<Eigen::Index>(k));
      const double sigma = d.sensors[j].location_error_sigma_m[k];
      const double z = std::abs(est - truth) / sigma;
      if (!(z <= c.max_z)) {
        c.max_z = std::isfinite(z) ? z : 1e300;
        c.worst = "a" + std::to_string(j + 1) + " axis " + std::to_string(k) + ": estimated " +
                  std::to_string(est * 1e3) + " mm, true " + std::to_string(truth * 1e3) +
                  " mm, 1σ " + std::to_string(sigma * 1e3) + " mm";
      }
    }
  }
  return c;
}

TEST(FirmwareCalibration, LocationErrorsFromRateTableRunsCapturedThroughTheFirmware) {
  TempDir dir;
  const auto loaded = sim::load_scenario("calibration-board", GFINS_SCENARIO_DIR);
  ASSERT_TRUE(loaded.is_ok()) << loaded.error().message;
  const sim::Scenario& truth = loaded.value();
  const double g_local =
      nav::GravityModel<double>::normal(truth.latitude_rad, truth.height_m).magnitude_at_origin();

  // 1. The base (orientation) calibration through the firmware, then the runs of all five
  // mountings through the firmware's capture command.
  const std::filesystem::path base_file = base_through_firmware(dir.path);
  ASSERT_FALSE(base_file.empty());
  const auto base = calib_file::load_calibration_file(base_file);
  ASSERT_TRUE(base.is_ok()) << base.status().message();
  EXPECT_TRUE(base.value().correlations_known);
  // The site the runs are simulated at (the same WGS-84 normal gravity, 17 digits on both sides).
  EXPECT_NEAR(base.value().gravity_mps2, g_local, 1e-9);
  double adc_lsb = 0;
  const std::vector<Mounting> all(kMountings.begin(), kMountings.end());
  const std::string csv = capture_location_runs(dir.path, truth, all, adc_lsb);
  ASSERT_FALSE(csv.empty());
  write(dir.path / "runs.csv", csv);

  // 2. gfins-calibrate solves Δρ on top of the base calibration.
  int rc = -1;
  std::string out = run_calibrate({"--location-runs", (dir.path / "runs.csv").string(), "--base",
                                   base_file.string(), "-o", (dir.path / "loc.toml").string()},
                                  dir.path, rc);
  ASSERT_EQ(rc, 0) << out;
  std::printf("%s", out.c_str());
  const auto solved = calib_file::load_calibration_file(dir.path / "loc.toml");
  ASSERT_TRUE(solved.is_ok()) << solved.status().message();
  const LocationCheck c = compare_location(solved.value(), truth);
  std::printf("location through the firmware: largest |est - true|/sigma %.2f (%s)\n", c.max_z,
              c.worst.c_str());
  EXPECT_LE(c.max_z, kLocationSigmas) << c.worst << "\n" << out;
  EXPECT_NE(out.find("and the base calibration's uncertainty"), std::string::npos) << out;
  // The full 3×3 covariance per sensor: the tool's own computation on the same inputs (the file
  // keeps the diagonal, checked equal below), then χ² of the truth against it.
  const auto rows = tools::read_location_runs(dir.path / "runs.csv");
  ASSERT_TRUE(rows.is_ok()) << rows.error().message;
  const auto rep = tools::run_location_calibration(rows.value(), base.value(), 1e-3, "runs.csv");
  ASSERT_TRUE(rep.is_ok()) << rep.error().message;
  double chi2 = 0.0;
  double chi2_runs = 0.0;
  double max_z_runs = 0.0;
  double z2_sum = 0.0;       // per component, against the file's σ
  double z2_runs_sum = 0.0;  // per component, against the runs' σ alone
  for (std::size_t j = 0; j < 6; ++j) {
    const Eigen::Matrix3d runs_cov = rep.value().solution.drho_cov_m2[j];
    const Eigen::Matrix3d total = runs_cov + rep.value().base_cov_m2[j];
    Eigen::Vector3d e;
    for (std::size_t k = 0; k < 3; ++k) {
      const auto kk = static_cast<Eigen::Index>(k);
      e(kk) = solved.value().sensors[j].location_error_m[k] - truth.misalignment.drho_b[j](kk);
      // The file's σ is the square root of this covariance's diagonal (the same computation).
      EXPECT_NEAR(solved.value().sensors[j].location_error_sigma_m[k], std::sqrt(total(kk, kk)),
                  1e-9 * std::sqrt(total(kk, kk)));
      const double z_runs = e(kk) / std::sqrt(runs_cov(kk, kk));
      const double z = e(kk) / solved.value().sensors[j].location_error_sigma_m[k];
      max_z_runs = std::max(max_z_runs, std::abs(z_runs));
      z2_runs_sum += z_runs * z_runs;
      z2_sum += z * z;
    }
    chi2 += e.dot(total.ldlt().solve(e));
    chi2_runs += e.dot(runs_cov.ldlt().solve(e));
  }
  std::printf(
      "base through the firmware: chi2 of the 18 components %.2f (chi2/dof %.3f; mean z^2 per "
      "component %.3f, worst |z| %.2f) against the stated covariance (runs + base); %.2f "
      "(chi2/dof %.3f; mean z^2 %.3f, worst |z| %.2f) against the runs' noise alone\n",
      chi2, chi2 / 18.0, z2_sum / 18.0, c.max_z, chi2_runs, chi2_runs / 18.0, z2_runs_sum / 18.0,
      max_z_runs);
  EXPECT_GE(chi2, kChi2Low) << out;
  EXPECT_LE(chi2, kChi2High) << out;
  // Optional data for docs/figures/location-sigma.png (scripts/plot_location_sigma.py).
  if (const char* fig = std::getenv("GFINS_CAL_E2E_OUT"); fig != nullptr) {
    std::ofstream f(std::filesystem::path(fig) / "location_z.csv");
    f << "component,z_runs,z_total,chi2_runs,chi2_total\n";
    for (std::size_t j = 0; j < 6; ++j) {
      const Eigen::Matrix3d runs_cov = rep.value().solution.drho_cov_m2[j];
      for (std::size_t k = 0; k < 3; ++k) {
        const auto kk = static_cast<Eigen::Index>(k);
        const double e =
            solved.value().sensors[j].location_error_m[k] - truth.misalignment.drho_b[j](kk);
        f << "a" << j + 1 << "xyz"[k] << "," << e / std::sqrt(runs_cov(kk, kk)) << ","
          << e / solved.value().sensors[j].location_error_sigma_m[k] << "," << chi2_runs << ","
          << chi2 << "\n";
      }
    }
  }
  // Every component observed: no sensor names an unobservable direction.
  EXPECT_EQ(out.find("direction(s)"), std::string::npos) << out;

  // 3. Runs about x, y and z only: each sensor's radial direction is named unobservable
  // (docs/calibration.md §5: Table 1's axis has no component along its own position).
  std::string xyz_csv;
  {
    std::istringstream in(csv);
    std::string line;
    while (std::getline(in, line)) {
      if (line.rfind("3,", 0) == 0 || line.rfind("4,", 0) == 0) continue;  // the diagonals
      xyz_csv += line + "\n";
    }
  }
  write(dir.path / "runs-xyz.csv", xyz_csv);
  out =
      run_calibrate({"--location-runs", (dir.path / "runs-xyz.csv").string(), "--base",
                     (dir.path / "base.toml").string(), "-o", (dir.path / "loc-xyz.toml").string()},
                    dir.path, rc);
  ASSERT_EQ(rc, 0) << out;
  for (int j = 1; j <= 6; ++j) {
    const auto at = out.find("\na" + std::to_string(j) + " ");
    ASSERT_NE(at, std::string::npos) << out;
    const std::string row = out.substr(at + 1, out.find('\n', at + 1) - at - 1);
    EXPECT_NE(row.find("1 direction(s)"), std::string::npos) << row;
  }

  // 4. A deliberate error: rows stating 5 % more rate than the table turned. The nominal
  // centripetal term ω²ρ (0.1 m) then misfits by 10 % of up to 10 m/s², thousands of σ: the
  // recovered Δρ is far from the truth.
  std::string wrong;
  {
    std::istringstream in(csv);
    std::string line;
    std::getline(in, line);
    wrong = line + "\n";
    while (std::getline(in, line)) {
      std::vector<std::string> f;
      std::stringstream ls(line);
      std::string cell;
      while (std::getline(ls, cell, ',')) f.push_back(cell);
      f[4] = std::to_string(std::stod(f[4]) * 1.05);
      for (std::size_t i = 0; i < f.size(); ++i) wrong += (i ? "," : "") + f[i];
      wrong += "\n";
    }
  }
  write(dir.path / "runs-wrong.csv", wrong);
  out = run_calibrate(
      {"--location-runs", (dir.path / "runs-wrong.csv").string(), "--base",
       (dir.path / "base.toml").string(), "-o", (dir.path / "loc-wrong.toml").string()},
      dir.path, rc);
  ASSERT_EQ(rc, 0) << out;  // the tool cannot know the table's rate: the oracle must catch it
  const auto bad = calib_file::load_calibration_file(dir.path / "loc-wrong.toml");
  ASSERT_TRUE(bad.is_ok()) << bad.status().message();
  const LocationCheck w = compare_location(bad.value(), truth);
  std::printf("rows with a 5 %% rate error: largest |est - true|/sigma %.3g (%s)\n", w.max_z,
              w.worst.c_str());
  EXPECT_GT(w.max_z, kLocationSigmas) << out;
}

}  // namespace
}  // namespace gfins
