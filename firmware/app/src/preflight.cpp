// Configuration checks against the file system (gfins/app/config.hpp, preflight()): what the run
// would otherwise find only when it gets there, so that --check-config and the start of a run
// reject the same configurations, and a run never ends with "cannot write" after its work.
#include <filesystem>
#include <system_error>

#include "gfins/app/board.hpp"
#include "gfins/app/config.hpp"
#include "gfins/app/startup.hpp"
#include "gfins/calib_file/calibration_file.hpp"

namespace gfins::app {
namespace {

namespace fs = std::filesystem;

// An output file the run creates or truncates: its folder must exist and the path must not be a
// folder. Whether the user may write there is learnt only by opening it, which the run does
// before its loop starts (a --check-config must not create files).
std::string output_path_problem(const std::string& path) {
  std::error_code ec;
  const fs::path p(path);
  if (fs::is_directory(p, ec)) return "is a folder, not a file";
  const fs::path parent = p.has_parent_path() ? p.parent_path() : fs::path(".");
  const bool there = fs::exists(parent, ec);
  if (ec)
    return "its folder " + quote_text(parent.string()) + " cannot be looked at: " + ec.message();
  if (!there) return "its folder " + quote_text(parent.string()) + " does not exist";
  if (!fs::is_directory(parent, ec)) return quote_text(parent.string()) + " is not a folder";
  return "";
}

}  // namespace

std::string preflight(const FwConfig& c, const BoardTable& boards, const std::string& origin,
                      const std::string& latency_csv) {
  const auto bad = [&](const std::string& key, const std::string& value, const std::string& why) {
    return origin + ": " + key + " = " + quote_text(value) + ": " + why;
  };
  // The board's own checks first (the simulated board: its scenario and its rate).
  const BoardEntry* board = boards.find(c.board);
  if (board == nullptr) return origin + ": " + board_not_built(c.board);
  if (board->check != nullptr) {
    if (std::string problem = board->check(c, origin); !problem.empty()) return problem;
  }
  if (!c.can_log.empty()) {
    if (std::string why = output_path_problem(c.can_log); !why.empty()) {
      return bad("can.log_file", c.can_log, why);
    }
  }
  if (!c.record_file.empty()) {
    if (std::string why = output_path_problem(c.record_file); !why.empty()) {
      return bad("record.file", c.record_file, why);
    }
  }
  if (c.board == BoardKind::kHil && !c.hil_port_file.empty()) {
    if (std::string why = output_path_problem(c.hil_port_file); !why.empty()) {
      return bad("hil.port_file", c.hil_port_file, why);
    }
  }
  if (!latency_csv.empty()) {
    if (!valid_path(latency_csv)) {
      return bad("--latency-csv", latency_csv,
                 "must be a path of valid UTF-8 without control characters");
    }
    if (std::string why = output_path_problem(latency_csv); !why.empty()) {
      return bad("--latency-csv", latency_csv, why);
    }
  }
  return "";
}

std::string calibration_note(const FwConfig& c) {
  constexpr const char* kConsequence = ": a run would navigate UNCALIBRATED (nominal defaults)";
  if (c.calibration_file.empty()) {
    return c.board == BoardKind::kSim ? std::string()
                                      : std::string("calibration.file is empty") + kConsequence;
  }
  const auto loaded = calib_file::load_calibration_file(c.calibration_file);
  std::string why;
  if (!loaded.is_ok()) {
    why = loaded.status().message();
  } else if (auto refusal = calibration_refusal(c, loaded.value(), nullptr)) {
    // The converter check needs the board itself; everything else is checked here as a run
    // would check it.
    why = *refusal;
  } else {
    return "";
  }
  return "calibration.file = " + quote_text(c.calibration_file) + ": " + why + kConsequence;
}

}  // namespace gfins::app
