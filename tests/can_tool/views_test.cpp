// The terminal views of gfins-can decode: a message its divider skipped in an epoch is shown as
// "-" in the line view (never nan); the table view keeps each signal's latest value with its age
// and aligns every row, the longest signal name included. Expected text written by hand.
#include "views.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <limits>
#include <string>
#include <vector>

namespace gfins::can_tool {
namespace {

std::string read_all(std::FILE* f) {
  std::rewind(f);
  std::string s;
  char buf[4096];
  std::size_t n = 0;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) s.append(buf, n);
  return s;
}

DecodedEpoch epoch(double time_us, double sample) {
  DecodedEpoch e;
  e.values.assign(columns().size(), std::numeric_limits<double>::quiet_NaN());
  e.present.assign(columns().size(), false);
  auto set = [&](const char* name, double v) {
    const auto i = static_cast<std::size_t>(column_index(name));
    e.values[i] = v;
    e.present[i] = true;
  };
  set("TimeUs", time_us);
  set("SampleCount", sample);
  set("Mode", 2);
  set("StatusFlags", 0);
  for (const char* n : {"RateX", "RateY", "RateZ", "VelN", "VelE", "VelD", "PosN", "PosE", "PosD"})
    set(n, 0.0);
  return e;
}

void set(DecodedEpoch& e, const char* name, double v) {
  const auto i = static_cast<std::size_t>(column_index(name));
  e.values[i] = v;
  e.present[i] = true;
}

TEST(Views, LineViewShowsADashForAMessageNotSentInTheEpoch) {
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  auto v = make_view(ViewKind::kLine, f);
  DecodedEpoch with = epoch(10000, 10);
  set(with, "Roll", 0.1);
  set(with, "Pitch", -0.2);
  set(with, "Yaw", std::numeric_limits<double>::quiet_NaN());  // sent as not available
  v->epoch(with);
  v->epoch(epoch(20000, 20));  // GfinsEuler not sent (divider 20)
  v->finish();
  const std::string out = read_all(f);
  std::fclose(f);
  // 0.1 rad = 5.730 deg, -0.2 rad = -11.459 deg.
  EXPECT_NE(out.find("rpy=(5.730 -11.459 n/a) deg"), std::string::npos) << out;
  EXPECT_NE(out.find("seq=20 Navigating rpy=- deg"), std::string::npos) << out;
  EXPECT_EQ(out.find("nan"), std::string::npos) << out;
}

TEST(Views, TableViewKeepsTheLatestValueWithItsAgeAndAlignsEveryRow) {
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  auto v = make_view(ViewKind::kTable, f);
  DecodedEpoch first = epoch(1000000, 0);
  set(first, "SaturatedSamples", 7);  // health: sent once every 100 epochs at the defaults
  set(first, "MissedEdges", 3);
  v->epoch(first);
  v->epoch(epoch(1250000, 250));  // 0.25 s of device time later, no health frame
  v->finish();
  std::string out = read_all(f);
  std::fclose(f);
  const std::size_t last = out.rfind("\x1b[H\x1b[2J");  // the final draw
  ASSERT_NE(last, std::string::npos);
  out = out.substr(last);
  // Rows "  NAME<pad> VALUE(16 wide) UNIT": the value column ends at the same offset on every
  // row, SaturatedSamples (16 characters, the longest name) included.
  std::vector<std::string> rows;
  for (std::size_t p = 0, q; (q = out.find('\n', p)) != std::string::npos; p = q + 1) {
    const std::string row = out.substr(p, q - p);
    if (row.rfind("  ", 0) == 0) rows.push_back(row);
  }
  ASSERT_GT(rows.size(), 40u);
  constexpr std::size_t kValueEnd = 2 + 16 + 1 + 16;  // indent, name column, space, value
  for (const std::string& r : rows) {
    ASSERT_GE(r.size(), kValueEnd) << r;
    EXPECT_NE(r[kValueEnd - 1], ' ')
        << "value not right-aligned at column " << kValueEnd << ": " << r;
  }
  // Name padded to 16, value right-aligned in 16, a space, the (empty) unit padded to 8, the age.
  EXPECT_NE(out.find("  SaturatedSamples                7           (0.250 s ago)"),
            std::string::npos)
      << out;
  EXPECT_NE(out.find("  MissedEdges                     3           (0.250 s ago)"),
            std::string::npos)
      << out;
  EXPECT_NE(out.find("  Sensor1                         - m/s^2"), std::string::npos) << out;
}

}  // namespace
}  // namespace gfins::can_tool
