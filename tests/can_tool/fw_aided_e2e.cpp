// Aided navigation end to end with the real programs: `gfins-fw --sim rest-qa1100 --aiding`
// writes a candump log, `gfins-can decode --view csv` decodes it, and the decoded values are
// compared with the scenario's truth (the board is at rest: every velocity component is 0). The
// same run without --aiding is the negative control: the comparison must fail it.
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
#include <sstream>
#include <string>
#include <vector>

#include "support/cli_fixture.hpp"

namespace gfins {
namespace {

constexpr int kSeconds = 30;
constexpr double kSettleS = 3.0;
constexpr double kAidedVelMaxMps = 0.05;
constexpr double kUnaidedVelMinMps = 1.0;
constexpr double kSigmaHorizonMps = 0.5;  // the filter's default validity horizon for velocity
constexpr double kSigmaVelStep = 0.01;    // SigmaVelH's factor (docs/can/gfins.dbc)

struct Table {
  std::vector<std::string> names;
  std::vector<std::vector<std::string>> rows;
  int col(const std::string& n) const {
    for (std::size_t i = 0; i < names.size(); ++i) {
      if (names[i] == n) return static_cast<int>(i);
    }
    return -1;
  }
};

Table read_csv(const std::string& text) {
  Table t;
  std::istringstream in(text);
  std::string line;
  const auto split = [](const std::string& s) {
    std::vector<std::string> out;
    std::string cell;
    std::istringstream ls(s);
    while (std::getline(ls, cell, ',')) out.push_back(cell);
    if (!s.empty() && s.back() == ',') out.emplace_back();
    return out;
  };
  if (std::getline(in, line)) {
    for (const std::string& h : split(line)) t.names.push_back(h.substr(0, h.find('[')));
  }
  while (std::getline(in, line)) t.rows.push_back(split(line));
  return t;
}

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
    const Table t = read_csv(test::slurp(csv));
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

}  // namespace
}  // namespace gfins
