// Scenario files: the built-ins parse, and every kind of bad input is rejected with a message that
// names the file, the key, the line and the problem.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <tuple>

#include "gfins/host_sim/scenario.hpp"

namespace gfins::sim {
namespace {

const std::string kBuiltinDir = std::string(GFINS_TEST_DATA_DIR) + "/../../host_sim/scenarios";

// A minimal valid file; the bad cases below each change one thing in it.
const char* const kGood = R"(# comment
[scenario]
duration_s = 2.0
rate_hz = 100.0
rho_m = 0.35
seed = 3

[gravity]
model = "up"

[trajectory]
kind = "constant_acceleration"
accel_mps2 = [9.80665, 0.0, 0.0]

[sensors]
orientation = "paper_table6"
noise_mps2 = 5e-4

[compensator]
kind = "exact"
misalignment = "calibrated"
)";

std::string replace(std::string text, const std::string& from, const std::string& to) {
  const auto pos = text.find(from);
  EXPECT_NE(pos, std::string::npos) << from;
  return text.replace(pos, from.size(), to);
}

void expect_error(const std::string& text, std::initializer_list<const char*> fragments) {
  const HostResult<Scenario> p = parse_scenario(text, "bad.toml");
  ASSERT_FALSE(p.is_ok()) << "accepted:\n" << text;
  for (const char* f : fragments) {
    EXPECT_NE(p.error().message.find(f), std::string::npos)
        << "message '" << p.error().message << "' lacks '" << f << "'";
  }
}

TEST(ScenarioParse, GoodFileGivesEveryValue) {
  // Given a complete file, when it is parsed, then every field has the value written.
  const HostResult<Scenario> p = parse_scenario(kGood, "good.toml");
  ASSERT_TRUE(p.is_ok()) << p.error().message;
  const Scenario& s = p.value();
  EXPECT_EQ(s.name, "good");
  EXPECT_DOUBLE_EQ(s.duration_s, 2.0);
  EXPECT_DOUBLE_EQ(s.rate_hz, 100.0);
  EXPECT_DOUBLE_EQ(s.rho_m, 0.35);
  EXPECT_EQ(s.seed, 3u);
  EXPECT_EQ(s.gravity, ScenarioGravity::kUp);
  EXPECT_EQ(s.trajectory.kind, "constant_acceleration");
  EXPECT_DOUBLE_EQ(s.trajectory.accel_n_mps2.x(), 9.80665);
  EXPECT_DOUBLE_EQ(s.noise_mps2, 5e-4);
  EXPECT_EQ(s.compensator, nav::CompensatorKind::kExact);
  EXPECT_EQ(s.misalignment_source, MisalignmentSource::kCalibrated);
  // Table 6's Δβ_xy = 1.117319° as the paper prints it, stored in radians.
  EXPECT_NEAR(s.misalignment.orientation.beta[0], 1.117319 * M_PI / 180.0, 1e-12);
  // The gravity model "up" points along −z.
  EXPECT_LT(gravity_model(s).g_n(Vec3d::Zero()).z(), 0.0);
}

TEST(ScenarioParse, EveryBuiltinScenarioParsesAndBuildsItsTrajectory) {
  const auto names = builtin_scenarios(kBuiltinDir);
  ASSERT_GE(names.size(), 9u) << kBuiltinDir;
  for (const auto& n : names) {
    const HostResult<Scenario> p = load_scenario(n, kBuiltinDir);
    ASSERT_TRUE(p.is_ok()) << p.error().message;
    EXPECT_FALSE(p.value().description.empty()) << n;
    const auto traj = make_trajectory(p.value().trajectory);
    ASSERT_TRUE(traj.is_ok()) << n << ": " << traj.error().message;
    const TruthState x = traj.value()->at(0.5);
    EXPECT_TRUE(x.q_nb.coeffs().allFinite()) << n;
  }
}

TEST(ScenarioParse, MissingRequiredKeyIsNamed) {
  expect_error(replace(kGood, "duration_s = 2.0\n", ""),
               {"bad.toml:", "scenario.duration_s", "missing"});
  expect_error(replace(kGood, "accel_mps2 = [9.80665, 0.0, 0.0]\n", ""),
               {"trajectory.accel_mps2", "missing"});
  expect_error(replace(kGood,
                       "[trajectory]\nkind = \"constant_acceleration\"\n"
                       "accel_mps2 = [9.80665, 0.0, 0.0]\n",
                       ""),
               {"trajectory", "missing table"});
}

TEST(ScenarioParse, ChannelFailuresAreReadWithTheirUnits) {
  const std::string text = replace(kGood, "noise_mps2 = 5e-4\n", R"(noise_mps2 = 5e-4
[[sensors.failures]]
kind = "bias"
sensor = 3
start_s = 1.5
bias_mg = 2.0
[[sensors.failures]]
kind = "stuck"
sensor = 6
start_s = 0.25
[[sensors.failures]]
kind = "saturation"
sensor = 1
start_s = 0
limit_g = 0.5
)");
  const HostResult<Scenario> p = parse_scenario(text, "failures.toml");
  ASSERT_TRUE(p.is_ok()) << p.error().message;
  const auto& f = p.value().failures;
  ASSERT_EQ(f.size(), 3U);
  EXPECT_EQ(f[0].kind, ChannelFailureKind::kBias);
  EXPECT_EQ(f[0].sensor, 2U);  // sensor 3, 0-based
  EXPECT_DOUBLE_EQ(f[0].start_s, 1.5);
  EXPECT_DOUBLE_EQ(f[0].value, 2e-3);  // g
  EXPECT_EQ(f[1].kind, ChannelFailureKind::kStuck);
  EXPECT_EQ(f[1].sensor, 5U);
  EXPECT_EQ(f[2].kind, ChannelFailureKind::kSaturation);
  EXPECT_DOUBLE_EQ(f[2].value, 0.5);
  // The sensor model the runs build gets them (array_errors, one path for gfins-sim and the
  // simulated board).
  EXPECT_EQ(array_errors(p.value()).failures.size(), 3U);
}

TEST(ScenarioParse, ABadChannelFailureIsNamedWithItsPlace) {
  const auto with = [](const std::string& body) {
    return replace(kGood, "noise_mps2 = 5e-4\n",
                   "noise_mps2 = 5e-4\n[[sensors.failures]]\n" + body);
  };
  expect_error(with("kind = \"melted\"\nsensor = 1\nstart_s = 0\n"),
               {"bad.toml", "sensors.failures[0].kind", "melted", "stuck"});
  expect_error(with("kind = \"dead\"\nsensor = 7\nstart_s = 0\n"),
               {"sensors.failures[0].sensor", "out of range"});
  expect_error(with("kind = \"dead\"\nsensor = 2.5\nstart_s = 0\n"),
               {"sensors.failures[0].sensor", "integer"});
  expect_error(with("kind = \"dead\"\nsensor = 2\nstart_s = 3.0\n"),
               {"sensors.failures[0].start_s", "out of range [0, 2]"});
  expect_error(with("kind = \"bias\"\nsensor = 2\nstart_s = 1.0\n"),
               {"sensors.failures[0].bias_mg", "missing"});
  expect_error(with("kind = \"stuck\"\nsensor = 2\nstart_s = 1.0\nbias_mg = 1.0\n"),
               {"sensors.failures[0].bias_mg", "unknown key"});
  expect_error(replace(kGood, "noise_mps2 = 5e-4\n", "noise_mps2 = 5e-4\nfailures = 3\n"),
               {"sensors.failures", "array of tables"});
}

TEST(ScenarioParse, BoardFaultsAreReadInTimeOrder) {
  // Written out of order; kGood runs 2 s at 100 Hz.
  const HostResult<Scenario> p = parse_scenario(std::string(kGood) + R"(
[[board.faults]]
kind = "stuck"
at_s = 1.5
sensor = 6
duration_s = 0.25
[[board.faults]]
kind = "missed_edges"
at_s = 0.5
count = 4
[[board.faults]]
kind = "bus_off"
at_s = 1.0
duration_s = 0.5
[[board.faults]]
kind = "crc_error"
at_s = 1.25
)",
                                                "faults.toml");
  ASSERT_TRUE(p.is_ok()) << p.error().message;
  const auto& f = p.value().board_faults;
  ASSERT_EQ(f.size(), 4U);
  EXPECT_EQ(f[0].kind, BoardFaultKind::kMissedEdges);
  EXPECT_EQ(f[0].count, 4U);
  EXPECT_EQ(f[1].kind, BoardFaultKind::kBusOff);
  EXPECT_DOUBLE_EQ(f[1].duration_s, 0.5);
  EXPECT_EQ(f[2].kind, BoardFaultKind::kCrcError);
  EXPECT_EQ(f[3].kind, BoardFaultKind::kStuck);
  EXPECT_EQ(f[3].channel, 5U);  // sensor 6, 0-based
  EXPECT_DOUBLE_EQ(f[3].at_s, 1.5);
  EXPECT_STREQ(to_string(f[3].kind), "stuck");
}

TEST(ScenarioParse, ABadBoardFaultIsNamedWithItsPlace) {
  const auto with = [](const std::string& body) {
    return std::string(kGood) + "\n[[board.faults]]\n" + body;
  };
  expect_error(with("kind = \"melted\"\nat_s = 1.0\n"),
               {"bad.toml", "board.faults[0].kind", "melted", "adc_dead"});
  expect_error(with("kind = \"crc_error\"\nat_s = 3.0\n"),
               {"board.faults[0].at_s", "out of range"});
  expect_error(with("kind = \"bus_off\"\nat_s = 1.8\nduration_s = 0.5\n"),
               {"board.faults[0].duration_s", "out of range"});
  expect_error(with("kind = \"stuck\"\nat_s = 1.0\nduration_s = 0.5\n"),
               {"board.faults[0].sensor", "missing"});
  expect_error(with("kind = \"read_error\"\nat_s = 1.0\ncount = 2.5\n"),
               {"board.faults[0].count", "integer"});
  expect_error(with("kind = \"crc_error\"\nat_s = 1.0\ncount = 2\n"),
               {"board.faults[0].count", "unknown key"});
  expect_error(with("kind = \"can_refuse\"\nat_s = 1.0\nduration_s = 0.5\n"
                    "[[board.faults]]\nkind = \"can_refuse\"\nat_s = 1.25\nduration_s = 0.1\n"),
               {"board.faults[1].at_s", "overlaps an earlier can_refuse fault"});
  expect_error(std::string(kGood) + "\n[board]\nfaults = 3\n", {"board.faults", "array of tables"});
  expect_error(std::string(kGood) + "\n[board]\nfault = []\n", {"board.fault", "unknown key"});
}

TEST(ScenarioParse, WrongTypeIsNamedWithItsLine) {
  // rate_hz is on line 4 of kGood.
  expect_error(replace(kGood, "rate_hz = 100.0", "rate_hz = \"fast\""),
               {"bad.toml:4:", "scenario.rate_hz", "expected a number, got a string"});
  expect_error(replace(kGood, "accel_mps2 = [9.80665, 0.0, 0.0]", "accel_mps2 = [9.8, \"x\", 0]"),
               {"trajectory.accel_mps2", "expected an array of numbers"});
  expect_error(replace(kGood, "accel_mps2 = [9.80665, 0.0, 0.0]", "accel_mps2 = [9.8, 0]"),
               {"trajectory.accel_mps2", "expected 3 numbers, got 2"});
  expect_error(replace(kGood, "seed = 3", "seed = 3.5"), {"scenario.seed", "expected an integer"});
}

TEST(ScenarioParse, ARateTheConverterModelCannotMakeIsRefusedWhileReading) {
  // ADS131M06: f_DATA = CLKIN / (2 OSR), CLKIN <= 8.192 MHz, OSR >= 128 (datasheet §8.3.6,
  // §8.3.7): 32,000 Hz at most. kGood has no [sensors] adc key, so the ADC is on.
  const auto at = [](const char* rate) {
    return replace(kGood, "rate_hz = 100.0", std::string("rate_hz = ") + rate);
  };
  ASSERT_TRUE(parse_scenario(at("32000.0"), "ok.toml").is_ok());
  expect_error(at("32000.5"),
               {"bad.toml:4:", "scenario.rate_hz", "at most 32000 Hz", "adc = false"});
  expect_error(at("90000.0"), {"scenario.rate_hz", "ADS131M06"});
  // Without the converter (the paper's m/s² setting) the documented range up to 1e5 holds.
  const std::string no_adc =
      replace(at("90000.0"), "noise_mps2 = 5e-4", "noise_mps2 = 5e-4\nadc = false");
  const HostResult<Scenario> p = parse_scenario(no_adc, "fast.toml");
  ASSERT_TRUE(p.is_ok()) << p.error().message;
  EXPECT_EQ(p.value().rate_hz, 90000.0);
}

TEST(ScenarioParse, UnknownTrajectoryAndOtherChoicesListTheAllowedOnes) {
  expect_error(replace(kGood, "\"constant_acceleration\"", "\"loop_the_loop\""),
               {"bad.toml:12:", "trajectory.kind", "unknown value 'loop_the_loop'", "coning"});
  expect_error(replace(kGood, "kind = \"exact\"", "kind = \"magic\""),
               {"compensator.kind", "unknown value 'magic'", "none, paper, exact"});
  expect_error(replace(kGood, "misalignment = \"calibrated\"", "misalignment = \"guessed\""),
               {"compensator.misalignment", "true, calibrated"});
  expect_error(replace(kGood, "model = \"up\"", "model = \"sideways\""), {"gravity.model"});
}

TEST(ScenarioParse, OutOfRangeValueIsNamedWithItsRange) {
  expect_error(replace(kGood, "rho_m = 0.35", "rho_m = -0.35"),
               {"bad.toml:5:", "scenario.rho_m", "out of range"});
  expect_error(replace(kGood, "rate_hz = 100.0", "rate_hz = 0"),
               {"scenario.rate_hz", "out of range"});
  expect_error(replace(kGood, "noise_mps2 = 5e-4", "noise_mps2 = nan"),
               {"sensors.noise_mps2", "out of range"});
  // Custom angles beyond the compensator's small-angle model (0.2 rad).
  expect_error(replace(kGood, "orientation = \"paper_table6\"",
                       "orientation = \"custom\"\nbeta_deg = [0, 0, 0, 0, 0, 20]\n"
                       "alpha_deg = [0, 0, 0, 0, 0, 0]"),
               {"sensors.beta_deg", "element 5 = 20 out of range"});
}

TEST(ScenarioParse, UnknownKeyAndSyntaxErrorAreReported) {
  expect_error(replace(kGood, "rho_m = 0.35", "rho = 0.35"),
               {"bad.toml:5:", "scenario.rho", "unknown key", "rho_m"});
  expect_error(replace(kGood, "rho_m = 0.35", "rho_m = = 0.35"),
               {"bad.toml:5:", "TOML syntax error"});
}

TEST(ScenarioParse, ANameThatIsNotAPlainFileNameComponentIsRefused) {
  // The name becomes the output folder sim-out/<name>: given names that would reach outside it
  // or hide ("../../../escaped" once wrote to ../../../escaped/), parsing fails
  // naming the key and the characters allowed.
  // ("new\\nline" is a TOML escape: a real newline in the name.)
  for (const char* name : {"../../../escaped", "/tmp/abs", "a/b", ".hidden", "..", "-x", "",
                           "two words", "new\\nline", "q'uote"}) {
    SCOPED_TRACE(name);
    expect_error(replace(kGood, "[scenario]", std::string("[scenario]\nname = \"") + name + "\""),
                 {"bad.toml:3:", "scenario.name", "letters, digits, '.', '_' and '-'"});
  }
  // A file whose stem is not a plain name and that has no name key: the same, and the hint.
  const HostResult<Scenario> stem = parse_scenario(kGood, "dir/my run.toml");
  ASSERT_FALSE(stem.is_ok());
  EXPECT_NE(stem.error().message.find("set one"), std::string::npos) << stem.error().message;
  // Plain names pass, the built-in ones among them (EveryBuiltinScenarioParses...).
  for (const char* name : {"rest", "paper-6.3-1mg", "rate_table.z", "A1"}) {
    SCOPED_TRACE(name);
    const HostResult<Scenario> ok = parse_scenario(
        replace(kGood, "[scenario]", std::string("[scenario]\nname = \"") + name + "\""), "x.toml");
    ASSERT_TRUE(ok.is_ok()) << ok.error().message;
    EXPECT_EQ(ok.value().name, name);
  }
}

TEST(ScenarioParse, ADescriptionWithAControlCharacterIsRefusedNamingItsPlace) {
  // The description goes to the terminal and into summary.txt: ESC [2J would clear the screen,
  // a newline forge a report line. TOML escapes put them there (\u001b, \n, \u007f, \u009b CSI).
  for (const auto& [text, code, at] : {std::tuple{"evil\\u001b[2J", "U+001B", "character 5"},
                                       std::tuple{"line\\nforged", "U+000A", "character 5"},
                                       std::tuple{"a\\tb", "U+0009", "character 2"},
                                       std::tuple{"\\u007f", "U+007F", "character 1"},
                                       std::tuple{"°\\u009b2J", "U+009B", "character 2"}}) {
    SCOPED_TRACE(text);
    expect_error(
        replace(kGood, "[scenario]", std::string("[scenario]\ndescription = \"") + text + "\""),
        {"bad.toml:3:", "scenario.description", code, at, "one line of printable text"});
  }
  // Printable text, UTF-8 included, passes unchanged.
  const HostResult<Scenario> ok = parse_scenario(
      replace(kGood, "[scenario]", "[scenario]\ndescription = \"tilt 30° — ρ 0.1 m\""), "x.toml");
  ASSERT_TRUE(ok.is_ok()) << ok.error().message;
  EXPECT_EQ(ok.value().description, "tilt 30° — ρ 0.1 m");
}

TEST(ScenarioParse, FewerThanTwoSamplesIsRefusedAndPartialPeriodsAreFloored) {
  // Samples are t = 0 and every whole period up to duration_s: floor(duration × rate) + 1
  // (written out here for each case).
  struct Case {
    const char* duration;
    const char* rate;
    std::uint64_t samples;  // 0: refused
  };
  const Case cases[] = {
      {"0.5", "1", 0},       // the review's case: half a period, was run to t = 1 s
      {"0.999", "1", 0},     // just under one period
      {"1.0", "1", 2},       // exactly one period: t = 0, 1 s
      {"1.4", "1", 2},       // 1.4 periods: ends at t = 1 s, not 1.4 (and not rounded up)
      {"1.6", "1", 2},       // 1.6 periods: was llround → 3 samples, to t = 2 s, past the end
      {"0.3", "1000", 301},  // 0.3 × 1000 is 299.99999999999994 in binary: still 300 periods
      {"0.1", "100", 11},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(std::string(c.duration) + " s at " + c.rate + " Hz");
    std::string text =
        replace(kGood, "duration_s = 2.0", std::string("duration_s = ") + c.duration);
    text = replace(text, "rate_hz = 100.0", std::string("rate_hz = ") + c.rate);
    const HostResult<Scenario> p = parse_scenario(text, "short.toml");
    if (c.samples == 0) {
      ASSERT_FALSE(p.is_ok());
      EXPECT_NE(p.error().message.find("scenario.duration_s"), std::string::npos);
      EXPECT_NE(p.error().message.find("at least 2 samples"), std::string::npos);
      continue;
    }
    ASSERT_TRUE(p.is_ok()) << p.error().message;
    EXPECT_EQ(sample_count(p.value()), c.samples);
    EXPECT_LE(covered_duration_s(p.value()), p.value().duration_s);
  }
}

TEST(ScenarioParse, MissingFileOrNameIsReported) {
  const HostResult<Scenario> p = load_scenario("no-such-scenario", kBuiltinDir);
  ASSERT_FALSE(p.is_ok());
  EXPECT_NE(p.error().message.find("no-such-scenario"), std::string::npos) << p.error().message;
}

// The aiding scenarios: stop-and-go trajectories of the lengths their descriptions promise
// (the urban drive at least 10 min, stops long enough for the 1 s static alignment).
TEST(ScenarioFiles, AidingScenariosAreStopAndGoOfTheirStatedLengths) {
  const std::string dir = std::string(GFINS_TEST_DATA_DIR) + "/../../host_sim/scenarios";
  struct Want {
    const char* name;
    double min_duration_s;
    double speed_mps;
  };
  for (const Want w : {Want{"urban-stop-and-go", 600.0, 12.0}, Want{"highway", 600.0, 30.0},
                       Want{"walk", 300.0, 1.4}}) {
    const HostResult<Scenario> p = load_scenario(w.name, dir);
    ASSERT_TRUE(p.is_ok()) << w.name << ": " << p.error().message;
    const Scenario& s = p.value();
    EXPECT_EQ(s.trajectory.kind, "stop_and_go") << w.name;
    EXPECT_GE(s.duration_s, w.min_duration_s) << w.name;
    EXPECT_EQ(s.trajectory.stop_and_go.speed_mps, w.speed_mps) << w.name;
    EXPECT_GE(s.trajectory.stop_and_go.initial_stop_s, 1.0) << w.name;
  }
}

}  // namespace
}  // namespace gfins::sim
