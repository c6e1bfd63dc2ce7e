// gfins-fw configuration: the shipped default file, every kind of bad value named with its file,
// line and key, unknown keys, and the command line overriding the file.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <vector>

#include "gfins/app/config.hpp"

namespace gfins::app {
namespace {

// Field by field: the default file must describe exactly the built-in defaults.
void expect_defaults(const FwConfig& c) {
  const FwConfig d;
  EXPECT_EQ(c.board, d.board);
  EXPECT_EQ(c.spi_device, d.spi_device);
  EXPECT_EQ(c.gpio_chip, d.gpio_chip);
  EXPECT_EQ(c.drdy_line, d.drdy_line);
  EXPECT_EQ(c.sample_rate_hz, d.sample_rate_hz);
  EXPECT_EQ(c.can_interface, d.can_interface);
  EXPECT_EQ(c.can_log, d.can_log);
  EXPECT_EQ(c.node_id, d.node_id);
  EXPECT_EQ(c.dividers, d.dividers);
  EXPECT_EQ(c.compensator, d.compensator);
  EXPECT_EQ(c.gravity, d.gravity);
  EXPECT_EQ(c.gravity_mps2, d.gravity_mps2);
  EXPECT_EQ(c.heading_deg, d.heading_deg);
  EXPECT_EQ(c.position_m, d.position_m);
  EXPECT_EQ(c.alignment_s, d.alignment_s);
  EXPECT_EQ(c.calibration_file, d.calibration_file);
  EXPECT_EQ(c.rt_priority, d.rt_priority);
  EXPECT_EQ(c.lock_memory, d.lock_memory);
  EXPECT_EQ(c.watchdog, d.watchdog);
  EXPECT_EQ(c.log_level, d.log_level);
  EXPECT_EQ(c.sim_scenario, d.sim_scenario);
  EXPECT_EQ(c.pacing, d.pacing);
  EXPECT_EQ(c.sim_duration_s, d.sim_duration_s);
}

TEST(Config, ShippedDefaultFileIsValidAndEqualsTheBuiltInDefaults) {
  const ConfigResult r = parse_config(default_config_text(), "gfins-fw.toml");
  ASSERT_TRUE(r.ok()) << r.error;
  expect_defaults(*r.config);
  EXPECT_EQ(validate(FwConfig{}, "defaults"), "");
}

TEST(Config, EmptyFileGivesDefaults) {
  const ConfigResult r = parse_config("", "empty.toml");
  ASSERT_TRUE(r.ok()) << r.error;
  expect_defaults(*r.config);
}

TEST(Config, ValuesAreRead) {
  const ConfigResult r = parse_config(R"(
[board]
kind = "sim"
[adc]
drdy_line = 17
[can]
node_id = 5
log_file = "out.log"
[output]
euler = 0
health_adc = 500
[navigation]
compensator = "exact"
gravity = "normal"
latitude_deg = 52.5
heading_deg = 90
position_m = [1, 2.5, -3]
[sim]
pacing = "realtime"
duration_s = 60
)",
                                      "f.toml");
  ASSERT_TRUE(r.ok()) << r.error;
  const FwConfig& c = *r.config;
  EXPECT_EQ(c.board, BoardKind::kSim);
  EXPECT_EQ(c.drdy_line, "17");
  EXPECT_EQ(c.node_id, 5);
  EXPECT_EQ(c.can_log, "out.log");
  EXPECT_EQ(c.dividers[static_cast<std::size_t>(message_index("euler"))], 0);
  EXPECT_EQ(c.dividers[static_cast<std::size_t>(message_index("health_adc"))], 500);
  EXPECT_EQ(c.compensator, CompensatorChoice::kExact);
  EXPECT_EQ(c.gravity, GravityChoice::kNormal);
  EXPECT_EQ(c.latitude_deg, 52.5);
  EXPECT_EQ(c.heading_deg, 90.0);
  EXPECT_EQ(c.position_m, (std::array<double, 3>{1.0, 2.5, -3.0}));
  EXPECT_EQ(c.pacing, Pacing::kRealTime);
  EXPECT_EQ(c.sim_duration_s, 60.0);
}

struct BadCase {
  const char* text;
  std::vector<const char*> must_contain;  // every fragment must be in the message
};

TEST(Config, EveryBadValueIsNamedWithFileKeyAndWhatIsAllowed) {
  const std::vector<BadCase> cases = {
      {"[can]\nnode_id = 40\n", {"bad.toml:2", "can.node_id = 40", "0..15"}},
      {"[can]\nnode_id = \"1\"\n", {"can.node_id", "integer"}},
      {"[adc]\nsample_rate_hz = 1234\n", {"adc.sample_rate_hz = 1234", "500, 1000, 2000 or 4000"}},
      {"[board]\nkind = \"arm\"\n", {"board.kind = \"arm\"", "\"linux\", \"sim\" or \"hil\""}},
      {"[navigation]\ncompensator = \"best\"\n", {"navigation.compensator", "\"paper\""}},
      {"[navigation]\nposition_m = [1, 2]\n", {"navigation.position_m", "3 numbers"}},
      {"[navigation]\nlatitude_deg = 91\n", {"navigation.latitude_deg = 91", "-90..90"}},
      {"[navigation]\nalignment_s = 0\n", {"navigation.alignment_s = 0", "0.1..600"}},
      {"[realtime]\npriority = 100\n", {"realtime.priority = 100", "0..99"}},
      {"[realtime]\nlock_memory = 1\n", {"realtime.lock_memory", "true or false"}},
      {"[output]\nstatus = 20\n", {"output.status = 20", "equal output.epoch"}},
      {"[output]\neuler = 15\n", {"output.euler = 15", "multiple of output.epoch"}},
      {"[output]\nepoch = 0\nstatus = 0\n", {"output.epoch = 0"}},
      {"[log]\nlevel = \"loud\"\n", {"log.level = \"loud\"", "\"warn\""}},
      {"[can]\ninterface = \"can0/../x\"\n", {"can.interface", "without '/'"}},
      {"[adc]\nspi_device = \"/dev/sda\"\n", {"adc.spi_device = \"/dev/sda\"", "/dev/spidevB.C"}},
      {"[can]\nnodeid = 3\n", {"bad.toml:2", "unknown key 'can.nodeid'"}},
      {"[cann]\nnode_id = 3\n", {"unknown key 'cann'"}},
      {"[can\nnode_id = 3\n", {"bad.toml:1", "TOML syntax"}},
      {"[sim]\npacing = \"edge\"\n", {"sim.pacing = \"edge\"", "\"gpio\""}},
  };
  for (const BadCase& c : cases) {
    const ConfigResult r = parse_config(c.text, "bad.toml");
    ASSERT_FALSE(r.ok()) << c.text;
    for (const char* frag : c.must_contain) {
      EXPECT_NE(r.error.find(frag), std::string::npos) << "'" << frag << "' not in: " << r.error;
    }
  }
}

CliResult cli(std::vector<const char*> args) {
  args.insert(args.begin(), "gfins-fw");
  return parse_command_line(static_cast<int>(args.size()), args.data());
}

TEST(Cli, OptionsOverrideTheFile) {
  const char* path = "cli_test_config.toml";
  {
    std::ofstream f(path);
    f << "[can]\nnode_id = 3\ninterface = \"can1\"\n[navigation]\nheading_deg = 10\n";
  }
  const CliResult r = cli({"--config", path, "--node-id", "7", "--sim", "spin", "--divider",
                           "euler=40", "--position-m", "1,2,3", "--pacing", "realtime"});
  std::remove(path);
  ASSERT_TRUE(r.config) << r.message;
  EXPECT_EQ(r.config->node_id, 7);             // option wins
  EXPECT_EQ(r.config->can_interface, "can1");  // file kept
  EXPECT_EQ(r.config->heading_deg, 10.0);
  EXPECT_EQ(r.config->board, BoardKind::kSim);
  EXPECT_EQ(r.config->sim_scenario, "spin");
  EXPECT_EQ(r.config->dividers[static_cast<std::size_t>(message_index("euler"))], 40);
  EXPECT_EQ(r.config->position_m, (std::array<double, 3>{1.0, 2.0, 3.0}));
  EXPECT_EQ(r.config->pacing, Pacing::kRealTime);
}

TEST(Config, GpioPacingIsReadFromTheFileAndTheCommandLine) {
  const ConfigResult r = parse_config("[sim]\npacing = \"gpio\"\n", "gpio.toml");
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.config->pacing, Pacing::kGpio);
  EXPECT_STREQ(to_string(Pacing::kGpio), "gpio");
  const CliResult c = cli({"--sim", "rest", "--pacing", "gpio"});
  ASSERT_TRUE(c.config) << c.message;
  EXPECT_EQ(c.config->pacing, Pacing::kGpio);
}

TEST(Cli, BadOptionsAreNamed) {
  const CliResult a = cli({"--node-id", "99"});
  EXPECT_FALSE(a.config);
  EXPECT_EQ(a.exit_code, 2);
  EXPECT_NE(a.message.find("command line"), std::string::npos) << a.message;
  EXPECT_NE(a.message.find("can.node_id = 99"), std::string::npos) << a.message;
  const CliResult b = cli({"--divider", "nosuch=3"});
  EXPECT_FALSE(b.config);
  EXPECT_NE(b.message.find("--divider nosuch=3"), std::string::npos) << b.message;
  const CliResult c = cli({"--compensator", "best"});
  EXPECT_FALSE(c.config);
  EXPECT_NE(c.exit_code, 0);
  const CliResult d = cli({"--config", "/nonexistent/gfins.toml"});
  EXPECT_FALSE(d.config);
  EXPECT_NE(d.exit_code, 0);
}

TEST(Cli, PrintDefaultConfigPrintsTheShippedFile) {
  const CliResult r = cli({"--print-default-config"});
  EXPECT_FALSE(r.config);
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_EQ(r.message, default_config_text());
}

}  // namespace
}  // namespace gfins::app
