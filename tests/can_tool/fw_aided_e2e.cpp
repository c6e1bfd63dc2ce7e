// Aided navigation end to end with the real programs: `gfins-fw --sim rest-qa1100 --aiding`
// writes a candump log, `gfins-can decode --view csv` decodes it, and the decoded values are
// compared with the scenario's truth (the board is at rest: every velocity component is 0). The
// same run without --aiding is the negative control: the comparison must fail it. A second test
// drives: the first minute of urban-stop-and-go, whose simulated GNSS receiver sends its fixes
// to the board as CAN input frames (bounds at that test).
//
// Bounds (the scenario: QA-1100 model at 40 °C, 0.45 mg of bias drift per sensor, 30 s):
//  - aided, |v| ≤ 0.05 m/s per axis at every epoch from 3 s on (after the 1 s alignment and the
//    first standstill windows): five times the 0.01 m/s zero-velocity update σ; unaided the
//    velocity passes 1 m/s within the 30 s (an angular-acceleration bias of ~5e-3 rad/s² turns
//    gravity into the horizontal channels), which the control checks;
//  - the filter's σ is published and honest: SigmaVelH is present at 5 Hz, within the
//    validity horizon (≤ 0.5 m/s), and the horizontal velocity error is within 4σ + one step of
//    SigmaVelH at every accuracy epoch (a Gaussian error beyond 4σ has probability 6e-5 per
//    check; the run has 140 of them, so a false failure has probability below 1 %);
//  - while the board aligns (the first second) every navigation value is not available.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "gfins/host_sim/scenario.hpp"
#include "gfins/nav_core/math.hpp"
#include "support/cli_fixture.hpp"
#include "support/csv.hpp"

namespace gfins {
namespace {

constexpr int kSeconds = 30;
constexpr double kSettleS = 3.0;
constexpr double kAidedVelMaxMps = 0.05;
constexpr double kUnaidedVelMinMps = 1.0;
constexpr double kSigmaHorizonMps = 0.5;  // the filter's default validity horizon for velocity
constexpr double kSigmaVelStep = 0.01;    // SigmaVelH's factor (docs/can/gfins.dbc)

using Table = test::DecodedTable;

struct Outcome {
  double worst_vel = 0;        // largest |v| component after the settling time, m/s
  double last_vel = 0;         // largest |v| component at the last epoch with a value
  std::size_t sigma_rows = 0;  // accuracy epochs with SigmaVelH after settling
  std::size_t sigma_outside = 0;
  double worst_sigma = 0;
  std::size_t values_while_aligning = 0;
};

class FwAided : public test::CliTest {
 protected:
  Outcome run_fw(bool aided) {
    const std::string tag = aided ? "aided" : "unaided";
    const std::string log = path(tag + ".log"), csv = path(tag + ".csv");
    std::vector<std::string> args = {"--sim",          "rest-qa1100",
                                     "--scenario-dir", GFINS_SCENARIO_DIR,
                                     "--calibration",  "",
                                     "--can-log",      log,
                                     "--duration",     std::to_string(kSeconds),
                                     "--watchdog",     "none"};
    if (aided) args.push_back("--aiding");
    const auto fw = run(GFINS_FW_EXE, args);
    EXPECT_EQ(fw.exit_code, 0) << fw.output;
    const auto dec = run(GFINS_CAN_EXE, {"decode", log, "--view", "csv", "-o", csv});
    EXPECT_EQ(dec.exit_code, 0) << dec.output;
    const Table t = test::read_decoded_csv(test::slurp(csv));
    const int ct = t.col("TimeUs"), vn = t.col("VelN"), ve = t.col("VelE"), vd = t.col("VelD"),
              sh = t.col("SigmaVelH");
    EXPECT_TRUE(ct >= 0 && vn >= 0 && ve >= 0 && vd >= 0 && sh >= 0) << "columns";
    Outcome o;
    if (ct < 0 || vn < 0 || ve < 0 || vd < 0 || sh < 0) return o;
    for (const auto& row : t.rows) {
      if (row.size() != t.names.size() || row[static_cast<std::size_t>(ct)].empty()) continue;
      const double t_s = std::stod(row[static_cast<std::size_t>(ct)]) * 1e-6;
      const std::string& n = row[static_cast<std::size_t>(vn)];
      if (t_s < 0.9) {  // aligning (1 s at rest): nothing may carry a value
        if (!n.empty()) ++o.values_while_aligning;
        continue;
      }
      if (n.empty()) continue;
      const double v[3] = {std::stod(n), std::stod(row[static_cast<std::size_t>(ve)]),
                           std::stod(row[static_cast<std::size_t>(vd)])};
      const double worst = std::max({std::abs(v[0]), std::abs(v[1]), std::abs(v[2])});
      o.last_vel = worst;
      if (t_s < kSettleS) continue;
      o.worst_vel = std::max(o.worst_vel, worst);
      const std::string& s = row[static_cast<std::size_t>(sh)];
      if (s.empty()) continue;
      const double sigma = std::stod(s);
      ++o.sigma_rows;
      o.worst_sigma = std::max(o.worst_sigma, sigma);
      if (std::hypot(v[0], v[1]) > 4.0 * sigma + kSigmaVelStep) ++o.sigma_outside;
    }
    return o;
  }
};

TEST_F(FwAided, StandstillAidingBoundsTheVelocityAndPublishesAnHonestSigma) {
  const Outcome a = run_fw(true);
  const Outcome u = run_fw(false);
  std::printf(
      "aided: worst |v| %.4f m/s, %zu accuracy epochs, worst SigmaVelH %.3f m/s; "
      "unaided: |v| %.2f m/s at %d s\n",
      a.worst_vel, a.sigma_rows, a.worst_sigma, u.last_vel, kSeconds);
  EXPECT_EQ(a.values_while_aligning, 0u);
  EXPECT_EQ(u.values_while_aligning, 0u);
  EXPECT_LE(a.worst_vel, kAidedVelMaxMps);
  EXPECT_GE(a.sigma_rows, static_cast<std::size_t>((kSeconds - kSettleS) * 5 - 2));
  EXPECT_LE(a.worst_sigma, kSigmaHorizonMps);
  EXPECT_EQ(a.sigma_outside, 0u);
  // Negative control: unaided, the velocity is lost and no σ is published.
  EXPECT_GT(u.last_vel, kUnaidedVelMinMps);
  EXPECT_EQ(u.sigma_rows, 0u);
}

// The first 60 s of urban-stop-and-go: 10 s at rest, then 12 m/s on a weaving road with a stop.
// Its receiver (5 Hz, 1.5 m / 3 m, 0.1 m/s, 100 ms latency, antenna 1 m aft 1.2 m up) sends every
// fix to the board as four input frames; the board's configuration states the lever arm. The
// decoded position and velocity are compared with the trajectory's own truth at each epoch's
// time (the scenario's analytic trajectory, not the firmware's code).
//
// Bounds, over the epochs from 12 s on (moving):
//  - horizontal position RMS per axis ≤ 1.5 m and velocity RMS per axis ≤ 0.1 m/s: the targets
//    for this receiver. The fixes alone scatter 1.5 m and 0.1 m/s per axis, so a board that
//    copied the last fix would sit at the bound on average and fail at its tails; ignoring the
//    1.56 m lever arm, the latency or the fixes altogether fails them (the control below);
//  - every epoch's horizontal position error within 4·SigmaPosH + the 0.01 m step: the σ on the
//    bus is honest (a Gaussian error beyond 4σ in a 2-D norm has probability 3.4e-4 per epoch;
//    the run has 48 accuracy epochs a second but they are strongly correlated, and the test allows
//    none);
//  - control, aiding.inputs = false (standstill updates only): once driving, the filter's σ
//    passes the validity horizon within seconds, so the board marks position not available
//    instead of publishing kilometres of error: it cannot meet the 4000 epochs of values the
//    aided run must have, and the values it does publish are within 4σ as well.
struct DriveOutcome {
  std::size_t epochs = 0;
  double rms_pos[3] = {0, 0, 0};
  double rms_vel[3] = {0, 0, 0};
  double worst_pos_h = 0;
  std::size_t sigma_rows = 0;
  std::size_t sigma_outside = 0;
  double worst_sigma_ratio = 0;
  std::uint64_t gnss_accepted = 0;
};

class FwAidedDrive : public FwAided {
 protected:
  /// `moved`: the board's data and input identifier groups moved (can.*_id_base), the scenario's
  /// receiver following them and the decoder reading the board's configuration.
  DriveOutcome run_drive(bool inputs, bool moved = false) {
    const std::string tag = std::string(inputs ? "gnss" : "standstill") + (moved ? "-moved" : "");
    const std::string cfg = file(tag + ".toml", std::string("[aiding]\nenabled = true\ninputs = ") +
                                                    (inputs ? "true" : "false") +
                                                    "\ngnss_lever_arm_m = [-1.0, 0.0, -1.2]\n" +
                                                    (moved ? "[can]\ndata_id_base = 0x300\n"
                                                             "input_id_base = 0x2A0\n"
                                                           : ""));
    const std::string log = path(tag + ".log"), csv = path(tag + ".csv");
    const auto fw = run(GFINS_FW_EXE, {"--config", cfg, "--sim", "urban-stop-and-go",
                                       "--scenario-dir", GFINS_SCENARIO_DIR, "--calibration", "",
                                       "--can-log", log, "--duration", "60", "--watchdog", "none"});
    EXPECT_EQ(fw.exit_code, 0) << fw.output;
    std::vector<std::string> decode = {"decode", log, "--view", "csv", "-o", csv};
    if (moved) decode.insert(decode.end(), {"--config", cfg});
    const auto dec = run(GFINS_CAN_EXE, decode);
    EXPECT_EQ(dec.exit_code, 0) << dec.output;
    const auto sc = sim::load_scenario("urban-stop-and-go", GFINS_SCENARIO_DIR);
    EXPECT_TRUE(sc.is_ok());
    DriveOutcome o;
    if (!sc.is_ok()) return o;
    const auto traj = sim::make_trajectory(sc.value().trajectory);
    EXPECT_TRUE(traj.is_ok());
    if (!traj.is_ok()) return o;
    const Table t = test::read_decoded_csv(test::slurp(csv));
    const char* pos_names[3] = {"PosN", "PosE", "PosD"};
    const char* vel_names[3] = {"VelN", "VelE", "VelD"};
    int cp[3], cv[3];
    for (int i = 0; i < 3; ++i) cp[i] = t.col(pos_names[i]), cv[i] = t.col(vel_names[i]);
    const int ct = t.col("TimeUs"), cs = t.col("SigmaPosH"), ca = t.col("GnssPosAccepted");
    for (int i = 0; i < 3; ++i) EXPECT_TRUE(cp[i] >= 0 && cv[i] >= 0) << "columns";
    EXPECT_TRUE(ct >= 0 && cs >= 0 && ca >= 0) << "columns";
    if (ct < 0 || cs < 0 || ca < 0 || cp[0] < 0 || cp[1] < 0 || cp[2] < 0 || cv[0] < 0 ||
        cv[1] < 0 || cv[2] < 0) {
      return o;
    }
    const auto at = [](const std::vector<std::string>& row, int c) -> const std::string& {
      return row[static_cast<std::size_t>(c)];
    };
    for (const auto& row : t.rows) {
      if (row.size() != t.names.size() || at(row, ct).empty()) continue;
      if (!at(row, ca).empty()) o.gnss_accepted = std::stoull(at(row, ca));
      const double t_s = std::stod(at(row, ct)) * 1e-6;
      if (t_s < 12.0 || at(row, cp[0]).empty() || at(row, cv[0]).empty()) continue;
      const sim::TruthState x = traj.value()->at(t_s);
      double e[3];
      for (int i = 0; i < 3; ++i) {
        e[i] = std::stod(at(row, cp[i])) - x.r_n[i];
        const double ev = std::stod(at(row, cv[i])) - x.v_n[i];
        o.rms_pos[i] += e[i] * e[i];
        o.rms_vel[i] += ev * ev;
      }
      ++o.epochs;
      const double eh = std::hypot(e[0], e[1]);
      o.worst_pos_h = std::max(o.worst_pos_h, eh);
      if (at(row, cs).empty()) continue;
      const double sigma = std::stod(at(row, cs));
      ++o.sigma_rows;
      o.worst_sigma_ratio = std::max(o.worst_sigma_ratio, eh / std::max(sigma, 1e-3));
      if (eh > 4.0 * sigma + 0.01) ++o.sigma_outside;
    }
    for (int i = 0; i < 3; ++i) {
      if (o.epochs == 0) break;
      o.rms_pos[i] = std::sqrt(o.rms_pos[i] / static_cast<double>(o.epochs));
      o.rms_vel[i] = std::sqrt(o.rms_vel[i] / static_cast<double>(o.epochs));
    }
    return o;
  }
};

TEST_F(FwAidedDrive, GnssInputFramesBoundPositionAndVelocityOnTheBus) {
  const DriveOutcome a = run_drive(true);
  const DriveOutcome c = run_drive(false);
  std::printf(
      "GNSS frames: %zu epochs, position RMS N %.3f E %.3f D %.3f m, velocity RMS N %.3f E %.3f "
      "D %.3f m/s, worst horizontal %.2f m, worst error/SigmaPosH %.2f over %zu accuracy "
      "epochs, %llu fixes accepted; standstill only: %zu epochs with a position, worst "
      "horizontal %.2f m\n",
      a.epochs, a.rms_pos[0], a.rms_pos[1], a.rms_pos[2], a.rms_vel[0], a.rms_vel[1], a.rms_vel[2],
      a.worst_pos_h, a.worst_sigma_ratio, a.sigma_rows,
      static_cast<unsigned long long>(a.gnss_accepted), c.epochs, c.worst_pos_h);
  constexpr double kPosRmsMaxM = 1.5;
  constexpr double kVelRmsMaxMps = 0.1;
  ASSERT_GT(a.epochs, 4000u);  // 48 s at 100 Hz of navigation values
  EXPECT_LE(a.rms_pos[0], kPosRmsMaxM);
  EXPECT_LE(a.rms_pos[1], kPosRmsMaxM);
  EXPECT_LE(a.rms_vel[0], kVelRmsMaxMps);
  EXPECT_LE(a.rms_vel[1], kVelRmsMaxMps);
  EXPECT_LE(a.rms_vel[2], kVelRmsMaxMps);
  EXPECT_GT(a.sigma_rows, 200u);
  EXPECT_EQ(a.sigma_outside, 0u);
  // 5 Hz for 60 s: 300 fixes sent; the first ones arrive while aligning.
  EXPECT_GE(a.gnss_accepted, 280u);
  EXPECT_LT(c.epochs, 4000u);
  EXPECT_EQ(c.sigma_outside, 0u);
  EXPECT_EQ(c.gnss_accepted, 0u);
}

// The same drive with the board's data and input groups moved (docs/can-interface.md,
// "Identifiers"): the receiver sends at the board's input identifiers and every fix is taken as
// at the stock ones (the same bounds as above; a receiver left at the stock identifiers gave 0).
TEST_F(FwAidedDrive, GnssInputFramesAtMovedIdentifiersAreTakenAsWell) {
  const DriveOutcome a = run_drive(true, true);
  ASSERT_GT(a.epochs, 4000u);
  EXPECT_LE(a.rms_pos[0], 1.5);
  EXPECT_LE(a.rms_pos[1], 1.5);
  EXPECT_EQ(a.sigma_outside, 0u);
  EXPECT_GE(a.gnss_accepted, 280u);
}

// Powered up on a moving vehicle: drive-gnss moves at 10 m/s on a weaving road from its first
// sample (turning at up to 0.2 rad/s, banked 11°), its receiver (10 Hz, 1.5 m / 3 m, 0.05 m/s,
// 60 ms latency, antenna 1 m aft 1.2 m up, an outage from 8 to 12 s) sending its fixes as input
// frames; the board is configured as a vehicle (heading from the track). The static alignment can
// never succeed; the board aligns in motion (docs/math.md, "In-motion alignment").
// Checked on the decoded log against the trajectory's own truth:
//  - before the first fix (60 ms of latency) no navigation value or σ is published, and until the
//    fixes have levelled the tilt no attitude σ is (the first 0.2 s);
//  - navigation values from 0.5 s on (a static alignment would need 1 s at rest, which never
//    comes);
//  - every fix and every track heading accepted by the filter's χ² gates: a start that levels
//    the tilt wrongly (as when the level also turned the heading, which in a turn reads the tilt
//    error as heading) has its track headings rejected from a few seconds on;
//  - from 5 s on, each epoch's horizontal position error within 4·SigmaPosH + 0.01 m and roll
//    within 4·SigmaRoll + 0.001 rad (a Gaussian beyond 4σ has probability 6e-5 in one axis and
//    3.4e-4 in a 2-D norm; the run has about 75 roll and 1,500 position checks, strongly
//    correlated, and allows none; the steps are the signals' resolution). Before 5 s the roll σ
//    is optimistic (a known limit, docs/navigation-accuracy.md).
TEST_F(FwAided, APowerUpWhileDrivingAlignsFromTheGnssFrames) {
  // Every value whose σ is on the bus is checked against it, from the first.
  const std::string cfg = file("vehicle.toml",
                               "[aiding]\nenabled = true\ntrack_heading_sigma_deg = 0.5\n"
                               "gnss_lever_arm_m = [-1.0, 0.0, -1.2]\n");
  const std::string log = path("moving.log"), csv = path("moving.csv");
  const auto fw = run(GFINS_FW_EXE, {"--config", cfg, "--sim", "drive-gnss", "--scenario-dir",
                                     GFINS_SCENARIO_DIR, "--calibration", "", "--can-log", log,
                                     "--duration", "20", "--watchdog", "none"});
  ASSERT_EQ(fw.exit_code, 0) << fw.output;
  const auto dec = run(GFINS_CAN_EXE, {"decode", log, "--view", "csv", "-o", csv});
  ASSERT_EQ(dec.exit_code, 0) << dec.output;
  const auto sc = sim::load_scenario("drive-gnss", GFINS_SCENARIO_DIR);
  ASSERT_TRUE(sc.is_ok());
  const auto traj = sim::make_trajectory(sc.value().trajectory);
  ASSERT_TRUE(traj.is_ok());
  const Table t = test::read_decoded_csv(test::slurp(csv));
  const int ct = t.col("TimeUs"), cn = t.col("PosN"), ce = t.col("PosE"), cs = t.col("SigmaPosH"),
            cr = t.col("Roll"), csr = t.col("SigmaRoll"), cva = t.col("GnssVelAccepted"),
            cvr = t.col("GnssVelRejected"), cha = t.col("HeadingAccepted"),
            chr = t.col("HeadingRejected"), cpr = t.col("GnssPosRejected");
  for (int c : {ct, cn, ce, cs, cr, csr, cva, cvr, cha, chr, cpr}) ASSERT_GE(c, 0) << "columns";
  const auto at = [](const std::vector<std::string>& row, int c) -> const std::string& {
    return row[static_cast<std::size_t>(c)];
  };
  double first_value_s = -1, first_roll_sigma_s = -1, worst_pos = 0, worst_roll = 0;
  std::size_t pos_checks = 0, pos_outside = 0, roll_checks = 0, roll_outside = 0;
  std::string vel_accepted, vel_rejected, head_accepted, head_rejected, pos_rejected;
  for (const auto& row : t.rows) {
    if (row.size() != t.names.size() || at(row, ct).empty()) continue;
    const double t_s = std::stod(at(row, ct)) * 1e-6;
    for (auto [c, v] : {std::pair{cva, &vel_accepted}, std::pair{cvr, &vel_rejected},
                        std::pair{cha, &head_accepted}, std::pair{chr, &head_rejected},
                        std::pair{cpr, &pos_rejected}}) {
      if (!at(row, c).empty()) *v = at(row, c);
    }
    if (!at(row, cn).empty() && first_value_s < 0) first_value_s = t_s;
    if (!at(row, csr).empty() && first_roll_sigma_s < 0) first_roll_sigma_s = t_s;
    const sim::TruthState x = traj.value()->at(t_s);
    if (!at(row, cn).empty() && !at(row, cs).empty()) {
      ++pos_checks;
      const double eh =
          std::hypot(std::stod(at(row, cn)) - x.r_n[0], std::stod(at(row, ce)) - x.r_n[1]);
      worst_pos = std::max(worst_pos, eh / std::stod(at(row, cs)));
      if (eh > 4.0 * std::stod(at(row, cs)) + 0.01) ++pos_outside;
    }
    if (!at(row, cr).empty() && !at(row, csr).empty()) {
      ++roll_checks;
      const double roll = nav::euler_from_quat(x.q_nb).x();
      const double er = std::remainder(std::stod(at(row, cr)) - roll, 2 * M_PI);
      worst_roll = std::max(worst_roll, std::abs(er) / std::stod(at(row, csr)));
      if (std::abs(er) > 4.0 * std::stod(at(row, csr)) + 0.001) ++roll_outside;
    }
  }
  std::printf(
      "moving power-up: first value at %.3f s, first roll sigma at %.3f s; %zu position "
      "and %zu roll checks, %zu and %zu outside 4 sigma (worst %.2f and %.2f sigma); velocity "
      "fixes %s accepted %s rejected, track headings %s accepted %s rejected\n",
      first_value_s, first_roll_sigma_s, pos_checks, roll_checks, pos_outside, roll_outside,
      worst_pos, worst_roll, vel_accepted.c_str(), vel_rejected.c_str(), head_accepted.c_str(),
      head_rejected.c_str());
  EXPECT_GE(first_value_s, 0.06);
  EXPECT_LT(first_value_s, 0.5);
  EXPECT_GE(first_roll_sigma_s, 0.2);
  EXPECT_LT(first_roll_sigma_s, 2.0);
  EXPECT_GT(pos_checks, 1000u);  // 100 Hz
  EXPECT_GT(roll_checks, 50u);   // 5 Hz
  EXPECT_EQ(pos_outside, 0u);
  EXPECT_EQ(roll_outside, 0u);
  // 10 Hz for 20 s less the 4 s outage and the fixes before the start: ~150 of each.
  EXPECT_GE(std::atoi(vel_accepted.c_str()), 140);
  EXPECT_GE(std::atoi(head_accepted.c_str()), 140);
  // The gate passes 99.9 % of the fixes of a consistent filter: of ~150, 3 or more rejected has
  // probability 5e-4 (1 velocity fix was rejected at 3.1 s in this run).
  for (const std::string* n : {&vel_rejected, &head_rejected, &pos_rejected}) {
    EXPECT_LE(std::atoi(n->c_str()), 2);
  }
}

}  // namespace
}  // namespace gfins
