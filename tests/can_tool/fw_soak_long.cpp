// The soak (docs/reliability.md, "Soak"): one simulated hour at 1 kHz through `gfins-fw --sim`
// with a board fault every minute, every row of docs/faults.md that the simulated board can make
// in turn ([[board.faults]], docs/simulation.md), the filter on (standstill aiding), the CAN log
// decoded by `gfins-can decode` and held against the schedule this test wrote. The oracle is the
// schedule and the fault table below (docs/faults.md written out here: which counter and which
// status bit each fault must move), not the firmware's code.
//
// Checked:
//  - the run ends normally; resident memory at the loop's end within 1 MiB of its start (a loop
//    that allocated one byte per sample would grow by 3.4 MiB);
//  - no NaN or infinity anywhere in the decoded log;
//  - every health counter on the bus only grows, grows only inside the window of a fault that
//    explains it, and ends at the total the schedule implies (below);
//  - every fault shows its status bit inside its window, and no fault bit is ever set outside
//    the windows of the faults that raise it;
//  - every problem the decoder reports (frames or epochs missing) falls inside the window of a
//    fault that loses samples or frames;
//  - the navigation stays bounded: |v| below 0.05 m/s at the end (ten times the standstill
//    update's σ; unaided, the same hour ends beyond 300 m/s).
// A fault's window runs from its start to its end plus 1.2 s: the event bits are held 1 s
// (kEventHoldSamples) and the health frames that carry the counters go out at 1 Hz.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "support/cli_fixture.hpp"
#include "support/csv.hpp"

namespace gfins {
namespace {

constexpr double kHourS = 3600.0;
constexpr double kRateHz = 1000.0;
constexpr double kWindowTailS = 1.2;

struct Kind {
  const char* name;
  const char* keys;   // the kind's own keys in [[board.faults]]
  int bit;            // the StatusFlags bit docs/faults.md names for it
  std::set<int> may;  // every bit it may raise (its own, and the loop's consequences: a sample
                      // gap after lost conversions, input invalid for a rejected sample,
                      // health degraded for a faulty input)
  double duration_s;  // how long it lasts (0: an instant)
};

// docs/faults.md, row by row, with the bit numbers of docs/can-interface.md (StatusFlags).
const std::vector<Kind>& kinds() {
  static const std::vector<Kind> k = {
      {"crc_error", "", 6, {6, 2, 1}, 0.0},
      {"missed_edges", "count = 3\n", 1, {1}, 0.0},
      {"extra_edge", "", 17, {17}, 0.0},
      {"silent_line", "count = 6\n", 15, {15, 13, 2, 1}, 0.006},
      {"adc_reset", "", 14, {14, 1}, 0.0},
      {"saturated", "sensor = 4\nduration_s = 0.05\n", 7, {7, 13, 2, 1}, 0.05},
      {"stuck", "sensor = 2\nduration_s = 0.2\n", 8, {8, 13}, 0.2},
      {"can_refuse", "duration_s = 0.5\n", 11, {11}, 0.5},
      {"bus_off", "duration_s = 0.5\n", 16, {16, 11}, 0.5},
      {"read_error", "count = 3\n", 19, {19, 13, 2, 1}, 0.003},
      {"adc_dead", "duration_s = 1.0\n", 19, {19, 13, 2, 1}, 1.0},
  };
  return k;
}

struct Fault {
  std::size_t kind;
  double at_s;
  double end_s() const { return at_s + kinds()[kind].duration_s + kWindowTailS; }
  bool covers(double t) const { return t >= at_s && t <= end_s(); }
};

// One fault a minute from 30 s on, the kinds in turn: 60 faults, each kind five or six times.
std::vector<Fault> schedule() {
  std::vector<Fault> s;
  for (std::size_t k = 0; k < 60; ++k) {
    s.push_back({k % kinds().size(), 30.0 + 60.0 * static_cast<double>(k)});
  }
  return s;
}

class FwSoak : public test::CliTest {};

TEST_F(FwSoak, AnHourWithAFaultEveryMinuteIsAccountedForOnTheBus) {
  // The scenario: the QA-1100 board at rest for an hour, with the schedule.
  std::ifstream base(std::string(GFINS_SCENARIO_DIR) + "/rest-qa1100.toml");
  ASSERT_TRUE(base.good());
  std::ostringstream text;
  std::string line;
  bool replaced = false;
  while (std::getline(base, line)) {
    if (!replaced && line.rfind("duration_s", 0) == 0) {
      line = "duration_s = 3600.0";
      replaced = true;
    }
    text << line << "\n";
  }
  ASSERT_TRUE(replaced);
  const std::vector<Fault> faults = schedule();
  for (const Fault& f : faults) {
    text << "\n[[board.faults]]\nkind = \"" << kinds()[f.kind].name << "\"\nat_s = " << f.at_s
         << "\n"
         << kinds()[f.kind].keys;
  }
  const std::string scenario = file("soak.toml", text.str());
  const std::string cfg = file("aided.toml", "[aiding]\nenabled = true\n");
  const std::string log = path("soak.log"), csv = path("soak.csv");
  const auto fw = run(GFINS_FW_EXE, {"--config", cfg, "--sim", scenario, "--calibration", "",
                                     "--can-log", log, "--watchdog", "none"});
  ASSERT_EQ(fw.exit_code, 0) << fw.output.substr(0, 4000);
  // Every problem printed (--max-issues), so that each can be held against the schedule; exit 3:
  // decoded to the end with problems (the drops the faults cause).
  const auto dec =
      run(GFINS_CAN_EXE, {"decode", log, "--view", "csv", "-o", csv, "--max-issues", "100000"});
  ASSERT_EQ(dec.exit_code, 3) << dec.output.substr(0, 4000);

  // Memory: "memory: resident A KiB at the loop's start, B KiB at its end".
  const std::size_t m = fw.output.find("memory: resident ");
  ASSERT_NE(m, std::string::npos) << fw.output.substr(0, 4000);
  char* end = nullptr;
  const long rss0 = std::strtol(fw.output.c_str() + m + 17, &end, 10);
  const std::size_t m1 = fw.output.find("start, ", m);
  ASSERT_NE(m1, std::string::npos);
  const long rss1 = std::strtol(fw.output.c_str() + m1 + 7, nullptr, 10);
  EXPECT_GT(rss0, 0);
  EXPECT_LE(rss1 - rss0, 1024) << "resident memory grew from " << rss0 << " to " << rss1 << " KiB";

  // The decoded log.
  std::ifstream in(csv);
  test::DecodedTable t;  // the header only: the 80 MB of rows are read one at a time below
  ASSERT_TRUE(std::getline(in, line));
  t.names = test::decoded_names(line);
  const int ct = t.col("TimeUs"), cf = t.col("StatusFlags"), clog = t.col("log_time_s");
  ASSERT_GE(ct, 0);
  ASSERT_GE(cf, 0);
  ASSERT_GE(clog, 0);
  const std::vector<std::string> counters = {"MissedEdges",      "AdcCrcErrors", "AdcResets",
                                             "SaturatedSamples", "CanTxDropped", "BusOffEvents",
                                             "LoopOverruns"};
  std::map<std::string, int> cc;
  for (const std::string& c : counters) {
    cc[c] = t.col(c);
    ASSERT_GE(cc[c], 0) << c;
  }
  // Which kinds explain a counter's growth (docs/faults.md, "counter" column; the conversions a
  // reset, a failed read and a dead ADC cost become missed edges when the edges return).
  const std::map<std::string, std::set<std::string>> explains = {
      {"MissedEdges", {"missed_edges", "silent_line", "adc_reset", "read_error", "adc_dead"}},
      {"AdcCrcErrors", {"crc_error"}},
      {"AdcResets", {"adc_reset"}},
      {"SaturatedSamples", {"saturated"}},
      {"CanTxDropped", {"can_refuse", "bus_off"}},
      {"BusOffEvents", {"bus_off"}},
      {"LoopOverruns", {}}};
  const auto explained = [&](const std::set<std::string>& by, double t0, double t1) {
    for (const Fault& f : faults) {
      if (by.count(kinds()[f.kind].name) != 0 && f.at_s <= t1 && f.end_s() >= t0) return true;
    }
    return false;
  };
  std::map<std::string, double> last, last_t;
  std::vector<bool> bit_seen(faults.size(), false);
  std::size_t rows = 0, bad_values = 0, unexplained_bits = 0;
  std::string first_unexplained;
  double log_offset_s = 0.0, v_last = 0.0;
  bool have_offset = false;
  const int cvn = t.col("VelN"), cve = t.col("VelE"), cvd = t.col("VelD");
  ASSERT_TRUE(cvn >= 0 && cve >= 0 && cvd >= 0);
  while (std::getline(in, line)) {
    const std::vector<std::string> row = test::decoded_cells(line);
    if (row.size() != t.names.size()) continue;
    ++rows;
    for (std::size_t i = 3; i < row.size(); ++i) {
      const std::string& v = row[i];
      if (v.find("nan") != std::string::npos || v.find("inf") != std::string::npos) ++bad_values;
    }
    const auto at = [&row](int c) -> const std::string& {
      return row[static_cast<std::size_t>(c)];
    };
    if (at(ct).empty()) continue;
    const double time_s = std::stod(at(ct)) * 1e-6;
    if (!have_offset && !at(clog).empty()) {
      log_offset_s = std::stod(at(clog)) - time_s;
      have_offset = true;
    }
    if (!at(cvn).empty()) {
      v_last = std::hypot(std::stod(at(cvn)), std::stod(at(cve)), std::stod(at(cvd)));
    }
    // Counters: growing only, and only where a fault explains it.
    for (const std::string& c : counters) {
      const std::string& v = at(cc[c]);
      if (v.empty()) continue;
      const double x = std::stod(v);
      if (last.count(c) != 0) {
        EXPECT_GE(x, last[c]) << c << " went back at t = " << time_s << " s";
        if (x > last[c]) {
          EXPECT_TRUE(explained(explains.at(c), last_t[c], time_s))
              << c << " grew from " << last[c] << " to " << x << " between t = " << last_t[c]
              << " and " << time_s << " s, outside every fault that explains it";
        }
      }
      last[c] = x;
      last_t[c] = time_s;
    }
    // Status bits: each fault's own inside its window; none outside the windows that raise it.
    if (at(cf).empty()) continue;
    const auto flags = static_cast<std::uint32_t>(std::stoul(at(cf)));
    std::set<int> allowed;
    for (std::size_t i = 0; i < faults.size(); ++i) {
      if (!faults[i].covers(time_s)) continue;
      const Kind& k = kinds()[faults[i].kind];
      allowed.insert(k.may.begin(), k.may.end());
      if ((flags >> k.bit) & 1u) bit_seen[i] = true;
    }
    for (const int b : {1, 6, 7, 8, 11, 14, 15, 16, 17, 19}) {
      if (((flags >> b) & 1u) != 0 && allowed.count(b) == 0) {
        if (unexplained_bits++ == 0) {
          first_unexplained = "bit " + std::to_string(b) + " at t = " + std::to_string(time_s);
        }
      }
    }
  }
  std::printf("[ soak     ] %zu decoded rows, resident %ld -> %ld KiB\n", rows, rss0, rss1);
  EXPECT_GT(rows, 350000u);  // 100 epochs/s for an hour, less the ones the faults cost
  EXPECT_EQ(bad_values, 0u);
  EXPECT_EQ(unexplained_bits, 0u) << "first: " << first_unexplained;
  for (std::size_t i = 0; i < faults.size(); ++i) {
    EXPECT_TRUE(bit_seen[i]) << kinds()[faults[i].kind].name << " at " << faults[i].at_s
                             << " s: its status bit " << kinds()[faults[i].kind].bit
                             << " never set in its window";
  }
  // Totals the schedule implies: one per CRC error, reset and bus-off; 50 samples per 50 ms of
  // saturation; missed edges: 3 per missed_edges fault, 6 per silent line, the conversion each
  // reset costs, 3 per read_error, and per dead second the conversions after the one at its
  // start (taken before the window opens: the loop's clock is then the previous sample's) up to
  // its end: 1000 − 1.
  std::map<std::string, double> n;
  for (const Fault& f : faults) n[kinds()[f.kind].name] += 1.0;
  EXPECT_EQ(last["AdcCrcErrors"], n["crc_error"]);
  EXPECT_EQ(last["AdcResets"], n["adc_reset"]);
  EXPECT_EQ(last["BusOffEvents"], n["bus_off"]);
  EXPECT_EQ(last["SaturatedSamples"], n["saturated"] * 0.05 * kRateHz);
  EXPECT_EQ(last["MissedEdges"], 3 * n["missed_edges"] + 6 * n["silent_line"] + n["adc_reset"] +
                                     3 * n["read_error"] + (kRateHz - 1) * n["adc_dead"]);
  EXPECT_EQ(last["LoopOverruns"], 0.0);
  // The frames refused or dropped while bus-off: those the board would have sent in 0.5 s,
  // about 450 per window at the default rates (the frame count of the log per second, measured
  // here, within 3 %: the slow messages make the pattern of a half second vary by a few frames).
  std::ifstream logf(log);
  std::size_t frames = 0;
  while (std::getline(logf, line)) frames += line.empty() ? 0 : 1;
  const double per_s = static_cast<double>(frames) / kHourS;
  const double windows = n["can_refuse"] + n["bus_off"];
  EXPECT_NEAR(last["CanTxDropped"], windows * 0.5 * per_s, 0.03 * windows * 0.5 * per_s);
  // Every problem the decoder reported lies in a window of a fault that loses samples or frames.
  const std::set<std::string> losing = {"missed_edges", "silent_line", "adc_reset", "read_error",
                                        "adc_dead",     "can_refuse",  "bus_off"};
  std::vector<std::size_t> problem_lines;
  std::istringstream out(dec.output);
  while (std::getline(out, line)) {
    const std::size_t c1 = line.find(".log:");
    if (c1 == std::string::npos) continue;
    problem_lines.push_back(std::strtoul(line.c_str() + c1 + 5, nullptr, 10));
  }
  EXPECT_GT(problem_lines.size(), 0u);
  std::ifstream logg(log);
  std::size_t number = 0, next = 0, unexplained_problems = 0;
  std::sort(problem_lines.begin(), problem_lines.end());
  while (next < problem_lines.size() && std::getline(logg, line)) {
    ++number;
    for (; next < problem_lines.size() && problem_lines[next] == number; ++next) {
      const double t_s = std::stod(line.substr(1)) - log_offset_s;
      if (!explained(losing, t_s - 1.0, t_s)) {
        ++unexplained_problems;
        ADD_FAILURE() << "decoder problem at log line " << number << " (t = " << t_s
                      << " s) outside every fault that loses samples or frames";
      }
    }
  }
  EXPECT_EQ(unexplained_problems, 0u);
  EXPECT_LT(v_last, 0.05);
}

}  // namespace
}  // namespace gfins
