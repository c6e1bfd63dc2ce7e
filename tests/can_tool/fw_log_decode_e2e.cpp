// The must-show, end to end with the real programs: `gfins-fw --sim` writes a candump log
// (--can-log), `gfins-can decode --view csv` decodes it, and every decoded navigation value
// equals a host-only run of the navigation core on the same scenario's samples within that
// signal's quantisation step; gfins-can's summary shows continuous counters and valid CRCs.
//
// Independent of the code under test: the steps and limits are read from the committed DBC text
// (docs/can/gfins.dbc, "SG_ name : start|len@1± (factor,offset) [min|max]"), the default output
// dividers and the quaternion/Euler conventions are written here from docs/can-interface.md, and
// the reference is NavPipeline<float>::process() on the samples of host_sim's sample source
// through the ADC chip model (the firmware's start-up configuration, not its loop or publisher).
// A negative control runs the same comparison against a core with another compensator and
// requires it to fail: the comparison can tell a wrong state from a right one.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <numbers>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "gfins/app/config.hpp"
#include "gfins/app/startup.hpp"
#include "gfins/host_sim/board/sim_board.hpp"
#include "gfins/host_sim/scenario.hpp"
#include "gfins/nav_core/pipeline.hpp"
#include "support/cli_fixture.hpp"
#include "support/csv.hpp"

namespace gfins {
namespace {

// ---- The run ----------------------------------------------------------------------------------

constexpr const char* kScenario = "maneuver";  // 6-DoF motion: every signal moves
constexpr int kSeconds = 4;
constexpr double kHeadingDeg = 30.0;  // non-zero, so the initial heading must be carried
constexpr int kRateHz = 1000;         // the scenario's rate = the firmware's adc.sample_rate_hz
constexpr std::uint32_t kSamples = kSeconds * kRateHz + 1;  // seq 0 .. 4000

// Default dividers (docs/can-interface.md, "Rates, dividers and bus load"): a message is in the
// epoch of sample seq when seq % divider == 0.
constexpr std::uint32_t kEpochDivider = 10;
const std::map<std::string, std::uint32_t> kDividerOf = {
    {"TimeUs", 10}, {"SampleCount", 10}, {"Qw", 10},      {"Qx", 10},      {"Qy", 10},
    {"Qz", 10},     {"Roll", 20},        {"Pitch", 20},   {"Yaw", 20},     {"RateX", 10},
    {"RateY", 10},  {"RateZ", 10},       {"AngAccX", 20}, {"AngAccY", 20}, {"AngAccZ", 20},
    {"AccelX", 10}, {"AccelY", 10},      {"AccelZ", 10},  {"VelN", 10},    {"VelE", 10},
    {"VelD", 10},   {"PosN", 10},        {"PosE", 10},    {"PosD", 10}};

// The CSV prints each value with %.10g (docs/can-interface.md, views): a relative rounding of at
// most 5e-10; 1e-9 of the value covers it and is far below any step (1e-4 rad of 3 rad is 3e-5).
constexpr double kPrintRelative = 1e-9;
// The two Euler computations (the firmware's and this test's, both from the same float
// quaternion in double) differ by a few double ulps: 1e-9 rad, 1e-5 of the 1e-4 rad step.
constexpr double kEulerFormulaRad = 1e-9;

// ---- The DBC, read as text --------------------------------------------------------------------

struct Step {
  double factor = 0, min = 0, max = 0;
};

std::map<std::string, Step> dbc_steps(const std::string& path) {
  std::ifstream f(path);
  std::map<std::string, Step> out;
  std::string line;
  while (std::getline(f, line)) {
    // " SG_ Roll : 0|16@1- (0.0001,0) [-3.1416|3.1416] "rad" HOST"
    std::istringstream in(line);
    std::string tag, name, colon, layout;
    if (!(in >> tag >> name >> colon >> layout) || tag != "SG_" || colon != ":") continue;
    Step s;
    char c = 0;
    double offset = 0;
    in >> c >> s.factor >> c >> offset >> c >> c >> s.min >> c >> s.max;
    if (in && offset == 0) out[name] = s;
  }
  return out;
}

// ---- The decoded CSV --------------------------------------------------------------------------

using Table = test::DecodedTable;

// ---- The host-only core run -------------------------------------------------------------------

struct HostRun {
  std::map<std::uint32_t, nav::NavState<float>> at_seq;  // the core's state after sample seq
  std::string error;
  std::set<std::uint32_t> aligning;  // samples after which the core was still aligning
};

HostRun failed(std::string why) {
  HostRun r;
  r.error = std::move(why);
  return r;
}

/// The samples gfins-fw --sim reads (host_sim's sample source → ADS131M06 model → real driver,
/// sample k at t = k · 1 ms), through the core configured as the firmware's start-up configures
/// it with --calibration "" on the simulated board (its factory calibration, the scenario's).
/// `compensator_override`: the negative control.
HostRun host_core_run(const nav::CompensatorKind* compensator_override) {
  HostRun out;
  auto parsed = sim::load_scenario(kScenario, GFINS_SCENARIO_DIR);
  if (!parsed.is_ok()) return failed(parsed.error().message);
  const sim::Scenario& s = parsed.value();
  auto stream = sim_board::make_scenario_stream(s);
  if (!stream.is_ok()) return failed(stream.error().message);
  sim_board::ChipAdc adc(s.rate_hz);
  if (!adc.start().is_ok()) return failed("chip model did not start");

  app::FwConfig fc;
  fc.calibration_file.clear();
  fc.heading_deg = kHeadingDeg;
  const calib_file::CalibrationData factory =
      sim_board::scenario_calibration(s, adc.volts_per_count());
  const app::StartupCalibration cal = app::load_calibration(fc, factory, &factory);
  const app::LoopOptions lo = app::loop_options(fc);
  nav::PipelineConfig<float> cfg = cal.set.config;
  cfg.sample_rate_hz = static_cast<float>(lo.sample_rate_hz);
  cfg.heading_rad = lo.initial_heading_rad;
  cfg.r0_n = lo.initial_position_n;
  if (compensator_override != nullptr) cfg.compensator = *compensator_override;
  auto pipe = std::make_unique<nav::NavPipeline<float>>();
  if (!pipe->configure(cfg).is_ok()) return failed("pipeline configuration refused");
  for (std::uint32_t k = 0; k < kSamples; ++k) {
    const auto t_ns = static_cast<std::int64_t>(k) * (1'000'000'000 / kRateHz);
    auto r = adc.convert(stream.value()->volts(k), k, t_ns);
    if (!r.is_ok()) return failed("sample " + std::to_string(k) + ": " + r.status().message());
    pipe->process(r.value());
    if (k % kEpochDivider == 0) {
      nav::NavState<float> n = pipe->state();
      n.t_ns = t_ns;
      n.seq = k;
      out.at_seq[k] = n;
      if (pipe->phase() != nav::PipelinePhase::kNavigating) out.aligning.insert(k);
    }
  }
  return out;
}

/// The value the ICD says a signal carries for state n (docs/can-interface.md, Messages).
double expected(const std::string& name, const nav::NavState<float>& n) {
  const auto d = [](float v) { return static_cast<double>(v); };
  // The bus carries the quaternion with w >= 0 (q and -q are one attitude).
  const double qs = n.q_nb.w() < 0 ? -1.0 : 1.0;
  const double w = qs * d(n.q_nb.w()), x = qs * d(n.q_nb.x()), y = qs * d(n.q_nb.y()),
               z = qs * d(n.q_nb.z());
  static const std::map<std::string, int> kAxis = {
      {"RateX", 0},   {"RateY", 1},  {"RateZ", 2},  {"AngAccX", 0}, {"AngAccY", 1},
      {"AngAccZ", 2}, {"AccelX", 0}, {"AccelY", 1}, {"AccelZ", 2},  {"VelN", 0},
      {"VelE", 1},    {"VelD", 2},   {"PosN", 0},   {"PosE", 1},    {"PosD", 2}};
  if (name == "TimeUs") return static_cast<double>(static_cast<std::uint32_t>(n.t_ns / 1000));
  if (name == "SampleCount") return static_cast<double>(n.seq & 0xFFFFu);
  if (name == "Qw") return w;
  if (name == "Qx") return x;
  if (name == "Qy") return y;
  if (name == "Qz") return z;
  // ZYX Euler angles of q_nb (roll, pitch, yaw), the aerospace formulas.
  if (name == "Roll") return std::atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y));
  if (name == "Pitch") return std::asin(std::clamp(2 * (w * y - z * x), -1.0, 1.0));
  if (name == "Yaw") return std::atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z));
  const int i = kAxis.at(name);
  if (name.starts_with("Rate")) return d(n.w_b(i));
  if (name.starts_with("AngAcc")) return d(n.wdot_b(i));
  if (name.starts_with("Accel")) return d(n.f_b(i));
  if (name.starts_with("Vel")) return d(n.v_n(i));
  return d(n.r_n(i));
}

struct Comparison {
  std::size_t values = 0, outside = 0, missing = 0, unknown_rows = 0;
  std::size_t not_available = 0;  // navigation values sent as not available while aligning
  std::map<std::string, double> worst_steps;
  std::string first_outside;
};

Comparison compare(const Table& t, const std::map<std::string, Step>& steps, const HostRun& host) {
  Comparison c;
  const int sc = t.col("SampleCount");
  for (const auto& row : t.rows) {
    if (sc < 0 || row.size() != t.names.size()) {
      ++c.unknown_rows;
      continue;
    }
    // 4000 samples: SampleCount (seq mod 2^16) is seq itself.
    const auto seq = static_cast<std::uint32_t>(std::stoul(row[static_cast<std::size_t>(sc)]));
    const auto it = host.at_seq.find(seq);
    if (it == host.at_seq.end()) {
      ++c.unknown_rows;
      continue;
    }
    for (const auto& [name, divider] : kDividerOf) {
      if (seq % divider != 0) continue;  // not due in this epoch
      const std::string& cell = row[static_cast<std::size_t>(t.col(name))];
      // While the core aligns there is no navigation value: every navigation signal goes out as
      // not available (an empty cell), never an identity quaternion or a zero.
      const bool nav_signal = name != "TimeUs" && name != "SampleCount";
      if (nav_signal && host.aligning.count(seq) != 0) {
        if (cell.empty()) {
          ++c.not_available;
        } else if (c.outside++ == 0) {
          c.first_outside = name + " at seq " + std::to_string(seq) + ": decoded " + cell +
                            " while aligning (expected not available)";
        }
        continue;
      }
      if (cell.empty()) {
        ++c.missing;
        continue;
      }
      const Step& s = steps.at(name);
      const double got = std::stod(cell);
      const double want = std::clamp(expected(name, it->second), s.min, s.max);
      const double tol =
          0.5 * s.factor + kPrintRelative * std::abs(want) +
          (name == "Roll" || name == "Pitch" || name == "Yaw" ? kEulerFormulaRad : 0);
      const double diff = std::abs(got - want);
      c.worst_steps[name] = std::max(c.worst_steps[name], diff / s.factor);
      ++c.values;
      if (diff > tol) {
        if (c.outside++ == 0) {
          c.first_outside = name + " at seq " + std::to_string(seq) + ": decoded " + cell +
                            ", core " + std::to_string(want);
        }
      }
    }
  }
  return c;
}

// ---- The test ---------------------------------------------------------------------------------

class FwLogDecode : public test::CliTest {};

TEST_F(FwLogDecode, EveryDecodedSignalEqualsTheHostCoreWithinItsStep) {
  // Given the steps of the committed DBC
  const auto steps = dbc_steps(GFINS_DBC);
  for (const auto& [name, divider] : kDividerOf) {
    ASSERT_TRUE(steps.contains(name)) << name << " not in " << GFINS_DBC;
  }
  EXPECT_EQ(steps.at("Roll").factor, 1e-4);  // the ICD's Euler step, rad: the parser works
  EXPECT_EQ(steps.at("PosN").factor, 0.01);

  // When gfins-fw --sim writes its candump log and gfins-can decodes it
  const std::string log = path("fw.log"), csv = path("fw.csv");
  const auto fw = run(GFINS_FW_EXE, {"--sim", kScenario, "--scenario-dir", GFINS_SCENARIO_DIR,
                                     "--calibration", "", "--heading-deg", "30", "--can-log", log,
                                     "--duration", std::to_string(kSeconds), "--watchdog", "none"});
  ASSERT_EQ(fw.exit_code, 0) << fw.output;
  const auto dec = run(GFINS_CAN_EXE, {"decode", log, "--view", "csv", "-o", csv});
  ASSERT_EQ(dec.exit_code, 0) << dec.output;
  const Table t = test::read_decoded_csv(test::slurp(csv));

  // Then gfins-can's summary: every epoch, every frame ok, no problem at all (no bad CRC, no
  // counter jump, no drop, duplicate or reorder). Frame counts from the default dividers:
  // 401 epochs (seq 0, 10, ..., 4000), 201 at divider 20, 5 frames of each 1 Hz message (two
  // health, the command counters; seq 0, 1000, ...).
  constexpr int kEpochs = kSamples / kEpochDivider + 1;
  constexpr int kHalfRate = kSamples / 20 + 1, kHealth = kSeconds + 1;
  constexpr int kFrames = 8 * kEpochs + 2 * kHalfRate + 3 * kHealth;
  const std::string f = std::to_string(kFrames);
  EXPECT_NE(dec.err.find("summary: " + f + " lines, " + f + " frames (" + f + " ok), " +
                         std::to_string(kEpochs) + " epochs, 0 commands, 0 responses, 0 problems"),
            std::string::npos)
      << dec.err;
  EXPECT_NE(dec.err.find("GfinsEpoch=" + std::to_string(kEpochs) +
                         " GfinsStatus=" + std::to_string(kEpochs)),
            std::string::npos)
      << dec.err;
  EXPECT_NE(dec.err.find("GfinsEuler=" + std::to_string(kHalfRate)), std::string::npos) << dec.err;
  ASSERT_EQ(t.rows.size(), static_cast<std::size_t>(kEpochs));

  // ... and every navigation value equals the host-only core run within its step
  const HostRun host = host_core_run(nullptr);
  ASSERT_TRUE(host.error.empty()) << host.error;
  const Comparison c = compare(t, steps, host);
  EXPECT_EQ(c.unknown_rows, 0u);
  EXPECT_EQ(c.missing, 0u) << "a message due in an epoch was not decoded";
  EXPECT_EQ(c.outside, 0u) << c.first_outside;
  // 401 epochs × (time 2 + quaternion 4 + rate 3 + accel 3 + velocity 3 + position 3 = 18)
  // + 201 × (Euler 3 + angular acceleration 3) values
  // (values compared, or sent as not available while the core aligned: 16 of the 18 per epoch
  // and all 6 of the half-rate ones; the alignment takes the first second)
  EXPECT_EQ(c.values + c.not_available, static_cast<std::size_t>(kEpochs * 18 + kHalfRate * 6));
  EXPECT_GT(c.not_available, 0u) << "the run aligned first: its epochs carry no navigation value";
  double worst = 0;
  for (const auto& [name, steps_off] : c.worst_steps) worst = std::max(worst, steps_off);
  std::printf(
      "fw-log e2e: %zu values compared, %zu outside their step, largest difference %.3f "
      "step(s)\n",
      c.values, c.outside, worst);
  // The run moved: the comparison is not of zeros (maneuver: metres and tens of degrees).
  const int pn = t.col("PosN"), yaw = t.col("Yaw");
  double max_pos = 0, max_yaw = 0;
  for (const auto& row : t.rows) {
    if (!row[static_cast<std::size_t>(pn)].empty())
      max_pos = std::max(max_pos, std::abs(std::stod(row[static_cast<std::size_t>(pn)])));
    if (!row[static_cast<std::size_t>(yaw)].empty())
      max_yaw = std::max(max_yaw, std::abs(std::stod(row[static_cast<std::size_t>(yaw)])));
  }
  EXPECT_GT(max_pos, 0.1);                                           // m
  EXPECT_GT(max_yaw, kHeadingDeg * std::numbers::pi / 180.0 * 0.5);  // rad

  // Negative control: the same comparison against a core with no compensation (the scenario's
  // array is misaligned, Table 6) must find values outside their step.
  const nav::CompensatorKind none = nav::CompensatorKind::kNone;
  const HostRun wrong = host_core_run(&none);
  ASSERT_TRUE(wrong.error.empty()) << wrong.error;
  const Comparison cw = compare(t, steps, wrong);
  EXPECT_GT(cw.outside, cw.values / 10) << "the comparison cannot tell another compensator";
  std::printf(
      "fw-log e2e, negative control (compensator none): %zu of %zu values outside their "
      "step (first: %s)\n",
      cw.outside, cw.values, cw.first_outside.c_str());
}

// A board with its identifier groups moved (can.*_id_base; docs/can-interface.md,
// "Identifiers"): everything it sends is at the moved identifiers, written out here from the
// bases and the ICD's offsets (GfinsEpoch 0x300 + node 1 = 0x301, GfinsCommandCounters 0x400 +
// 1); gfins-can finds its epochs only with the board's configuration, and the DBC made from that
// configuration names the moved identifiers.
TEST_F(FwLogDecode, AMovedBoardIsDecodedWithItsConfiguration) {
  const std::string cfg = path("moved.toml"), log = path("moved.log"), dbc = path("moved.dbc");
  {
    std::ofstream f(cfg);
    f << "[can]\ndata_id_base = 0x300\ninput_id_base = 0x2A0\ncommand_id_base = 0x700\n"
         "response_id_base = 0x710\nreserved_ids = [[0x600, 0x60F]]\n";
  }
  const auto fw = run(GFINS_FW_EXE, {"--config", cfg, "--sim", "rest", "--scenario-dir",
                                     GFINS_SCENARIO_DIR, "--calibration", "", "--can-log", log,
                                     "--duration", "2", "--watchdog", "none"});
  ASSERT_EQ(fw.exit_code, 0) << fw.output;
  // candump lines: "(seconds.micros) iface ID#DATA".
  std::set<unsigned> ids;
  std::istringstream lines(test::slurp(log));
  for (std::string line; std::getline(lines, line);) {
    const auto sp = line.find(' ', line.find(' ') + 1);
    const auto hash = line.find('#');
    ASSERT_NE(hash, std::string::npos) << line;
    ids.insert(static_cast<unsigned>(std::stoul(line.substr(sp + 1, hash - sp - 1), nullptr, 16)));
  }
  ASSERT_FALSE(ids.empty());
  EXPECT_TRUE(ids.contains(0x301)) << "GfinsEpoch of node 1 at 0x300 + 1";
  EXPECT_TRUE(ids.contains(0x401)) << "GfinsCommandCounters at 0x300 + 0x100 + 1";
  for (const unsigned id : ids) {
    EXPECT_TRUE(id >= 0x301 && id <= 0x40F) << std::hex << "0x" << id << " outside the data group";
  }
  // Without the configuration these are no gfins frames: not one epoch.
  const auto blind = run(GFINS_CAN_EXE, {"decode", log, "--view", "none"});
  EXPECT_NE(blind.err.find(" 0 epochs,"), std::string::npos) << blind.err;
  // With it, every epoch (2 s at divider 10: seq 0, 10, ..., 2000) and no problem.
  const auto dec = run(GFINS_CAN_EXE, {"decode", log, "--config", cfg, "--view", "none"});
  EXPECT_EQ(dec.exit_code, 0) << dec.err;
  EXPECT_NE(dec.err.find(" 201 epochs,"), std::string::npos) << dec.err;
  EXPECT_NE(dec.err.find(" 0 problems"), std::string::npos) << dec.err;
  // The DBC of that board: BO_ <decimal id> <name>: ...
  const auto gen = run(GFINS_CAN_EXE, {"dbc", "--config", cfg, "-o", dbc});
  ASSERT_EQ(gen.exit_code, 0) << gen.err;
  const std::string text = test::slurp(dbc);
  for (const char* bo : {"BO_ 769 GfinsEpoch:", "BO_ 1025 GfinsCommandCounters:",
                         "BO_ 1793 GfinsCommand:", "BO_ 1809 GfinsResponse:"}) {
    EXPECT_NE(text.find(bo), std::string::npos) << bo;
  }
  // gfins-can plot reads the log through the same configuration.
  const auto plot = run(GFINS_CAN_EXE, {"plot", log, "--config", cfg, "-o", path("moved.png")});
  EXPECT_EQ(plot.exit_code, 0) << plot.err;
  // A configuration whose groups overlap is refused by gfins-can as by the firmware.
  {
    std::ofstream f(cfg);
    f << "[can]\ncommand_id_base = 0x200\n";
  }
  const auto bad = run(GFINS_CAN_EXE, {"decode", log, "--config", cfg});
  EXPECT_EQ(bad.exit_code, 2) << bad.err;
  EXPECT_NE(bad.err.find("can.command_id_base = 0x200"), std::string::npos) << bad.err;
}

// A board mounted rotated in the vehicle (navigation.mounting_rpy_deg; docs/firmware.md,
// "Mounting"): the same drive is published once in the board's frame and once in the vehicle's,
// and each mounted value equals the rotation of the unmounted one, written out here from the
// textbook ZYX direction cosine matrix and the quaternion product (not the firmware's code):
// ω_v = C_vb ω_b for the rate, angular acceleration and specific force, q_nv = q_nb ⊗ q_vb* for
// the attitude; velocity and position (NED) do not change. Tolerance: each side carries half a
// step of quantisation per component, so a rotated component may be off by
// (Σ_j |C_ij| + 1) / 2 steps (a quaternion: (Σ |q_vb| + 1) / 2 steps); a mounting applied the
// wrong way round (C_bv for C_vb, q_vb for q_vb*) is off by up to the full value.
TEST_F(FwLogDecode, AMountedBoardPublishesTheVehiclesAxes) {
  constexpr double kRollDeg = 10.0, kPitchDeg = -20.0, kYawDeg = 90.0;
  const std::string plain = path("plain.log"), mounted = path("mounted.log");
  const std::string cfg =
      file("mounted.toml", "[navigation]\nmounting_rpy_deg = [10.0, -20.0, 90.0]\n");
  const std::vector<std::string> common = {
      "--sim",         kScenario, "--scenario-dir", GFINS_SCENARIO_DIR,
      "--calibration", "",        "--duration",     "2",
      "--watchdog",    "none"};
  auto args = common;
  args.insert(args.end(), {"--can-log", plain});
  ASSERT_EQ(run(GFINS_FW_EXE, args).exit_code, 0);
  args = common;
  args.insert(args.end(), {"--config", cfg, "--can-log", mounted});
  const auto fw = run(GFINS_FW_EXE, args);
  ASSERT_EQ(fw.exit_code, 0) << fw.output;
  const auto table = [this](const std::string& log, const std::string& name) {
    const auto dec = run(GFINS_CAN_EXE, {"decode", log, "--view", "csv", "-o", path(name)});
    EXPECT_EQ(dec.exit_code, 0) << dec.output;
    return test::read_decoded_csv(test::slurp(path(name)));
  };
  const Table b = table(plain, "plain.csv"), v = table(mounted, "mounted.csv");
  ASSERT_EQ(b.rows.size(), v.rows.size());
  ASSERT_GT(b.rows.size(), 150u);
  const auto steps = dbc_steps(GFINS_DBC);

  // C_vb = Rz(ψ) Ry(θ) Rx(φ), and its quaternion.
  const double r = kRollDeg * std::numbers::pi / 180, p = kPitchDeg * std::numbers::pi / 180,
               y = kYawDeg * std::numbers::pi / 180;
  const double cr = std::cos(r), sr = std::sin(r), cp = std::cos(p), sp = std::sin(p),
               cy = std::cos(y), sy = std::sin(y);
  const double c[3][3] = {{cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr},
                          {sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr},
                          {-sp, cp * sr, cp * cr}};
  const double m[4] = {std::cos(r / 2) * std::cos(p / 2) * std::cos(y / 2) +
                           std::sin(r / 2) * std::sin(p / 2) * std::sin(y / 2),
                       std::sin(r / 2) * std::cos(p / 2) * std::cos(y / 2) -
                           std::cos(r / 2) * std::sin(p / 2) * std::sin(y / 2),
                       std::cos(r / 2) * std::sin(p / 2) * std::cos(y / 2) +
                           std::sin(r / 2) * std::cos(p / 2) * std::sin(y / 2),
                       std::cos(r / 2) * std::cos(p / 2) * std::sin(y / 2) -
                           std::sin(r / 2) * std::sin(p / 2) * std::cos(y / 2)};
  const auto cell = [](const Table& t, std::size_t row, const std::string& n, double& out) {
    const int i = t.col(n);
    if (i < 0 || t.rows[row][static_cast<std::size_t>(i)].empty()) return false;
    out = std::stod(t.rows[row][static_cast<std::size_t>(i)]);
    return true;
  };
  std::size_t compared = 0, outside = 0;
  std::string first;
  const auto check = [&](const std::string& n, double want, double got, double steps_allowed) {
    ++compared;
    const double step = steps.at(n).factor;
    if (std::abs(got - want) > steps_allowed * step * (1 + 1e-9) && outside++ == 0) {
      first = n + ": mounted " + std::to_string(got) + ", rotated " + std::to_string(want);
    }
  };
  for (std::size_t k = 0; k < b.rows.size(); ++k) {
    for (const char* group : {"Rate", "AngAcc", "Accel"}) {
      double x[3];
      bool have = true;
      for (int j = 0; j < 3; ++j) have = have && cell(b, k, group + std::string(1, "XYZ"[j]), x[j]);
      if (!have) continue;
      for (int i = 0; i < 3; ++i) {
        const std::string n = group + std::string(1, "XYZ"[i]);
        double got = 0;
        if (!cell(v, k, n, got)) continue;
        const double want = c[i][0] * x[0] + c[i][1] * x[1] + c[i][2] * x[2];
        check(n, want, got, (std::abs(c[i][0]) + std::abs(c[i][1]) + std::abs(c[i][2]) + 1) / 2);
      }
    }
    double q[4];
    bool have = true;
    for (int j = 0; j < 4; ++j) have = have && cell(b, k, std::string("Q") + "wxyz"[j], q[j]);
    if (have) {
      // q_nv = q_nb ⊗ conj(q_vb), Hamilton product, then w ≥ 0 as the bus carries it.
      const double a = q[0], bx = q[1], by = q[2], bz = q[3];
      const double w2 = m[0], x2 = -m[1], y2 = -m[2], z2 = -m[3];
      double want[4] = {a * w2 - bx * x2 - by * y2 - bz * z2, a * x2 + bx * w2 + by * z2 - bz * y2,
                        a * y2 - bx * z2 + by * w2 + bz * x2, a * z2 + bx * y2 - by * x2 + bz * w2};
      if (want[0] < 0) {
        for (double& e : want) e = -e;
      }
      const double allowed =
          (std::abs(m[0]) + std::abs(m[1]) + std::abs(m[2]) + std::abs(m[3]) + 1) / 2;
      for (int j = 0; j < 4; ++j) {
        const std::string n = std::string("Q") + "wxyz"[j];
        double got = 0;
        if (cell(v, k, n, got)) check(n, want[j], got, allowed);
      }
    }
    for (const char* n : {"VelN", "VelE", "VelD", "PosN", "PosE", "PosD"}) {
      double x = 0, got = 0;
      if (cell(b, k, n, x) && cell(v, k, n, got)) check(n, x, got, 0);
    }
  }
  // About 100 epochs after the 1 s alignment (the navigation values are not available before),
  // 16 to 19 values each.
  EXPECT_GT(compared, 1500u);
  EXPECT_EQ(outside, 0u) << "first: " << first;
  std::printf("fw-log e2e, mounted board: %zu values compared, %zu outside their tolerance\n",
              compared, outside);
}

}  // namespace
}  // namespace gfins
