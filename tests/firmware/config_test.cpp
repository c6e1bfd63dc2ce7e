// gfins-fw configuration: the shipped default file, every kind of bad value named with its file,
// line and key, unknown keys, and the command line overriding the file.
#include <gtest/gtest.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <vector>

#include "gfins/app/board.hpp"
#include "gfins/app/config.hpp"
#include "gfins/host_sim/board/sim_board.hpp"

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
  EXPECT_EQ(c.id_bases, d.id_bases);
  EXPECT_EQ(c.reserved_ids, d.reserved_ids);
  EXPECT_EQ(c.dividers, d.dividers);
  EXPECT_EQ(c.compensator, d.compensator);
  EXPECT_EQ(c.gravity, d.gravity);
  EXPECT_EQ(c.gravity_mps2, d.gravity_mps2);
  EXPECT_EQ(c.heading_deg, d.heading_deg);
  EXPECT_EQ(c.position_m, d.position_m);
  EXPECT_EQ(c.mounting_rpy_deg, d.mounting_rpy_deg);
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
mounting_rpy_deg = [180, 0, -180]
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
  EXPECT_EQ(c.mounting_rpy_deg, (std::array<double, 3>{180.0, 0.0, -180.0}));
  EXPECT_EQ(c.pacing, Pacing::kRealTime);
  EXPECT_EQ(c.sim_duration_s, 60.0);
}

struct BadCase {
  const char* text;
  std::vector<const char*> must_contain;  // every fragment must be in the message
};

// Each case's text, read as the file `name`, is refused with every fragment in the message.
void expect_refused(const std::vector<BadCase>& cases, const char* name) {
  for (const BadCase& c : cases) {
    const ConfigResult r = parse_config(c.text, name);
    ASSERT_FALSE(r.ok()) << c.text;
    for (const char* frag : c.must_contain) {
      EXPECT_NE(r.error.find(frag), std::string::npos) << "'" << frag << "' not in: " << r.error;
    }
  }
}

TEST(Config, EveryBadValueIsNamedWithFileKeyAndWhatIsAllowed) {
  const std::vector<BadCase> cases = {
      {"[can]\nnode_id = 40\n", {"bad.toml:2", "can.node_id = 40", "0..15"}},
      {"[can]\nnode_id = \"1\"\n", {"can.node_id", "integer"}},
      {"[adc]\nsample_rate_hz = 1234\n",
       {"bad.toml:2: adc.sample_rate_hz = 1234", "500, 1000, 2000 or 4000"}},
      // A value a hair off an allowed one is shown as it was read, not rounded onto it.
      {"[adc]\nsample_rate_hz = 1000.0000001\n",
       {"bad.toml:2: adc.sample_rate_hz = 1000.0000001: must be 500, 1000"}},
      {"[navigation]\nalignment_s = 600.0000001\n", {"navigation.alignment_s = 600.0000001"}},
      {"[board]\nkind = \"arm\"\n", {"board.kind = \"arm\"", "\"linux\", \"sim\" or \"hil\""}},
      {"[navigation]\ncompensator = \"best\"\n", {"navigation.compensator", "\"paper\""}},
      {"[navigation]\nposition_m = [1, 2]\n", {"navigation.position_m", "3 numbers"}},
      {"[navigation]\nlatitude_deg = 91\n", {"navigation.latitude_deg = 91", "-90..90"}},
      {"[navigation]\nmounting_rpy_deg = [0, 90.5, 0]\n",
       {"bad.toml:2: navigation.mounting_rpy_deg = 90.5", "pitch must be -90..90"}},
      {"[navigation]\nmounting_rpy_deg = [-181, 0, 0]\n",
       {"navigation.mounting_rpy_deg = -181", "roll and yaw must be -180..180"}},
      {"[navigation]\nmounting_rpy_deg = [0, 0, nan]\n", {"navigation.mounting_rpy_deg = nan"}},
      {"[navigation]\nmounting_rpy_deg = [0, 0, 90]\n[aiding]\nenabled = true\n",
       {"navigation.mounting_rpy_deg = [0, 0, 90]", "cannot be combined with aiding.enabled"}},
      {"[navigation]\nalignment_s = 0\n", {"navigation.alignment_s = 0", "0.1..600"}},
      {"[realtime]\npriority = 100\n", {"realtime.priority = 100", "0..99"}},
      {"[realtime]\nlock_memory = 1\n", {"realtime.lock_memory", "true or false"}},
      {"[output]\nstatus = 20\n", {"bad.toml:2: output.status = 20", "equal output.epoch"}},
      {"[output]\neuler = 15\n", {"output.euler = 15", "multiple of output.epoch"}},
      {"[output]\nepoch = 0\nstatus = 0\n", {"output.epoch = 0"}},
      // The bus budget (docs/can-interface.md): at 4 kHz the default dividers send
      // 4000 x (8/10 + 2/20 + 3/1000) = 3612 frames/s x 135 worst-case bits = 487,620 bit/s,
      // 97.5 % of 500 kbit/s, over the default 50 %.
      {"[adc]\nsample_rate_hz = 4000\n",
       {"output = a worst-case bus load of 97.5 % of 500000 bit/s at adc.sample_rate_hz = 4000",
        "at most can.max_bus_load_percent = 50 %"}},
      // 1 kHz on a 125 kbit/s bus: 903 x 135 = 121,905 bit/s = 97.5 % of it.
      {"[can]\nbit_rate = 125000\n", {"output = a worst-case bus load of 97.5 % of 125000 bit/s"}},
      {"[can]\nbit_rate = 300000\n", {"bad.toml:2: can.bit_rate = 300000", "125000, 250000"}},
      {"[can]\nmax_bus_load_percent = 0\n", {"can.max_bus_load_percent = 0", "(0, 100]"}},
      {"[can]\nmax_bus_load_percent = nan\n", {"can.max_bus_load_percent = nan"}},
      // 20 % is below the defaults' 24.4 % at 1 kHz (aiding off: 902 frames/s).
      {"[can]\nmax_bus_load_percent = 20\n", {"24.4 % of 500000 bit/s", "= 20 %"}},
      {"[log]\nlevel = \"loud\"\n", {"bad.toml:2: log.level = \"loud\"", "\"warn\""}},
      {"[can]\ninterface = \"can0/../x\"\n", {"can.interface", "without '/'"}},
      {"[adc]\nspi_device = \"/dev/sda\"\n", {"adc.spi_device = \"/dev/sda\"", "/dev/spidevB.C"}},
      {"[can]\nnodeid = 3\n", {"bad.toml:2", "unknown key 'can.nodeid'"}},
      {"[cann]\nnode_id = 3\n", {"unknown key 'cann'"}},
      {"[can\nnode_id = 3\n", {"bad.toml:1", "TOML syntax"}},
      {"[sim]\npacing = \"edge\"\n", {"sim.pacing = \"edge\"", "\"gpio\""}},
  };
  expect_refused(cases, "bad.toml");
}

// The identifier groups (docs/can-interface.md, "Identifiers"): each group's span written out
// here from the message table of that page (data 0x100 + node .. 0x200 + node: 0x110 identifiers;
// aiding inputs 0x0B0..0x0FF: 0x50; command and response 16 each), not taken from the code.
TEST(Config, IdentifierGroupsMoveAsAWholeAndNeverOverlap) {
  const ConfigResult moved = parse_config(
      "[can]\ndata_id_base = 0x300\ninput_id_base = 0x2A0\ncommand_id_base = 0x700\n"
      "response_id_base = 0x710\nreserved_ids = [[0x600, 0x60F], [0x181, 0x1DF]]\n",
      "ids.toml");
  ASSERT_TRUE(moved.ok()) << moved.error;
  EXPECT_EQ(moved.config->id_bases, (std::array<int, 4>{0x300, 0x2A0, 0x700, 0x710}));
  ASSERT_EQ(moved.config->reserved_ids.size(), 2u);
  EXPECT_EQ(moved.config->reserved_ids[1], (std::array<int, 2>{0x181, 0x1DF}));
  EXPECT_EQ(validate(*moved.config, "ids.toml"), "");

  const std::vector<BadCase> cases = {
      // Data 0x100..0x20F against the command group moved to 0x200: one identifier shared.
      {"[can]\ncommand_id_base = 0x200\n",
       {"ids.toml:2: can.command_id_base = 0x200",
        "0x200..0x20F overlap can.data_id_base's "
        "0x100..0x20F"}},
      // Only the data group moved, onto the commands' stock identifiers: the key the file set
      // is the one named, with its line.
      {"[can]\ndata_id_base = 0x5F0\n",
       {"ids.toml:2: can.data_id_base = 0x5F0",
        "0x5F0..0x6FF overlap can.command_id_base's "
        "0x600..0x60F"}},
      // One identifier shared at the other end: the moved group's last is the data group's first.
      {"[can]\ncommand_id_base = 0x0F1\n",
       {"ids.toml:2: can.command_id_base = 0x0F1",
        "0x0F1..0x100 overlap can.data_id_base's "
        "0x100..0x20F"}},
      // The stock command group is where OxTS RT frames are: a reserved range says so.
      {"[can]\nreserved_ids = [[0x600, 0x60F]]\n",
       {"can.command_id_base = 0x600", "0x600..0x60F overlap the reserved range 0x600..0x60F"}},
      // A reserved range that ends on a group's first identifier, and one that starts on its last.
      {"[can]\nreserved_ids = [[0x0F0, 0x100]]\n",
       {"can.data_id_base = 0x100", "0x100..0x20F overlap the reserved range 0x0F0..0x100"}},
      {"[can]\nreserved_ids = [[0x20F, 0x20F]]\n",
       {"can.data_id_base = 0x100", "0x100..0x20F overlap the reserved range 0x20F..0x20F"}},
      // The last identifier of a group must fit in 11 bits: data at 0x700 would end at 0x80F.
      {"[can]\ndata_id_base = 0x700\n", {"can.data_id_base = 0x700", "0..0x6F0"}},
      {"[can]\nresponse_id_base = 0x7F1\n", {"can.response_id_base = 0x7F1", "0..0x7F0"}},
      {"[can]\ninput_id_base = 2048\n", {"can.input_id_base = 2048", "0..2047"}},
      {"[can]\ninput_id_base = -1\n", {"can.input_id_base = -1"}},
      {"[can]\nreserved_ids = [[0x20, 0x10]]\n", {"can.reserved_ids", "first <= last"}},
      {"[can]\nreserved_ids = [0x600]\n", {"can.reserved_ids", "[first, last] pairs"}},
      {"[can]\nreserved_ids = [[0x600, 0x800]]\n", {"can.reserved_ids", "2047 (0x7FF)"}},
  };
  expect_refused(cases, "ids.toml");
  // Touching but not overlapping is allowed: data ends at 0x20F, the inputs start at 0x210.
  const ConfigResult touching = parse_config("[can]\ninput_id_base = 0x210\n", "ids.toml");
  EXPECT_TRUE(touching.ok()) << touching.error;
}

CliResult cli(std::vector<const char*> args) {
  args.insert(args.begin(), "gfins-fw");
  return parse_command_line(static_cast<int>(args.size()), args.data());
}

// The worst-case bus load against arithmetic written out here: 135 bits per 8-byte base frame
// (ISO 11898-1 with every stuff bit, tests/can/bus_budget_test.cpp), frames per second from the
// dividers of docs/can-interface.md. What fits under 50 % is accepted.
TEST(Config, TheBusBudgetAcceptsWhatFitsAndCountsEveryFrame) {
  constexpr double kBits = 135.0;
  // 1 kHz, aiding off: epoch, status, quaternion, rate, accel, velocity, position NE, D at 100 Hz,
  // Euler and angular acceleration at 50 Hz, two health messages and the command counters at
  // 1 Hz (the counters' divider is the table's 1000 samples at any rate).
  constexpr double kDefaultFrames = 8 * 100.0 + 2 * 50.0 + 3 * 1.0;
  const auto load_of = [](const std::string& text) {
    const ConfigResult r = parse_config(text, "t.toml");
    EXPECT_TRUE(r.ok()) << r.error;
    return r.ok() ? worst_case_bus_load(*r.config) : -1.0;
  };
  EXPECT_NEAR(load_of(""), kDefaultFrames * kBits / 500000.0, 1e-12);
  // Aiding on adds GfinsAccuracy (5 Hz) and GfinsAidingCounters (2.5 Hz).
  EXPECT_NEAR(load_of("[aiding]\nenabled = true\n"), (kDefaultFrames + 7.5) * kBits / 500000.0,
              1e-12);
  // 48.7 %: twice the rate, or half the bit rate, still fits the default 50 %.
  EXPECT_NEAR(load_of("[adc]\nsample_rate_hz = 2000\n"), 2 * kDefaultFrames * kBits / 500000.0,
              1e-12);
  EXPECT_NEAR(load_of("[can]\nbit_rate = 250000\n"), kDefaultFrames * kBits / 250000.0, 1e-12);
  // 4 kHz fits with the dividers scaled by 4 (24.4 %: the same but for the command counters, at
  // 4 Hz), and with the limit raised.
  EXPECT_NEAR(load_of("[adc]\nsample_rate_hz = 4000\n[output]\nepoch = 40\nstatus = 40\n"
                      "quaternion = 40\neuler = 80\nrate = 40\nangular_accel = 80\naccel = 40\n"
                      "velocity = 40\nposition_ne = 40\nposition_d = 40\nhealth_adc = 4000\n"
                      "health_system = 4000\n"),
              (kDefaultFrames + 3.0) * kBits / 500000.0, 1e-12);
  EXPECT_NEAR(load_of("[adc]\nsample_rate_hz = 4000\n[can]\nmax_bus_load_percent = 100\n"),
              4 * kDefaultFrames * kBits / 500000.0, 1e-12);
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

// ---- Refused values: the expected messages are written out in full ---------------------------

// Item 1: a quoted key is ONE key, dots included (TOML 1.0, "Keys"): "can.node_id" = 7 is not
// can → node_id, so it is unknown, and must not be accepted and ignored.
TEST(Config, QuotedDottedKeyIsUnknownNotIgnored) {
  const ConfigResult r = parse_config("\"can.node_id\" = 7\n", "q.toml");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error,
            "q.toml:1: unknown key '\"can.node_id\"' (a quoted key is one name, dots included: "
            "write the path unquoted, e.g. can.node_id = 7 or node_id = 7 under [can])");
  // The same inside a table.
  const ConfigResult t = parse_config("[adc]\n\"sample_rate_hz.x\" = 2\n", "q.toml");
  ASSERT_FALSE(t.ok());
  EXPECT_NE(t.error.find("q.toml:2: unknown key 'adc.\"sample_rate_hz.x\"'"), std::string::npos)
      << t.error;
  // A quoted key that spells a bare name is that name (TOML: "node_id" and node_id are equal),
  // and the dotted bare path is the path.
  const ConfigResult a = parse_config("[can]\n\"node_id\" = 7\n", "a.toml");
  ASSERT_TRUE(a.ok()) << a.error;
  EXPECT_EQ(a.config->node_id, 7);
  const ConfigResult b = parse_config("can.node_id = 6\n", "b.toml");
  ASSERT_TRUE(b.ok()) << b.error;
  EXPECT_EQ(b.config->node_id, 6);
}

// Item 2: paths are UTF-8 text; what is refused is a control character or bytes that are not
// UTF-8 (RFC 3629: overlong forms and surrogates are not UTF-8).
TEST(Config, PathsAcceptUtf8AndRefuseControlsAndInvalidUtf8) {
  EXPECT_TRUE(valid_path("/tmp/caf\xC3\xA9.toml"));                    // é, U+00E9
  EXPECT_TRUE(valid_path("/var/lib/gfins/\xE6\xA0\xA1\xE5\x87\x86"));  // 校准, 3-byte forms
  EXPECT_TRUE(valid_path("/tmp/\xF0\x9F\x9B\xB0.log"));                // U+1F6F0, 4 bytes
  EXPECT_FALSE(valid_path(""));
  EXPECT_FALSE(
      valid_path("a\x01"
                 "b"));               // C0 control
  EXPECT_FALSE(valid_path("a\x7F"));  // DEL
  EXPECT_FALSE(
      valid_path("a\xC2\x9B"
                 "31m"));                            // C1 CSI, U+009B
  EXPECT_FALSE(valid_path("a\xC3("));                // truncated sequence
  EXPECT_FALSE(valid_path("a\xC0\xAF"));             // overlong '/'
  EXPECT_FALSE(valid_path("a\xED\xA0\x80"));         // surrogate U+D800
  EXPECT_FALSE(valid_path("a\xF4\x90\x80\x80"));     // U+110000
  EXPECT_FALSE(valid_path(std::string(4096, 'a')));  // PATH_MAX with NUL
  EXPECT_FALSE(valid_path(std::string_view("a\0b", 3)));
  // Every path key takes UTF-8, from the file and from the command line.
  const ConfigResult r = parse_config(
      "[can]\nlog_file = \"/tmp/caf\xC3\xA9.log\"\n[adc]\ngpio_chip = \"/dev/gpiochip\xC3\xA9\"\n"
      "[calibration]\nfile = \"/tmp/caf\xC3\xA9.toml\"\n[watchdog]\nkind = \"device\"\n"
      "device = \"/dev/watchdog\xC3\xA9\"\n",
      "utf8.toml");
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.config->calibration_file, "/tmp/caf\xC3\xA9.toml");
}

// Item 3: a value is shown escaped, never raw: no NUL cuts the message, no ESC reaches the
// terminal, invalid UTF-8 is shown byte by byte.
TEST(Config, MessagesEscapeControlCharactersAndInvalidUtf8) {
  const ConfigResult n = parse_config("[can]\ninterface = \"can0\\u0000x\"\n", "n.toml");
  ASSERT_FALSE(n.ok());
  EXPECT_EQ(n.error,
            "n.toml:2: can.interface = \"can0\\u0000x\": must be an interface name of 1..15 "
            "characters without '/', ':' or spaces");
  const ConfigResult e = parse_config("[log]\nlevel = \"info\\u001b[31m\"\n", "e.toml");
  ASSERT_FALSE(e.ok());
  EXPECT_EQ(e.error,
            "e.toml:2: log.level = \"info\\u001B[31m\": must be \"trace\", \"debug\", \"info\", "
            "\"warn\", \"error\" or \"off\"");
  const ConfigResult c = parse_config("[calibration]\nfile = \"a\\u009b1m\"\n", "c.toml");
  ASSERT_FALSE(c.ok());
  EXPECT_EQ(c.error,
            "c.toml:2: calibration.file = \"a\\u009B1m\": must be a path of valid UTF-8 without "
            "control characters (or empty for none)");
  // Invalid UTF-8 comes only from the command line (TOML text must be UTF-8).
  const CliResult bad_utf8 = [] {
    std::vector<const char*> args = {"gfins-fw", "--calibration", "/tmp/caf\xC3(.toml"};
    return parse_command_line(static_cast<int>(args.size()), args.data());
  }();
  EXPECT_EQ(bad_utf8.message,
            "gfins-fw: command line: calibration.file = \"/tmp/caf\\xC3(.toml\": must be a path of "
            "valid UTF-8 without control characters (or empty for none)\n");
  EXPECT_EQ(quote_text("say \"hi\"\\\t\n"), "\"say \\\"hi\\\"\\\\\\t\\n\"");
  EXPECT_EQ(quote_text(std::string(70, 'x')), "\"" + std::string(60, 'x') + "...\"");
  EXPECT_EQ(printable_text("line 1\nline\x1B[2J\t2\n"), "line 1\nline\\u001B[2J\t2\n");
}

// Item 5: a problem validate() finds names the line of its key, like the reader's own.
TEST(Config, RuleProblemsCarryTheLineOfTheirKey) {
  const ConfigResult r = parse_config("[adc]\nsample_rate_hz = nan\n", "c.toml");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error,
            "c.toml:2: adc.sample_rate_hz = nan: must be 500, 1000, 2000 or 4000 (ADS131M06 data "
            "rates at 8.192 MHz)");
  const ConfigResult g = parse_config(
      "# site\n[navigation]\n\ngravity = \"constant\"\ngravity_mps2 = 98.1\n", "g.toml");
  ASSERT_FALSE(g.ok());
  EXPECT_EQ(g.error,
            "g.toml:5: navigation.gravity_mps2 = 98.1: must be 9.7..9.9 m/s² (the Earth's surface "
            "range is 9.76..9.84)");
  // (the defaults of the other messages, 10 to 1000, are multiples of 5)
  const ConfigResult o = parse_config("[output]\nepoch = 5\nstatus = 5\neuler = 7\n", "o.toml");
  ASSERT_FALSE(o.ok());
  EXPECT_EQ(o.error,
            "o.toml:4: output.euler = 7: must be 0 (off) or a multiple of output.epoch (5)");
  // A rule broken between a key in the file and a default not in it: the key named is the one
  // given, so the line is still there (epoch 20 leaves status at its default 10).
  const ConfigResult d = parse_config("[output]\n\nepoch = 20\n", "d.toml");
  ASSERT_FALSE(d.ok());
  EXPECT_EQ(d.error.rfind("d.toml: output.status = 10: must equal output.epoch (20)", 0), 0u)
      << d.error;
}

// Item 4: the rules the run applies when it opens the board are checked by validate() too.
TEST(Cli, ValuesTheRunWouldRefuseAreRefusedUpFront) {
  struct Case {
    std::vector<const char*> args;
    const char* message;
  };
  const std::vector<Case> cases = {
      // The candump lines carry the interface name: checked with a log file too.
      {{"--sim", "rest", "--can", "a b", "--can-log", "x.log"},
       "gfins-fw: command line: can.interface = \"a b\": must be an interface name of 1..15 "
       "characters without '/', ':' or spaces\n"},
      {{"--board", "hil", "--hil-address", "zz zz"},
       "gfins-fw: command line: hil.address = \"zz zz\": must be an IPv4 address a.b.c.d (each "
       "0..255), e.g. \"127.0.0.1\"\n"},
      {{"--hil-address", "10.0.0.256"},
       "gfins-fw: command line: hil.address = \"10.0.0.256\": must be an IPv4 address a.b.c.d "
       "(each 0..255), e.g. \"127.0.0.1\"\n"},
      {{"--drdy-line", "-5"},
       "gfins-fw: command line: adc.drdy_line = \"-5\": line offset must be 0..1023\n"},
      {{"--drdy-line", "99999"},
       "gfins-fw: command line: adc.drdy_line = \"99999\": line offset must be 0..1023\n"},
      {{"--drdy-line", "99999999999999999999"},  // std::stoi would throw on this one
       "gfins-fw: command line: adc.drdy_line = \"99999999999999999999\": line offset must be "
       "0..1023\n"},
  };
  for (const Case& c : cases) {
    std::vector<const char*> args = c.args;
    args.insert(args.begin(), "gfins-fw");
    const CliResult r = parse_command_line(static_cast<int>(args.size()), args.data());
    EXPECT_FALSE(r.config) << c.message;
    EXPECT_EQ(r.exit_code, 2) << c.message;
    EXPECT_EQ(r.message, c.message);
  }
  // The file's string form obeys the same rule as its integer form and the option.
  const ConfigResult f = parse_config("[adc]\ndrdy_line = \"99999\"\n", "f.toml");
  EXPECT_EQ(f.error, "f.toml:2: adc.drdy_line = \"99999\": line offset must be 0..1023");
  const ConfigResult i = parse_config("[adc]\ndrdy_line = 99999\n", "f.toml");
  EXPECT_EQ(i.error, "f.toml:2: adc.drdy_line = 99999: line offset must be 0..1023");
  // Names and in-range offsets stay valid.
  for (const char* ok : {"0", "1023", "DRDY_N", "GPIO25"}) {
    std::vector<const char*> args = {"gfins-fw", "--drdy-line", ok};
    EXPECT_TRUE(parse_command_line(3, args.data()).config) << ok;
  }
}

// The boards of the host build of gfins-fw: the firmware's and the simulated one.
BoardTable host_boards() {
  BoardTable t;
  add_firmware_boards(t);
  sim_board::add_to(t);
  return t;
}

TEST(Cli, PreflightFindsWhatOnlyTheRunFoundBefore) {
  const BoardTable boards = host_boards();
  const std::string dir = GFINS_SCENARIO_DIR;
  FwConfig c;
  c.board = BoardKind::kSim;
  c.sim_scenario_dir = dir;
  c.sim_scenario = "rest";
  EXPECT_EQ(preflight(c, boards, "o"), "");
  c.sim_scenario = "nosuchscenario";
  const std::string missing = preflight(c, boards, "o");
  EXPECT_EQ(missing.rfind("o: sim.scenario = \"nosuchscenario\": ", 0), 0u) << missing;
  // The scenario's rate must be the ADC's.
  c.sim_scenario = "rest";
  c.sample_rate_hz = 2000;
  EXPECT_EQ(preflight(c, boards, "o"),
            "o: sim.scenario = \"rest\": runs at 1000 Hz: adc.sample_rate_hz must be the same");
  c.sample_rate_hz = 1000;
  // Output files: the folder must exist; a folder is not a file.
  c.can_log = "/nonexistent-gfins/x.log";
  EXPECT_EQ(preflight(c, boards, "o"),
            "o: can.log_file = \"/nonexistent-gfins/x.log\": its folder \"/nonexistent-gfins\" "
            "does not exist");
  // A folder that is a symlink loop does not "not exist": the system's ELOOP text says what it is.
  const std::string loop = ::testing::TempDir() + "gfins-preflight-loop";
  std::filesystem::remove(loop);
  std::filesystem::remove(loop + "2");
  std::filesystem::create_symlink(loop + "2", loop);
  std::filesystem::create_symlink(loop, loop + "2");
  c.can_log = loop + "/x.log";
  EXPECT_EQ(preflight(c, boards, "o"), "o: can.log_file = \"" + loop + "/x.log\": its folder \"" +
                                           loop +
                                           "\" cannot be looked at: " + std::strerror(ELOOP));
  std::filesystem::remove(loop);
  std::filesystem::remove(loop + "2");
  c.can_log = "/tmp";
  EXPECT_EQ(preflight(c, boards, "o"), "o: can.log_file = \"/tmp\": is a folder, not a file");
  c.can_log = "out.log";  // the working folder
  EXPECT_EQ(preflight(c, boards, "o"), "");
  EXPECT_EQ(preflight(c, boards, "o", "/nonexistent-gfins/x.csv"),
            "o: --latency-csv = \"/nonexistent-gfins/x.csv\": its folder \"/nonexistent-gfins\" "
            "does not exist");
  FwConfig h;
  h.board = BoardKind::kHil;
  h.hil_port_file = "/nonexistent-gfins/port";
  EXPECT_EQ(preflight(h, boards, "o"),
            "o: hil.port_file = \"/nonexistent-gfins/port\": its folder \"/nonexistent-gfins\" "
            "does not exist");
}

TEST(Cli, PreflightRefusesABoardThisBuildDoesNotHave) {
  // The board's own build of gfins-fw (GFINS_SIM_BOARD=OFF) registers only the firmware's boards.
  BoardTable board_only;
  add_firmware_boards(board_only);
  FwConfig c;
  c.board = BoardKind::kSim;
  c.sim_scenario_dir = GFINS_SCENARIO_DIR;
  c.sim_scenario = "rest";
  EXPECT_EQ(preflight(c, board_only, "o"),
            "o: board.kind = \"sim\": this gfins-fw is built without that board (the simulated "
            "board is host code: GFINS_SIM_BOARD=OFF)");
  EXPECT_EQ(make_board(board_only, c).error,
            "board.kind = \"sim\": this gfins-fw is built without that board (the simulated "
            "board is host code: GFINS_SIM_BOARD=OFF)");
  c.board = BoardKind::kLinux;
  EXPECT_EQ(preflight(c, board_only, "o"), "");
}

TEST(Cli, OriginSaysWhatTheConfigurationIsMadeOf) {
  EXPECT_EQ(cli({}).origin, "built-in defaults");
  EXPECT_EQ(cli({"--check-config"}).origin, "built-in defaults");
  EXPECT_EQ(cli({"--sim", "rest", "--check-config"}).origin, "built-in defaults + command line");
  const char* path = "cli_origin_config.toml";
  { std::ofstream(path) << "[can]\nnode_id = 3\n"; }
  const CliResult f = cli({"--config", path, "--check-config"});
  const CliResult fo = cli({"--config", path, "--node-id", "4"});
  std::remove(path);
  EXPECT_EQ(f.origin, "cli_origin_config.toml");
  EXPECT_EQ(fo.origin, "cli_origin_config.toml + command line");
}

}  // namespace
}  // namespace gfins::app
