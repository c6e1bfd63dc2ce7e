// CAN settings kept across restarts (docs/can-interface.md, "Stored settings"): the file's text
// and checksum against a hand-written FNV-1a, every kind of damage refused with file, line and
// key, the start-up fallback and its flag, the commands that change and forget the settings on
// the simulated board, a failed save flagged on the bus, and a restart of the real program.
#include "gfins/app/can_settings.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <array>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "gfins/app/publisher_sink.hpp"
#include "gfins/can/command.hpp"
#include "sim_rig.hpp"
#include "support/temp_dir.hpp"
#ifdef GFINS_FW_EXE
#include "support/run_cli.hpp"
#endif

namespace gfins::app {
namespace {

using gfins::testing::SimRig;

// The [output] keys in the ICD's order (docs/firmware.md), written out here.
constexpr const char* kKeys[14] = {"epoch",       "status",        "quaternion", "euler",
                                   "rate",        "angular_accel", "accel",      "velocity",
                                   "position_ne", "position_d",    "health_adc", "health_system",
                                   "sensors_a",   "sensors_b"};

// FNV-1a 64 (Fowler/Noll/Vo: offset basis 0xcbf29ce484222325, prime 0x100000001b3), written here
// rather than taken from the project's header.
std::uint64_t fnv(const std::string& s) {
  std::uint64_t h = 0xcbf29ce484222325ull;
  for (const char ch : s) {
    h ^= static_cast<unsigned char>(ch);
    h *= 0x100000001b3ull;
  }
  return h;
}

// What a test stores: a node id (or none, -1), the dividers set (name -> value) and the
// identifier groups moved (data, input, command, response; -1 = not moved).
struct Stored {
  int node = -1;
  std::map<std::string, int> dividers;
  std::array<int, 4> id_bases = {-1, -1, -1, -1};
};

constexpr const char* kGroupKeys[4] = {"data_id_base", "input_id_base", "command_id_base",
                                       "response_id_base"};

// The checksum the ICD defines: FNV-1a of the lines "format_version=1", "node_id=N" (when
// stored), "output.NAME=D" for each divider stored, in the table's order, and "GROUP_id_base=B"
// (decimal) for each group moved, data to response, each ending in '\n'.
std::string checksum_of(const Stored& st) {
  std::string canonical = "format_version=1\n";
  if (st.node >= 0) canonical += "node_id=" + std::to_string(st.node) + "\n";
  for (const char* key : kKeys) {
    const auto it = st.dividers.find(key);
    if (it != st.dividers.end()) {
      canonical += "output." + std::string(key) + "=" + std::to_string(it->second) + "\n";
    }
  }
  for (std::size_t g = 0; g < 4; ++g) {
    if (st.id_bases[g] >= 0) {
      canonical += std::string(kGroupKeys[g]) + "=" + std::to_string(st.id_bases[g]) + "\n";
    }
  }
  char buf[40];
  std::snprintf(buf, sizeof buf, "fnv1a64:%016llx",
                static_cast<unsigned long long>(fnv(canonical)));
  return buf;
}

// A settings file as a person would write it from the ICD (dividers in the map's order, which is
// not the table's), with the checksum given.
std::string file_text(const Stored& st, const std::string& sum, int version = 1,
                      const std::string& extra = "") {
  std::ostringstream o;
  o << "format_version = " << version << "\n";
  if (st.node >= 0) o << "node_id = " << st.node << "\n";
  for (std::size_t g = 4; g-- > 0;) {  // not the canonical order
    if (st.id_bases[g] >= 0) o << kGroupKeys[g] << " = " << st.id_bases[g] << "\n";
  }
  o << extra << "[output]\n";
  for (const auto& [key, value] : st.dividers) o << key << " = " << value << "\n";
  o << "[integrity]\nchecksum = '" << sum << "'\n";
  return o.str();
}

CanSettings settings(const Stored& st) {
  CanSettings s;
  if (st.node >= 0) s.node_id = static_cast<std::uint8_t>(st.node);
  for (std::size_t m = 0; m < 14; ++m) {
    const auto it = st.dividers.find(kKeys[m]);
    if (it != st.dividers.end()) s.dividers[m] = static_cast<std::uint16_t>(it->second);
  }
  for (std::size_t g = 0; g < 4; ++g) {
    if (st.id_bases[g] >= 0) s.id_bases[g] = static_cast<std::uint16_t>(st.id_bases[g]);
  }
  return s;
}

TEST(CanSettingsFile, TextRoundTripsAndTheChecksumIsFnv1a64OfTheCanonicalLines) {
  const Stored st{5, {{"euler", 40}, {"accel", 20}}};
  const std::string text = settings_text(settings(st));
  EXPECT_NE(text.find("checksum = '" + checksum_of(st) + "'"), std::string::npos) << text;
  EXPECT_EQ(text.find("epoch ="), std::string::npos) << "only what a command set is stored";
  const SettingsParse p = parse_settings(text, "s.toml", FwConfig{});
  ASSERT_TRUE(p.settings) << p.error;
  EXPECT_EQ(*p.settings, settings(st));
  // A file written from the ICD by hand (other layout, same values) reads the same.
  const SettingsParse q = parse_settings(file_text(st, checksum_of(st)), "h.toml", FwConfig{});
  ASSERT_TRUE(q.settings) << q.error;
  EXPECT_EQ(*q.settings, settings(st));
  // Nothing but a divider, no node id: valid too.
  const Stored only{-1, {{"euler", 40}}};
  const SettingsParse r = parse_settings(file_text(only, checksum_of(only)), "o.toml", FwConfig{});
  ASSERT_TRUE(r.settings) << r.error;
  EXPECT_FALSE(r.settings->node_id);
  // Identifier groups moved by SetIdBase: written in hex, covered by the checksum in decimal.
  const Stored ids{-1, {}, {0x300, -1, 0x100, -1}};
  const std::string ids_text = settings_text(settings(ids));
  EXPECT_NE(ids_text.find("data_id_base = 0x300\n"), std::string::npos) << ids_text;
  EXPECT_NE(ids_text.find("checksum = '" + checksum_of(ids) + "'"), std::string::npos) << ids_text;
  const SettingsParse t = parse_settings(ids_text, "i.toml", FwConfig{});
  ASSERT_TRUE(t.settings) << t.error;
  EXPECT_EQ(*t.settings, settings(ids));
  const SettingsParse u = parse_settings(file_text(ids, checksum_of(ids)), "j.toml", FwConfig{});
  ASSERT_TRUE(u.settings) << u.error;
  EXPECT_EQ(*u.settings, settings(ids));
}

TEST(CanSettingsFile, EveryDamageIsRefusedWithFileLineAndKey) {
  const Stored good{1, {{"euler", 40}}};
  const std::string good_sum = checksum_of(good);
  const Stored edited{1, {{"euler", 80}}};
  const Stored euler15{1, {{"euler", 15}}};  // not a multiple of the configuration's epoch 10
  struct Case {
    const char* what;
    std::string text;
    std::string expect;
  };
  const Case cases[] = {
      {"a divider edited, checksum not", file_text(edited, good_sum),
       "h.toml:6: integrity.checksum"},
      {"node id edited", file_text(Stored{2, good.dividers}, good_sum),
       "the file was changed or damaged"},
      {"a key added", file_text(Stored{1, {{"euler", 40}, {"accel", 20}}}, good_sum),
       "the file was changed or damaged"},
      {"another version", file_text(good, good_sum, 2),
       "h.toml:1: format_version = 2: this build reads version 1"},
      {"a key the version does not have", file_text(good, good_sum, 1, "profile = 1\n"),
       "h.toml:3: unknown key \"profile\""},
      {"an unknown message", file_text(Stored{1, {{"eulr", 40}}}, good_sum), "unknown key output."},
      {"node id out of range", file_text(Stored{16, {}}, checksum_of(Stored{16, {}})),
       "h.toml:2: node_id must be an integer 0..15"},
      {"no checksum", "format_version = 1\nnode_id = 1\n", "integrity.checksum is missing"},
      {"TOML syntax", "format_version = \n", "h.toml:1: TOML syntax"},
      {"checksum right, rules broken", file_text(euler15, checksum_of(euler15)),
       "breaks the configuration's rules"},
      {"a group moved onto another",
       file_text(Stored{-1, {}, {-1, -1, 0x100, -1}},
                 checksum_of(Stored{-1, {}, {-1, -1, 0x100, -1}})),
       "the stored can.command_id_base = 0x100 breaks the configuration's rules"},
      {"a base past 11 bits", file_text(Stored{-1, {}, {0x800, -1, -1, -1}}, good_sum),
       "h.toml:2: data_id_base must be an integer 0..2047"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    const SettingsParse p = parse_settings(c.text, "h.toml", FwConfig{});
    EXPECT_FALSE(p.settings);
    EXPECT_NE(p.error.find(c.expect), std::string::npos) << p.error;
  }
  // The same file is valid or not with the configuration it meets: at 4 kHz the default
  // dividers exceed the 50 % bus budget (docs/can-interface.md), and a stored euler = 40 does
  // not bring them back under it.
  FwConfig fast;
  fast.sample_rate_hz = 4000.0;
  const SettingsParse p = parse_settings(file_text(good, good_sum), "h.toml", fast);
  EXPECT_FALSE(p.settings);
  EXPECT_NE(p.error.find("bus load"), std::string::npos) << p.error;
}

TEST(CanSettingsFile, StartUpUsesAValidFileTheCommandLineWinsAndDamageFallsBackWithAFlag) {
  gfins::testing::TempDir dir("gfins-settings");
  const std::filesystem::path file = dir.path() / "can.toml";
  FwConfig c;
  c.can_settings_file.clear();
  EXPECT_EQ(load_stored_settings(c).source, SettingsSource::kConfiguration);
  EXPECT_TRUE(load_stored_settings(c).message.empty()) << "nothing configured, nothing to say";
  c.can_settings_file = file.string();
  StartupSettings s = load_stored_settings(c);
  EXPECT_EQ(s.source, SettingsSource::kConfiguration);
  EXPECT_NE(s.message.find("nothing stored yet"), std::string::npos) << s.message;
  const Stored st{7, {{"euler", 40}}};
  gfins::testing::write_text(file, file_text(st, checksum_of(st)));
  FwConfig applied = c;
  applied.dividers[4] = 20;  // rate: the configuration's, not stored
  s = load_stored_settings(applied);
  EXPECT_EQ(s.source, SettingsSource::kStored);
  EXPECT_EQ(s.stored, settings(st));
  EXPECT_EQ(applied.node_id, 7);
  EXPECT_EQ(applied.dividers[3], 40);
  EXPECT_EQ(applied.dividers[4], 20) << "what no command set stays the configuration's";
  // The command line wins over the file, and the message says which stored value lost.
  FwConfig cli = c;
  cli.node_id = 3;
  cli.node_id_from_cli = true;
  cli.dividers[3] = 100;
  cli.dividers_from_cli = 1u << 3;
  s = load_stored_settings(cli);
  EXPECT_EQ(cli.node_id, 3);
  EXPECT_EQ(cli.dividers[3], 100);
  EXPECT_NE(s.message.find("node_id = 7 (--node-id 3)"), std::string::npos) << s.message;
  EXPECT_NE(s.message.find("output.euler = 40 (--divider euler=100)"), std::string::npos)
      << s.message;
  // One byte off: the configuration's settings, the flag, and a message naming file and key.
  gfins::testing::write_text(file, file_text(Stored{7, {{"euler", 80}}}, checksum_of(st)));
  FwConfig fallback = c;
  s = load_stored_settings(fallback);
  EXPECT_EQ(s.source, SettingsSource::kStoredCorrupt);
  EXPECT_EQ(fallback.node_id, c.node_id);
  EXPECT_EQ(fallback.dividers, c.dividers);
  EXPECT_NE(s.message.find("can.toml:6: integrity.checksum"), std::string::npos) << s.message;
  // A folder, and a FIFO (which a plain read would wait on forever) where the file should be:
  // flagged alike, without blocking.
  std::filesystem::remove(file);
  std::filesystem::create_directory(file);
  s = load_stored_settings(fallback);
  EXPECT_EQ(s.source, SettingsSource::kStoredCorrupt);
  EXPECT_NE(s.message.find("not a regular file"), std::string::npos) << s.message;
  std::filesystem::remove(file);
  ASSERT_EQ(::mkfifo(file.c_str(), 0600), 0);
  s = load_stored_settings(fallback);
  EXPECT_EQ(s.source, SettingsSource::kStoredCorrupt);
  EXPECT_NE(s.message.find("not a regular file"), std::string::npos) << s.message;
}

// ---- On the simulated board ---------------------------------------------------------------

std::uint16_t g_sequence = 0;

can::Command numbered(can::Opcode op) {
  can::Command c;
  c.opcode = op;
  c.token = 0x70;
  c.sequence = ++g_sequence;
  return c;
}

// Sends `c`, runs two cycles, returns the status response's result (or -1 without one).
int send(SimRig& rig, const can::Command& c, std::uint32_t* value = nullptr) {
  rig.bus->clear_sent();
  EXPECT_TRUE(rig.bus->inject_rx(can::encode_command(c, SimRig::kNode)));
  rig.run_cycles(2);
  for (const hal::CanFrame& f : rig.bus->sent()) {
    const auto r = can::decode_response(f);
    if (r.is_ok() && r->part == can::kPartStatus) {
      if (value != nullptr) *value = r->value;
      return static_cast<int>(r->result);
    }
  }
  return -1;
}

// Frames with identifier `id` in the next `cycles` samples, and the last one's byte 6.
std::size_t frames(SimRig& rig, std::uint32_t id, std::uint32_t cycles, int* byte6 = nullptr) {
  rig.bus->clear_sent();
  rig.run_cycles(cycles);
  std::size_t n = 0;
  for (const hal::CanFrame& f : rig.bus->sent()) {
    if (f.id != id) continue;
    ++n;
    if (byte6 != nullptr) *byte6 = f.data[6];
  }
  return n;
}

SettingsParse read_back(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return parse_settings(s.str(), p.string(), FwConfig{});
}

TEST(StoredSettings, CommandsAreKeptAndRestoreDefaultsForgetsThem) {
  gfins::testing::TempDir dir("gfins-settings");
  const std::filesystem::path file = dir.path() / "can.toml";
  SimRig rig("rest", 8.0);
  SettingsWriter writer(file.string(), SettingsSource::kConfiguration);
  rig.loop->set_settings_port(&writer);
  rig.configure();
  rig.run_cycles(1500);
  // GfinsCommandCounters (0x200 + node) byte 6, bits 0-1: where the settings came from.
  constexpr std::uint32_t kCounters = 0x200 + SimRig::kNode;
  int byte6 = -1;
  ASSERT_EQ(frames(rig, kCounters, 1000, &byte6), 1u);
  EXPECT_EQ(byte6 & 3, 0) << "Configuration";

  can::Command div = numbered(can::Opcode::kSetDivider);
  div.message = can::MessageId::kEuler;
  div.divider = 40;
  ASSERT_EQ(send(rig, div), 0);
  writer.wait_settled();
  SettingsParse kept = read_back(file);
  ASSERT_TRUE(kept.settings) << kept.error;
  EXPECT_EQ(kept.settings->dividers[3], 40);
  EXPECT_FALSE(kept.settings->node_id) << "only what a command set is stored";
  EXPECT_FALSE(kept.settings->dividers[0]);
  EXPECT_EQ(frames(rig, kCounters, 1000, &byte6), 1u);
  EXPECT_EQ(byte6 & 3, 1) << "Stored";

  can::Command node = numbered(can::Opcode::kSetNodeId);
  node.node_id = 5;
  std::uint32_t value = 0;
  ASSERT_EQ(send(rig, node, &value), 0);
  EXPECT_EQ(value, 5u);
  writer.wait_settled();
  kept = read_back(file);
  ASSERT_TRUE(kept.settings) << kept.error;
  EXPECT_EQ(kept.settings->node_id, 5);
  EXPECT_EQ(kept.settings->dividers[3], 40) << "the divider stays";
  // The node id changes at the next start: this run still speaks as node 1.
  EXPECT_EQ(frames(rig, 0x100 + SimRig::kNode, 100), 10u);
  EXPECT_EQ(frames(rig, 0x100 + 5, 100), 0u);
  EXPECT_EQ(frames(rig, 0x130 + SimRig::kNode, 400), 10u) << "Euler every 40 samples";

  ASSERT_EQ(send(rig, numbered(can::Opcode::kRestoreDefaults), &value), 0);
  EXPECT_EQ(value, SimRig::kNode) << "the configuration's node id from the next start";
  writer.wait_settled();
  EXPECT_FALSE(std::filesystem::exists(file));
  EXPECT_EQ(frames(rig, 0x130 + SimRig::kNode, 400), 20u) << "Euler every 20 samples again";
  EXPECT_EQ(frames(rig, kCounters, 1000, &byte6), 1u);
  EXPECT_EQ(byte6 & 3, 0) << "Configuration";
  EXPECT_EQ(rig.loop->health().command_errors, 0u);
}

TEST(StoredSettings, WithoutAStoreSetNodeIdIsRefusedAndASaveThatFailsIsFlagged) {
  SimRig rig("rest", 5.0);
  rig.configure();
  rig.run_cycles(1500);
  can::Command node = numbered(can::Opcode::kSetNodeId);
  node.node_id = 3;
  EXPECT_EQ(send(rig, node), 7) << "Failed: a node id that would be forgotten";
  EXPECT_EQ(rig.loop->health().last_refusal, 7);
  // RestoreDefaults needs no store: the configuration's dividers come back.
  can::Command euler = numbered(can::Opcode::kSetDivider);
  euler.message = can::MessageId::kEuler;
  euler.divider = 40;
  ASSERT_EQ(send(rig, euler), 0);
  EXPECT_EQ(frames(rig, 0x130 + SimRig::kNode, 400), 10u);
  std::uint32_t value = 99;
  EXPECT_EQ(send(rig, numbered(can::Opcode::kRestoreDefaults), &value), 0);
  EXPECT_EQ(value, SimRig::kNode);
  EXPECT_EQ(frames(rig, 0x130 + SimRig::kNode, 400), 20u);

  gfins::testing::TempDir dir("gfins-settings");
  SimRig other("rest", 5.0);
  // A folder that does not exist: the atomic save cannot create its temporary file.
  SettingsWriter writer((dir.path() / "missing" / "can.toml").string(),
                        SettingsSource::kConfiguration);
  other.loop->set_settings_port(&writer);
  other.configure();
  other.run_cycles(1500);
  can::Command div = numbered(can::Opcode::kSetDivider);
  div.message = can::MessageId::kEuler;
  div.divider = 40;
  ASSERT_EQ(send(other, div), 0) << "the divider is in use";
  writer.wait_settled();
  int byte6 = -1;
  ASSERT_EQ(frames(other, 0x200 + SimRig::kNode, 1000, &byte6), 1u);
  EXPECT_EQ(byte6 & 3, 3) << "SaveFailed";
  EXPECT_EQ(frames(other, 0x130 + SimRig::kNode, 400), 10u);
}

// SetIdBase stores a group's base for the next start. The groups of the next start are the
// configuration's with the stored ones and the new one; the ICD's stock groups (data 0x100, input
// 0x0B0, command 0x600, response 0x680, each its messages' offsets plus 16 node ids) and a
// reserved range 0x700..0x70F are written out here.
TEST(StoredSettings, SetIdBaseIsKeptForTheNextStartAndRefusedWhereItWouldCollide) {
  gfins::testing::TempDir dir("gfins-settings");
  const std::filesystem::path file = dir.path() / "can.toml";
  SimRig rig("rest", 5.0);
  rig.config.reserved_ids = {{0x700, 0x70F}};
  SettingsWriter writer(file.string(), SettingsSource::kConfiguration);
  rig.loop->set_settings_port(&writer);
  rig.configure();
  rig.run_cycles(1500);
  const auto set_base = [&](can::IdGroup g, std::uint16_t base, std::uint32_t* value = nullptr) {
    can::Command c = numbered(can::Opcode::kSetIdBase);
    c.id_group = g;
    c.id_base = base;
    return send(rig, c, value);
  };
  std::uint32_t value = 0;
  ASSERT_EQ(set_base(can::IdGroup::kData, 0x300, &value), 0);
  EXPECT_EQ(value, 0x300u);
  writer.wait_settled();
  SettingsParse kept = read_back(file);
  ASSERT_TRUE(kept.settings) << kept.error;
  EXPECT_EQ(kept.settings->id_bases[0], 0x300);
  EXPECT_FALSE(kept.settings->id_bases[2]);
  // This run keeps its identifiers: the epoch still on 0x100 + node.
  EXPECT_EQ(frames(rig, 0x100 + SimRig::kNode, 100), 10u);
  EXPECT_EQ(frames(rig, 0x300 + SimRig::kNode, 100), 0u);
  // Refused (Result 4, nothing stored): the command group onto the data group's next-start
  // 0x300, the response group over the reserved 0x700..0x70F, the input group past 0x7FF.
  EXPECT_EQ(set_base(can::IdGroup::kCommand, 0x300), 4);
  EXPECT_EQ(set_base(can::IdGroup::kResponse, 0x6F8), 4);
  EXPECT_EQ(set_base(can::IdGroup::kInput, 0x7F8), 4);
  EXPECT_EQ(rig.loop->health().last_refusal, 4);
  // The command group onto the configuration's data identifiers is free at the next start.
  ASSERT_EQ(set_base(can::IdGroup::kCommand, 0x100), 0);
  writer.wait_settled();
  kept = read_back(file);
  ASSERT_TRUE(kept.settings) << kept.error;
  EXPECT_EQ(kept.settings->id_bases[0], 0x300);
  EXPECT_EQ(kept.settings->id_bases[2], 0x100);
  EXPECT_FALSE(kept.settings->id_bases[1]);
  EXPECT_FALSE(kept.settings->id_bases[3]);
  ASSERT_EQ(send(rig, numbered(can::Opcode::kRestoreDefaults)), 0);
  writer.wait_settled();
  EXPECT_FALSE(std::filesystem::exists(file));

  // Without a store the base would be forgotten before it takes effect: refused (Result 7).
  SimRig bare("rest", 5.0);
  bare.configure();
  bare.run_cycles(1500);
  can::Command c = numbered(can::Opcode::kSetIdBase);
  c.id_group = can::IdGroup::kData;
  c.id_base = 0x300;
  EXPECT_EQ(send(bare, c), 7);
}

// The messages the board derives from the epoch divider (its command counters always, the
// filter's two with aiding) follow a new epoch divider instead of blocking it, and come back with
// the old one: 1000, 200 and 400 samples rounded up to multiples of 30 are 1020, 210 and 420.
TEST(StoredSettings, TheBoardsOwnMessagesFollowTheEpochDivider) {
  for (const bool aiding : {false, true}) {
    SCOPED_TRACE(aiding);
    sim_board::MemoryCanBus bus(64);
    FwConfig c;
    c.aiding = aiding;
    c.dividers.fill(0);
    c.dividers[0] = c.dividers[1] = 10;  // epoch and status alone
    PublisherSink sink(bus, 1, bus_dividers(c), bus_budget(c));
    ASSERT_TRUE(sink.publisher().init_status().is_ok());
    ASSERT_TRUE(sink.set_divider(0, 30).is_ok());
    const can::Publisher& p = sink.publisher();
    EXPECT_EQ(p.divider(can::MessageId::kStatus), 30);
    EXPECT_EQ(p.divider(can::MessageId::kCommandCounters), 1020);
    EXPECT_EQ(p.divider(can::MessageId::kAccuracy), aiding ? 210 : 0);
    EXPECT_EQ(p.divider(can::MessageId::kAidingCounters), aiding ? 420 : 0);
    ASSERT_TRUE(sink.set_dividers(c.dividers).is_ok()) << "RestoreDefaults' path";
    EXPECT_EQ(p.divider(can::MessageId::kEpoch), 10);
    EXPECT_EQ(p.divider(can::MessageId::kCommandCounters), 1000);
    EXPECT_EQ(p.divider(can::MessageId::kAccuracy), aiding ? 200 : 0);
    // The status divider alone is still refused: it follows the epoch's.
    EXPECT_FALSE(sink.set_divider(1, 20).is_ok());
  }
}

#ifdef GFINS_FW_EXE
// Node id 5 and Euler every 40 samples set by commands on the in-process board, then gfins-fw
// started on that file: its CAN log speaks as node 5 at the stored rates and says "Stored". A
// damaged file gives the configuration's node and "StoredCorrupt", and the run goes on.
TEST(StoredSettings, SurviveARestartOfTheProgram) {
  gfins::testing::TempDir dir("gfins-settings");
  const std::string file = (dir.path() / "can.toml").string();
  {
    SimRig rig("rest", 5.0);
    SettingsWriter writer(file, SettingsSource::kConfiguration);
    rig.loop->set_settings_port(&writer);
    rig.configure();
    rig.run_cycles(1500);
    can::Command node = numbered(can::Opcode::kSetNodeId);
    node.node_id = 5;
    ASSERT_EQ(send(rig, node), 0);
    can::Command div = numbered(can::Opcode::kSetDivider);
    div.message = can::MessageId::kEuler;
    div.divider = 40;
    ASSERT_EQ(send(rig, div), 0);
    can::Command ids = numbered(can::Opcode::kSetIdBase);
    ids.id_group = can::IdGroup::kData;
    ids.id_base = 0x300;
    ASSERT_EQ(send(rig, ids), 0);
    writer.wait_settled();
  }
  // Frames per identifier of a candump log "(t) iface ID#DATA", and the last frame's data.
  const auto count = [](const std::string& log, std::map<std::uint32_t, std::string>* last) {
    std::map<std::uint32_t, int> n;
    std::ifstream in(log);
    std::string line;
    while (std::getline(in, line)) {
      const auto hash = line.find('#');
      const auto sp = line.rfind(' ', hash);
      if (hash == std::string::npos || sp == std::string::npos) continue;
      const auto id =
          static_cast<std::uint32_t>(std::stoul(line.substr(sp + 1, hash - sp - 1), nullptr, 16));
      ++n[id];
      if (last != nullptr) (*last)[id] = line.substr(hash + 1);
    }
    return n;
  };
  const auto run = [&](const std::string& log, std::vector<std::string> source) {
    std::vector<std::string> args = {"--sim",      "rest", "--calibration",  "",
                                     "--duration", "2",    "--scenario-dir", GFINS_SCENARIO_DIR,
                                     "--can-log",  log};
    args.insert(args.end(), source.begin(), source.end());
    return test::run_tool(GFINS_FW_EXE, args, dir.path());
  };
  const std::string log = (dir.path() / "stored.log").string();
  const test::CliResult r = run(log, {"--settings-file", file});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("stored CAN settings from"), std::string::npos) << r.err;
  std::map<std::uint32_t, std::string> last;
  std::map<std::uint32_t, int> n = count(log, &last);
  EXPECT_EQ(n[0x101], 0) << "node 1 no more";
  EXPECT_EQ(n[0x105], 0) << "the data group moved to 0x300";
  EXPECT_EQ(n[0x305], 201) << "epochs of node 5: 2 s at 1 kHz, divider 10, seq 0..2000";
  EXPECT_EQ(n[0x335], 51) << "Euler (0x130 + node in the stock group) every 40 samples";
  EXPECT_NE(r.err.find("can.data_id_base 0x300"), std::string::npos) << r.err;
  ASSERT_EQ(last.count(0x405), 1u);
  // Data as 16 hex digits: byte 6 is characters 12-13; bits 0-1 = 1, Stored.
  EXPECT_EQ(std::stoi(last[0x405].substr(12, 2), nullptr, 16) & 3, 1) << last[0x405];

  // A configuration file naming the same settings file, without --settings-file: the simulated
  // board leaves it alone (only the board itself keeps settings in can.settings_file; a replay
  // would carry out recorded commands again).
  const std::string cfg = (dir.path() / "fw.toml").string();
  gfins::testing::write_text(cfg, "[can]\nsettings_file = \"" + file + "\"\n");
  const std::string log_cfg = (dir.path() / "config.log").string();
  const test::CliResult rc = run(log_cfg, {"--config", cfg});
  ASSERT_EQ(rc.exit_code, 0) << rc.err;
  EXPECT_EQ(rc.err.find("stored CAN settings"), std::string::npos) << rc.err;
  n = count(log_cfg, nullptr);
  EXPECT_EQ(n[0x105], 0);
  EXPECT_EQ(n[0x101], 201) << "the configuration's node 1";

  // The file damaged (a divider changed by hand): the configuration's node 1, flagged, run on.
  {
    std::ifstream in(file);
    std::stringstream s;
    s << in.rdbuf();
    std::string text = s.str();
    const auto at = text.find("euler = 40");
    ASSERT_NE(at, std::string::npos) << text;
    text.replace(at, 10, "euler = 80");
    gfins::testing::write_text(file, text);
  }
  const std::string log2 = (dir.path() / "corrupt.log").string();
  const test::CliResult r2 = run(log2, {"--settings-file", file});
  ASSERT_EQ(r2.exit_code, 0) << r2.err;
  EXPECT_NE(r2.err.find("stored CAN settings ignored"), std::string::npos) << r2.err;
  EXPECT_NE(r2.err.find("integrity.checksum"), std::string::npos) << r2.err;
  last.clear();
  n = count(log2, &last);
  EXPECT_EQ(n[0x105], 0);
  EXPECT_EQ(n[0x101], 201);
  EXPECT_EQ(n[0x131], 101) << "Euler at the configuration's divider 20";
  ASSERT_EQ(last.count(0x201), 1u);
  EXPECT_EQ(std::stoi(last[0x201].substr(12, 2), nullptr, 16) & 3, 2) << "StoredCorrupt";
}
#endif

}  // namespace
}  // namespace gfins::app
