// The committed derived files match what the message table generates now: docs/can/gfins.dbc
// byte for byte, and the generated blocks of docs/can-interface.md (signal tables, bus budget).
// Regenerate with build/.../gfins-can-gen dbc > docs/can/gfins.dbc (and icd / budget).
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "generate.hpp"
#include "gfins/can/message_table.hpp"

namespace gfins::can_tool {
namespace {

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string block(const std::string& doc, const std::string& begin, const std::string& end) {
  const auto b = doc.find(begin);
  const auto e = doc.find(end);
  if (b == std::string::npos || e == std::string::npos || e < b) return "<markers missing>";
  return doc.substr(b + begin.size() + 1, e - b - begin.size() - 1);
}

TEST(GeneratedFiles, CommittedDbcIsWhatTheTableGenerates) {
  const std::string committed = read_file(GFINS_SOURCE_DIR "/docs/can/gfins.dbc");
  ASSERT_FALSE(committed.empty());
  // The committed DBC decodes a stock board: the node of can.node_id's default (node 1), not 0.
  static_assert(can::kDefaultNodeId == 1);
  EXPECT_EQ(committed, generate_dbc(can::kDefaultNodeId))
      << "docs/can/gfins.dbc is stale: regenerate it with `gfins-can-gen dbc > docs/can/gfins.dbc`";
  EXPECT_NE(committed.find("BO_ 257 GfinsEpoch"), std::string::npos) << "0x100 + node 1";
}

TEST(GeneratedFiles, IcdTablesAreWhatTheTableGenerates) {
  const std::string doc = read_file(GFINS_SOURCE_DIR "/docs/can-interface.md");
  ASSERT_FALSE(doc.empty());
  EXPECT_EQ(block(doc, kSignalsBegin, kSignalsEnd), generate_signal_tables())
      << "regenerate with `gfins-can-gen icd`";
  EXPECT_EQ(block(doc, kBudgetBegin, kBudgetEnd),
            generate_budget_table(can::kDefaultSampleRateHz, can::kDefaultBitRate))
      << "regenerate with `gfins-can-gen budget`";
}

TEST(GeneratedFiles, DbcNodeIdShiftsEveryIdentifier) {
  const std::string n0 = generate_dbc(0);
  const std::string n5 = generate_dbc(5);
  EXPECT_NE(n0.find("BO_ 256 GfinsEpoch: 8 GFINS"), std::string::npos);
  EXPECT_NE(n5.find("BO_ 261 GfinsEpoch: 8 GFINS"), std::string::npos);
  EXPECT_NE(n5.find("BO_ 1669 GfinsResponse: 8 GFINS"), std::string::npos);  // 0x680 + 5
}

TEST(GeneratedFiles, DbcLinesFollowTheStandardSyntax) {
  // Signal lines as Vector's DBC format defines them, checked by hand-written patterns:
  //   SG_ name [M|mN] : start|length@1(+|-) (factor,offset) [min|max] "unit" receivers
  std::istringstream in(generate_dbc(0));
  std::string line;
  int signals = 0;
  while (std::getline(in, line)) {
    if (line.rfind(" SG_ ", 0) != 0) continue;
    ++signals;
    EXPECT_NE(line.find("@1"), std::string::npos) << line;  // Intel byte order everywhere
    EXPECT_NE(line.find(" ("), std::string::npos) << line;
    EXPECT_NE(line.find(") ["), std::string::npos) << line;
    EXPECT_NE(line.find("] \""), std::string::npos) << line;
    // Numbers in plain decimal notation (some readers reject exponents).
    const auto p0 = line.find(" (");
    const auto p1 = line.find("] \"");
    const std::string numbers = line.substr(p0, p1 - p0);
    EXPECT_EQ(numbers.find_first_of("eE"), std::string::npos) << line;
  }
  EXPECT_GT(signals, 80);
}

}  // namespace
}  // namespace gfins::can_tool
