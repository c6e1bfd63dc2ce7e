// The scenario registry as a user meets it: a name is a name and a path is a path, so a
// file or folder named like a built-in scenario in the current folder never shadows it; an unknown
// name suggests the closest built-in names; the data folders are found relative to the program.
#include <gtest/gtest.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "gfins/host_sim/data_paths.hpp"
#include "gfins/host_sim/progress_interval.hpp"
#include "gfins/host_sim/scenario.hpp"

namespace gfins::sim {
namespace {

namespace fs = std::filesystem;

const std::string kBuiltinDir = std::string(GFINS_TEST_DATA_DIR) + "/../../host_sim/scenarios";

// A fresh folder under the system temp dir, removed at the end; the current folder is restored.
class ScenarioLookupFs : public ::testing::Test {
 protected:
  void SetUp() override {
    std::random_device rd;
    dir_ =
        fs::temp_directory_path() / ("gfins-lookup-" + std::to_string(rd()) + std::to_string(rd()));
    fs::create_directories(dir_);
    old_cwd_ = fs::current_path();
  }
  void TearDown() override {
    fs::current_path(old_cwd_);
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  void touch(const fs::path& p, const std::string& text = "not a scenario [[[\n") {
    fs::create_directories(p.parent_path());
    std::ofstream(p) << text;
  }
  fs::path dir_;
  fs::path old_cwd_;
};

TEST(ScenarioLookup, PathOrNameByItsSpelling) {
  EXPECT_FALSE(is_scenario_path("drive"));
  EXPECT_FALSE(is_scenario_path("rest-calibrated"));
  EXPECT_FALSE(is_scenario_path("x.tomlx"));
  EXPECT_TRUE(is_scenario_path("./drive"));
  EXPECT_TRUE(is_scenario_path("drive.toml"));
  EXPECT_TRUE(is_scenario_path("a/b"));
  EXPECT_TRUE(is_scenario_path("/abs/file"));
}

// Expected suggestions from Levenshtein distances worked by hand:
//   drvie -> drive 2 (two substitutions), spni -> spin 2, xyzzy -> every name > 2 and no
//   containment; rest-calib is contained in rest-calibrated (5 edits) and contains rest (6).
TEST(ScenarioLookup, ClosestNamesByEditDistance) {
  const std::vector<std::string> names = {"coning", "drive",           "drive-qa1100",
                                          "rest",   "rest-calibrated", "spin"};
  EXPECT_EQ(closest_names("drvie", names), std::vector<std::string>({"drive"}));
  EXPECT_EQ(closest_names("spni", names), std::vector<std::string>({"spin"}));
  EXPECT_TRUE(closest_names("xyzzy", names).empty());
  EXPECT_EQ(closest_names("rest-calib", names),
            std::vector<std::string>({"rest-calibrated", "rest"}));
  // drive 0 edits, drive-qa1100 contains it (7 edits): best first, at most max_count.
  EXPECT_EQ(closest_names("drive", names, 1), std::vector<std::string>({"drive"}));
}

TEST_F(ScenarioLookupFs, FileOrFolderOfTheSameNameDoesNotShadowABuiltIn) {
  // Given `gfins-sim run drive -o drive` left a folder "drive", and a junk file "rest".
  fs::create_directories(dir_ / "drive");
  touch(dir_ / "rest");
  fs::current_path(dir_);
  // When the names are loaded, then the built-ins come back.
  const auto d = load_scenario("drive", kBuiltinDir);
  ASSERT_TRUE(d.is_ok()) << d.error().message;
  EXPECT_EQ(d.value().name, "drive");
  const auto r = load_scenario("rest", kBuiltinDir);
  ASSERT_TRUE(r.is_ok()) << r.error().message;
  EXPECT_EQ(r.value().name, "rest");
  // And the path spelling reaches the local folder / file.
  const auto folder = load_scenario("./drive", kBuiltinDir);
  ASSERT_FALSE(folder.is_ok());
  EXPECT_NE(folder.error().message.find("is a folder"), std::string::npos)
      << folder.error().message;
  const auto junk = load_scenario("./rest", kBuiltinDir);
  ASSERT_FALSE(junk.is_ok());
  EXPECT_NE(junk.error().message.find("./rest"), std::string::npos) << junk.error().message;
}

TEST_F(ScenarioLookupFs, UnknownNameSuggestsClosestAndList) {
  touch(dir_ / "mine");
  fs::current_path(dir_);
  const auto typo = load_scenario("drvie", kBuiltinDir);
  ASSERT_FALSE(typo.is_ok());
  const std::string& m = typo.error().message;
  EXPECT_NE(m.find("'drvie' is not a built-in scenario"), std::string::npos) << m;
  EXPECT_NE(m.find("closest: drive"), std::string::npos) << m;
  EXPECT_NE(m.find("gfins-sim list"), std::string::npos) << m;
  // A local file with a name's spelling: the message says how to reach it.
  const auto local = load_scenario("mine", kBuiltinDir);
  ASSERT_FALSE(local.is_ok());
  EXPECT_NE(local.error().message.find("./mine"), std::string::npos) << local.error().message;
  const auto missing = load_scenario("./nothing.toml", kBuiltinDir);
  ASSERT_FALSE(missing.is_ok());
  EXPECT_NE(missing.error().message.find("no such scenario file"), std::string::npos);
  // A symlink loop is not a missing file: the system's ELOOP text (strerror), not "no such".
  fs::create_symlink("loop-b.toml", dir_ / "loop-a.toml");
  fs::create_symlink("loop-a.toml", dir_ / "loop-b.toml");
  const auto loop = load_scenario("./loop-a.toml", kBuiltinDir);
  ASSERT_FALSE(loop.is_ok());
  const std::string& lm = loop.error().message;
  EXPECT_NE(lm.find("./loop-a.toml: cannot look at it: " + std::string(std::strerror(ELOOP))),
            std::string::npos)
      << lm;
  EXPECT_EQ(lm.find("no such"), std::string::npos) << lm;
}

// data_paths: the prefixes above a program's folder, as laid out by an install and a build tree.
TEST_F(ScenarioLookupFs, DataFolderFoundFromTheProgramsLocation) {
  ASSERT_EQ(::unsetenv(paths::kScenarioEnv), 0);
  // Installed: P/bin/prog finds P/share/gfins/scenarios.
  fs::create_directories(dir_ / "inst/share/gfins/scenarios");
  auto a = paths::find_data_dir_from(dir_ / "inst/bin/prog", "scenarios", paths::kScenarioEnv,
                                     {"gfins", "gfins-fw"});
  EXPECT_EQ(a.dir, dir_ / "inst/share/gfins/scenarios");
  // The firmware package alone: share/gfins-fw/scenarios.
  fs::create_directories(dir_ / "fw/share/gfins-fw/scenarios");
  auto f = paths::find_data_dir_from(dir_ / "fw/bin/gfins-fw", "scenarios", paths::kScenarioEnv,
                                     {"gfins", "gfins-fw"});
  EXPECT_EQ(f.dir, dir_ / "fw/share/gfins-fw/scenarios");
  // Build tree: B/host_sim/app/prog finds B/share/gfins/scripts two levels up.
  fs::create_directories(dir_ / "B/share/gfins/scripts");
  auto b = paths::find_data_dir_from(dir_ / "B/host_sim/app/prog", "scripts", nullptr, {"gfins"});
  EXPECT_EQ(b.dir, dir_ / "B/share/gfins/scripts");
  // The program four folders below the prefix is beyond the search (kPrefixLevels = 3): not found,
  // and the message lists the three prefixes tried.
  auto deep = paths::find_data_dir_from(dir_ / "B/a/b/c/d/prog", "scripts", nullptr, {"gfins"});
  EXPECT_FALSE(deep.found());
  EXPECT_EQ(deep.tried.size(), 3U);
}

TEST_F(ScenarioLookupFs, EnvironmentOverrideIsUsedAsGiven) {
  fs::create_directories(dir_ / "inst/share/gfins/scenarios");
  fs::create_directories(dir_ / "mine");
  ASSERT_EQ(::setenv(paths::kScenarioEnv, (dir_ / "mine").c_str(), 1), 0);
  auto a = paths::find_data_dir_from(dir_ / "inst/bin/prog", "scenarios", paths::kScenarioEnv,
                                     {"gfins"});
  EXPECT_EQ(a.dir, dir_ / "mine");
  // A wrong override is an error naming it, not a silent fallback to the installed folder.
  ASSERT_EQ(::setenv(paths::kScenarioEnv, (dir_ / "typo").c_str(), 1), 0);
  auto b = paths::find_data_dir_from(dir_ / "inst/bin/prog", "scenarios", paths::kScenarioEnv,
                                     {"gfins"});
  EXPECT_FALSE(b.found());
  EXPECT_NE(b.explain("scenario", "").find("GFINS_SCENARIO_DIR"), std::string::npos);
  ASSERT_EQ(::unsetenv(paths::kScenarioEnv), 0);
}

// One reading of $GFINS_PROGRESS_INTERVAL_S for gfins-sim, gfins-replay and gfins-fw's simulated
// board: a number in (0, 1e6) is taken, anything else falls back to the documented 5 s
// (docs/simulation.md).
TEST(ProgressInterval, ANumberInRangeIsTakenAnythingElseFallsBackToFiveSeconds) {
  ASSERT_EQ(::unsetenv(paths::kProgressIntervalEnv), 0);
  EXPECT_EQ(paths::progress_interval_s(), 5.0);
  const auto with = [](const char* text) {
    EXPECT_EQ(::setenv(paths::kProgressIntervalEnv, text, 1), 0);
    return paths::progress_interval_s();
  };
  EXPECT_EQ(with("0.05"), 0.05);
  EXPECT_EQ(with("2"), 2.0);
  for (const char* bad : {"", "0", "-1", "nan", "inf", "1e6", "0.1s", "abc", " "}) {
    EXPECT_EQ(with(bad), 5.0) << "'" << bad << "'";
  }
  ASSERT_EQ(::unsetenv(paths::kProgressIntervalEnv), 0);
}

}  // namespace
}  // namespace gfins::sim
