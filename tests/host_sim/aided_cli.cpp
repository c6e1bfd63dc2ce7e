// `gfins-sim aided` as a user runs it, on a 30 s stop-and-go drive with GNSS (cheap under the
// sanitizers): exit 0, the two CSV files with the documented columns (docs/simulation.md,
// "Output files": the filter's σ, `nan` in the unaided run), the summary's rows; a calibration
// scenario (nothing navigates) is refused with exit 2 before anything is written. The oracle is
// the documented file format and exit codes, and the physics the table must show: the aided
// error below the unaided one at 30 s.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "support/cli_fixture.hpp"

namespace gfins::sim {
namespace {

namespace fs = std::filesystem;

constexpr int kExitOk = 0;
constexpr int kExitBadInput = 2;

constexpr const char* kDrive = R"([scenario]
duration_s = 30.0
rate_hz = 200.0
[trajectory]
kind = "stop_and_go"
speed_mps = 10.0
accel_s = 4.0
cruise_s = 10.0
stop_s = 3.0
initial_stop_s = 5.0
[sensors]
model = "qa1100"
temperature_c = 40.0
[compensator]
kind = "exact"
[gnss]
rate_hz = 5.0
sigma_pos_m = [1.5, 3.0]
sigma_vel_mps = 0.1
[aiding]
enabled = false
track_heading_sigma_deg = 0.5
)";

std::string read(const fs::path& p) {
  std::ifstream f(p);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

std::string first_line(const fs::path& p) {
  std::ifstream f(p);
  std::string line;
  std::getline(f, line);
  return line;
}

class AidedCli : public test::CliTest {
 protected:
  test::CliResult sim(const std::vector<std::string>& args) const {
    return run(GFINS_SIM_BIN, args, dir());
  }
};

TEST_F(AidedCli, WritesBothRunsWithTheFiltersSigmaAndTheTable) {
  std::ofstream(dir() / "drive.toml") << kDrive;
  const auto r = sim({"aided", "./drive.toml", "-o", "out", "--no-plot", "--decimate", "20"});
  ASSERT_EQ(r.exit_code, kExitOk) << r.output;
  for (const char* f : {"out/aided.csv", "out/unaided.csv", "out/summary.txt"}) {
    EXPECT_TRUE(fs::is_regular_file(dir() / f)) << f;
  }
  const std::string head = first_line(dir() / "out/aided.csv");
  for (const char* col : {"err_euler_roll_rad", "err_euler_heading_rad", "sigma_euler_roll_rad",
                          "sigma_euler_heading_rad", "sigma_v_n_x_mps", "sigma_r_n_z_m"}) {
    EXPECT_NE(head.find(col), std::string::npos) << col;
  }
  EXPECT_EQ(head, first_line(dir() / "out/unaided.csv"));
  // The unaided run has no filter: its σ columns are nan, never a number.
  const std::string unaided = read(dir() / "out/unaided.csv");
  EXPECT_NE(unaided.find(",nan,nan,nan"), std::string::npos);
  const std::string summary = read(dir() / "out/summary.txt");
  for (const char* row : {"at 10 s", "RMS over t >= 10 s", "worst over t >= 10 s",
                          "within the filter's 3 sigma", "aiding updates", "standstill detector"}) {
    EXPECT_NE(summary.find(row), std::string::npos) << row << "\n" << summary;
  }
  EXPECT_NE(r.output.find("RMS over t >= 10 s"), std::string::npos);
}

TEST_F(AidedCli, ACalibrationScenarioIsRefusedBeforeAnythingIsWritten) {
  const auto r = sim({"aided", "calibration-tables23", "-o", "cal", "--no-plot"});
  EXPECT_EQ(r.exit_code, kExitBadInput) << r.output;
  EXPECT_NE(r.output.find("nothing navigates"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir() / "cal"));
}

}  // namespace
}  // namespace gfins::sim
