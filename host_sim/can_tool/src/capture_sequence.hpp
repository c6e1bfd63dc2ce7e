// gfins-can calibrate: the host side of an orientation calibration through the firmware
// (docs/calibration.md, "Calibrating a board through the firmware"). For every pose of a plan
// it asks the board for a capture (StartCapture, pose k, N samples: mean, standard deviation,
// count, saturation and motion flags per channel), refuses a capture that moved, saturated or
// was taken in the wrong pose (saying which channel and why), and writes the means CSV that
// gfins-calibrate reads (sensor,attitude,mean_v,std_v,count) with its poses file.
//
// The bus is any hal::CanBus: SocketCAN on a board or vcan, or an in-memory pair in tests.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "command_client.hpp"
#include "gfins/can/command.hpp"
#include "gfins/hal/can_bus.hpp"

namespace gfins::can_tool {

/// One pose of a calibration plan.
struct PlanPose {
  int attitude = 0;               // its number in the means CSV (all-sensor layout), 1-based
  std::string label;              // "T2.1" (Table 2 pose 1), "P7" (pose 7 of a poses file)
  std::array<double, 3> f_b_g{};  // specific force sensed at rest, body axes, g ("up")
  // Paper layout (Tables 4/5): the sensors recorded in this pose (bit i = sensor i+1) and the
  // attitude number they are written under (1..6 of their table).
  std::uint8_t paper_mask = 0;
  int paper_attitude = 0;
};

/// The twelve poses of the paper's Tables 2 (set β = sensors 2, 3, 5) and 3 (set α = sensors 1,
/// 4, 6), in that order: attitudes 1..12, labels T2.1..T2.6, T3.1..T3.6.
std::vector<PlanPose> tables23_plan();

/// A plan from a poses file's rows (attitude, fx_g, fy_g, fz_g), in file order, labels "P<n>".
/// Empty, with `error` naming the row, for a vector far from 1 g (outside 0.8..1.2 g), a
/// repeated attitude, or no rows.
std::vector<PlanPose> plan_from_rows(const std::vector<std::pair<int, std::array<double, 3>>>& rows,
                                     std::string& error);

/// How the tool waits for the board to be in the next pose.
enum class WaitMode : std::uint8_t {
  kHook,  // the caller's await_pose (the CLI asks the operator to press Enter)
  kAuto,  // short probe captures until the board is still in the expected pose
};

struct SequenceOptions {
  std::uint8_t node_id = 0;
  can::IdBases ids;  // the board's identifier groups (docs/can-interface.md, "Identifiers")
  std::uint16_t samples = 2000;  // N per pose
  double sample_rate_hz = 1000.0;
  /// Volts at the sensor per ADC count (QA-1100 chain: 1.2 V / 2^23 / (1/8.33)).
  double adc_lsb_v = 0.0;
  /// Nominal scale factors (V/g), only to recognise a pose and to express σ in g.
  std::array<double, 6> nominal_sf_v_per_g{1.33, 1.33, 1.33, 1.33, 1.33, 1.33};
  /// A channel further than this from the pose's expected output (Table 1 axes, nominal SF) means
  /// the board is not in that pose (g). The twelve poses of Tables 2/3 differ by at least 0.85 g
  /// on some channel; scale-factor spread (QA-1100: ±10 %), misalignment and bias stay below it.
  double pose_tolerance_g = 0.2;
  WaitMode wait = WaitMode::kHook;
  std::uint16_t probe_samples = 200;  // kAuto: length of one probe (0.2 s at 1 kHz)
  /// kAuto: consecutive probes still in the pose before the capture starts. The first such probe
  /// may still hold the last, slow part of a turn (below the motion limit, not below the noise
  /// of the mean); the second starts after it.
  int settle_probes = 2;
  double pose_timeout_s = 60.0;  // kAuto: give up after probing this long (board time) per pose
  int retries = 3;               // refused captures of one pose before giving up
  std::uint8_t first_token = 1;  // tokens count up from here (one per command)
  CommandTimeouts timeouts{};
};

/// Why a capture is not usable.
enum class Refusal : std::uint8_t { kNone, kIncomplete, kSaturated, kMotion, kWrongPose };
const char* to_string(Refusal r);

struct CaptureCheck {
  Refusal refusal = Refusal::kNone;
  std::string text;           // "pose 3 (T2.3) refused: ...", empty when accepted
  int looks_like = -1;        // kWrongPose: index in the plan of the pose it reads like, or -1
  std::uint8_t channels = 0;  // bit i: the channel(s) the refusal names
};

/// The checks of one capture against the pose it was meant for, in order: complete, no channel
/// saturated, no motion (the firmware's flags), every channel within pose_tolerance_g of the
/// pose's expected output.
CaptureCheck check_capture(const can::CaptureResult& r, const PlanPose& pose,
                           const std::vector<PlanPose>& plan, const SequenceOptions& o);

struct PoseCapture {
  PlanPose pose;
  can::CaptureResult result;
};

struct SequenceIo {
  /// kHook: called before each pose (again after a refusal); false aborts the sequence.
  std::function<bool(const PlanPose& pose, std::size_t index, std::size_t total, bool repeat)>
      await_pose;
  /// Progress and refusals, one line each (may be empty).
  std::function<void(const std::string&)> note;
};

struct SequenceResult {
  /// Why the sequence stopped early.
  enum class Stop : std::uint8_t {
    kNone,        // every pose captured
    kRefused,     // a pose refused retries + 1 times
    kNoAnswer,    // a command got no (complete) answer, or was rejected by the board
    kNotReached,  // kAuto: the pose was not seen within pose_timeout_s
    kAborted,     // the operator stopped (await_pose returned false), or bad options
  };
  bool ok = false;
  Stop stop = Stop::kNone;
  std::vector<PoseCapture> captures;  // the accepted ones, in plan order
  std::string error;                  // why it stopped (names the pose and the reason)
  int refused = 0;                    // captures refused along the way
};

/// Captures every pose of `plan` in order (see the file comment).
SequenceResult run_capture_sequence(hal::CanBus& bus, const std::vector<PlanPose>& plan,
                                    const SequenceOptions& o, const SequenceIo& io);

/// One StartCapture round trip with the next token; the outcome as run_command gives it.
CommandOutcome capture_once(hal::CanBus& bus, std::uint8_t pose, std::uint16_t samples,
                            const SequenceOptions& o, std::uint8_t& token);

/// The means CSV gfins-calibrate --means reads: sensor,attitude,mean_v,std_v,count, volts from
/// the codes by adc_lsb_v. `paper_layout`: each pose's paper_mask sensors under paper_attitude
/// (Tables 4/5, read without --poses); otherwise every sensor of every pose under its attitude
/// (read with the poses file of poses_csv).
std::string means_csv(const std::vector<PoseCapture>& captures, double adc_lsb_v,
                      bool paper_layout);

/// The poses file (attitude,fx_g,fy_g,fz_g) of a plan.
std::string poses_csv(const std::vector<PlanPose>& plan);

// ---- Location runs on a rate table (docs/calibration.md, "Location runs on a rate table") ----

/// One run of a rate-table plan: the mounting number, the body axis pointing up (the table axis,
/// normalised here) and the table rate.
struct RateTableRun {
  int mounting = 0;
  std::array<double, 3> up_b{};
  double rate_rad_s = 0.0;
};

/// A plan from a CSV with the rows mounting,axis_x,axis_y,axis_z,rate_rad_s (a header line
/// first). Empty, with `error` naming the line and the value, for a malformed line, a zero or
/// non-finite axis, a rate outside (0, 100] rad/s, or no rows.
std::vector<RateTableRun> rate_table_plan(const std::string& csv_text, std::string& error);

/// N for a capture of whole revolutions at rate_rad_s: the whole number of turns (at least one)
/// whose samples come nearest to target_samples, capped to what one capture holds (65535).
/// Whole turns average out what varies once per turn on a real table (axis tilt, wobble).
std::uint16_t whole_revolution_samples(double rate_rad_s, double sample_rate_hz,
                                       double target_samples);

/// Whether a capture is usable as a rate-table run: complete (every channel counted `samples`)
/// and no channel saturated; `why` names the channel otherwise. The firmware's motion flag is
/// *not* a refusal here: it is the static-pose test (spread above 2 mg), and a rotation whose
/// axis is a little off the vertical spreads gravity over the turn (0.16° gives 2 mg rms) while
/// its mean over whole turns is what the location solve wants; a flagged channel is named in
/// `note` so the operator can check the table.
bool check_rate_table_capture(const can::CaptureResult& r, std::uint16_t samples, std::string& why,
                              std::string* note = nullptr);

/// The header of gfins-calibrate --location-runs (mounting,axis_x,...,count), newline-terminated.
std::string location_runs_header();

/// One row of gfins-calibrate --location-runs from a capture: volts from the codes by adc_lsb_v,
/// the axis normalised, count = the samples of channel 1.
std::string location_run_row(const can::CaptureResult& r, int mounting,
                             const std::array<double, 3>& up_b, double rate_rad_s,
                             double adc_lsb_v);

/// The outcome of one rate-table run.
struct RateTableCapture {
  bool ok = false;
  std::uint16_t samples = 0;  // N asked for (whole revolutions)
  can::CaptureResult result;
  std::string row;    // location_run_row, when ok
  std::string error;  // why not ok (names the run, the channel and the reason)
  std::string note;   // check_rate_table_capture's note (motion flags), may be empty
};

/// One rate-table run (the code of gfins-can calibrate --rate-table): StartCapture over whole
/// revolutions nearest o.samples (pose number = the mounting), checked, as a --location-runs row.
RateTableCapture capture_rate_table_run(hal::CanBus& bus, const RateTableRun& run,
                                        const SequenceOptions& o, std::uint8_t& token);

}  // namespace gfins::can_tool
