// Simulation scenarios: what moves, which errors the array has, what the navigation core is told,
// described in TOML files (docs/simulation.md, "Scenario format"), and the run of one scenario
// through the navigation core the firmware uses (nav::NavPipeline), without and with compensation.
//
// Host code: the standard library and exceptions are allowed here, but nothing escapes this
// interface: errors come back as HostError values (error.hpp) whose message names the file, the
// key and the line.
#pragma once

#include <array>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "gfins/host_sim/error.hpp"
#include "gfins/host_sim/gnss_model.hpp"
#include "gfins/host_sim/nav_loop.hpp"
#include "gfins/host_sim/sensor_model.hpp"
#include "gfins/host_sim/trajectory.hpp"
#include "gfins/nav_core/calibration/multi_attitude.hpp"
#include "gfins/nav_core/compensator.hpp"
#include "gfins/nav_core/gravity.hpp"
#include "gfins/nav_core/misalignment.hpp"

namespace gfins::sim {

/// The motion. Which fields matter depends on `kind` (docs/simulation.md lists them).
struct TrajectorySpec {
  std::string kind = "rest";         // rest | constant_acceleration | spin | rate_table | coning |
                                     // maneuver | drive | stop_and_go | calibration_poses
  Vec3d euler0_rad = Vec3d::Zero();  // initial roll, pitch, yaw (file: degrees)
  Vec3d accel_n_mps2 = Vec3d::Zero();  // constant_acceleration
  Vec3d axis_b = Vec3d::UnitZ();       // spin, rate_table
  double rate_rps = 0.0;               // spin, rate_table (file: deg/s)
  double half_angle_rad = 0.0;         // coning (file: degrees)
  double cone_rate_rps = 0.0;          // coning (file: Hz → rad/s)
  double scale = 1.0;                  // maneuver
  double speed_mps = 10.0;             // drive: forward speed
  double turn_amplitude_m = 20.0;      // drive: lateral amplitude of the weave
  double turn_period_s = 20.0;         // drive: period of one left-right weave
  StopAndGoSpec stop_and_go{};         // stop_and_go (speed_mps above is its cruise speed)
  std::string poses = "both";          // calibration_poses: "table2" | "table3" | "both"
  double dwell_s = 10.0;               // calibration_poses: time at rest in each pose
  double transition_s = 2.0;           // calibration_poses: time to turn to the next pose
  std::vector<Vec3d> extra_poses_g;    // calibration_poses: more poses after the tables' (e.g.
                                       // verification poses), specific force in g, body axes
};

/// Where the compensator's misalignment comes from.
enum class MisalignmentSource : std::uint8_t {
  kTrue,        // the simulated (true) misalignment: the paper's §6.3 setting
  kCalibrated,  // estimated by a simulated multi-attitude calibration (Tables 2/3 poses)
};

enum class ScenarioGravity : std::uint8_t {
  kDown,    // constant |g| along +z of NED (the project's convention)
  kUp,      // constant |g| along −z of the navigation frame (the paper's §6.3 inertial frame)
  kNormal,  // WGS-84 normal gravity at a latitude and height
};

/// A simulated calibration: the twelve poses of Tables 2/3 held still, one mean per sensor and
/// pose with white noise of `mean_noise_g` (1σ of each mean, g).
struct CalibrationSpec {
  double mean_noise_g = 1e-3;
  double scale_v_per_g = 1.0;  // simulated SF of every sensor (V/g); the solver estimates it
  std::uint64_t seed = 7;
};

/// [aiding]: the navigation core's error-state filter and standstill updates
/// (nav/filter/aiding.hpp). The filter's noise model comes from the scenario's sensors (white σ per
/// sample); the bias prior and walk are stated here because the filter cannot know the truth.
struct AidingSpec {
  bool enabled = false;
  std::uint32_t decimation = 10;    // filter propagation every D samples
  bool standstill = true;           // ZUPT + ZARU when the detector says "at rest"
  std::uint32_t window = 100;       // standstill detector window, samples
  double false_alarm = 0.01;        // P(a rest window declared moving)
  double zupt_sigma_mps = 0.01;     // 1σ of the zero-velocity pseudo-measurement
  double zaru_sigma_rps = 1e-3;     // 1σ of the zero-rate pseudo-measurement
  double bias_sigma_ug = 500.0;     // random-constant bias 1σ per sensor (prior), µg
  double bias_rw_ug_sqrt_s = 10.0;  // bias random walk per sensor, µg/√s
  // Heading from the GNSS track with this side-slip 1σ (degrees; 0: off), for a vehicle that
  // moves along its x axis (FilterConfig::track_heading_sigma_rad).
  double track_heading_sigma_deg = 0.0;
};

/// A fault of the simulated board ([[board.faults]]): each kind is a row of docs/faults.md.
enum class BoardFaultKind : std::uint8_t {
  kCrcError,     // one ADC output frame with a bad CRC
  kMissedEdges,  // `count` data-ready edges lost in a row
  kExtraEdge,    // a spurious data-ready edge without a conversion
  kSilentLine,   // no data-ready edge for `count` periods
  kAdcReset,     // the ADC resets (power-on reset) mid-run
  kSaturated,    // `channel` at full scale for `duration_s`
  kStuck,        // `channel`'s code frozen for `duration_s`
  kCanRefuse,    // the CAN output refuses every frame (queue full) for `duration_s`
  kBusOff,       // the CAN controller is bus-off for `duration_s`
  kReadError,    // `count` ADC reads fail (SPI transfer error), their conversions lost
  kAdcDead,      // every ADC read fails at once for `duration_s` (the driver gave up)
};

struct BoardFault {
  BoardFaultKind kind = BoardFaultKind::kCrcError;
  double at_s = 0.0;        // scenario time of the fault's start
  std::uint32_t count = 1;  // kMissedEdges, kSilentLine (periods), kReadError
  std::size_t channel = 0;  // kSaturated, kStuck: ADC channel 0..5 (sensor 1..6)
  double duration_s = 0.0;  // kSaturated, kStuck, kCanRefuse, kBusOff, kAdcDead
};

/// The name of a kind as [[board.faults]] writes it ("crc_error", "bus_off", ...).
const char* to_string(BoardFaultKind k);

struct Scenario {
  std::string name;         // file stem or [scenario] name
  std::string description;  // one line
  std::string source;       // the file it came from, for messages

  TrajectorySpec trajectory;
  double duration_s = 10.0;
  double rate_hz = 1000.0;
  double rho_m = 0.1;  // Table 1 half-size

  ScenarioGravity gravity = ScenarioGravity::kDown;
  double gravity_mps2 = nav::kStandardGravity;  // kDown / kUp
  double latitude_rad = 0.0;                    // kNormal
  double height_m = 0.0;                        // kNormal

  // Sensor errors (true values).
  nav::Misalignment<double> misalignment{};
  std::array<double, 6> bias_mps2{};
  double noise_mps2 = 0.0;               // white noise per sensor and sample, 1σ
  std::vector<ChannelFailure> failures;  // [[sensors.failures]], docs/simulation.md
  std::uint64_t seed = 1;

  // What the navigation core is told.
  nav::CompensatorKind compensator = nav::CompensatorKind::kPaper;
  MisalignmentSource misalignment_source = MisalignmentSource::kTrue;
  CalibrationSpec calibration;

  bool noise_uniform = false;  // uniform noise of the same σ instead of Gaussian

  // Per-sensor scale factor (V/g) behind the converter; 0 = the QA-1100's nominal 1.33 V/g.
  // Known scale-factor errors of a simulated board to be calibrated ([sensors] scale_v_per_g).
  std::array<double, 6> scale_v_per_g{};

  // The sensor model behind the outputs (SensorArrayModel, sensor_model.hpp): "paper" = unit-gain
  // sensors with only the errors above (the paper's §6.3); "qa1100" = AccelErrors::qa1100_typical
  // per sensor (K2, bias random walk, temperature coefficients, datasheet noise unless noise is
  // given) on top of them. The front end divides by the true scale factor in both cases.
  bool qa1100 = false;
  double temperature_c = 25.0;  // array temperature (reference 25 °C)

  // The converter. true (every scenario but the paper's §6.3): volts → ADC (sample_generator.hpp)
  // → RawSample counts → the pipeline's front end with the real LSB and the QA-1100's nominal
  // scale factor (1.33 V/g for the "paper" model too). false ([sensors] adc = false, the
  // paper-6.3 files only): the paper's §6.3 experiment, whose sensor outputs are m/s² with a
  // noise stated in m/s² and no converter, enter the pipeline after its front end
  // (nav::NavPipeline::process_specific_force), unit-gain sensors.
  bool adc = true;

  // [gnss] (optional): a simulated GNSS receiver on the board's CAN bus (gnss_model.hpp,
  // `gfins-can gnss`). Absent: no GNSS.
  std::optional<GnssSpec> gnss;
  AidingSpec aiding{};

  // [[board.faults]] (optional): faults of the simulated board itself (its ADC, data-ready line
  // and CAN bus), each a row of docs/faults.md, injected by `gfins-fw --sim` at their times
  // (docs/simulation.md, "Board faults"). The host simulator's own runs (gfins-sim) have no board
  // and do not use them.
  std::vector<BoardFault> board_faults;
};

/// Parses TOML text; `source` names it in messages. Errors name the file, the key and the line.
HostResult<Scenario> parse_scenario(std::string_view toml_text, const std::string& source);

/// A scenario argument is a file path when it contains a '/' or ends in ".toml" (`./drive`,
/// `my.toml`), otherwise the name of a built-in scenario (`drive`). A file or folder named like a
/// built-in scenario in the current directory never shadows it (docs/install.md).
bool is_scenario_path(std::string_view arg);

/// Loads a file (is_scenario_path), or a built-in scenario by name from `builtin_dir`
/// (NAME.toml): the one scenario registry of the host is that folder (host_sim/scenarios,
/// installed as share/gfins/scenarios). An unknown name is an error naming the closest built-in
/// names and `gfins-sim list`.
HostResult<Scenario> load_scenario(const std::string& file_or_name, const std::string& builtin_dir);

/// Same, with the built-in folder found relative to the running program
/// (gfins::paths::scenario_dir(): $GFINS_SCENARIO_DIR, PREFIX/share/gfins/scenarios,
/// PREFIX/share/gfins-fw/scenarios). A file path needs no folder; a name without a folder found
/// is an error saying where it looked.
HostResult<Scenario> load_scenario(const std::string& file_or_name);

/// Names of the built-in scenarios in a folder (file stems of *.toml), sorted.
std::vector<std::string> builtin_scenarios(const std::string& builtin_dir);

/// The folder of the built-in scenarios found relative to the running program, or an error
/// saying where it looked and which package holds them.
HostResult<std::string> builtin_scenario_dir();

/// The names among `names` closest to `name` by edit distance (Levenshtein: insertions,
/// deletions, substitutions), best first, at most `max_count`; a name further than
/// max(2, |name| / 3) edits is not suggested, except that a name containing `name` (or contained
/// in it) always is.
std::vector<std::string> closest_names(std::string_view name, const std::vector<std::string>& names,
                                       std::size_t max_count = 3);

/// The trajectory of a scenario; kInvalidArgument for a kind it does not know (parse_scenario
/// rejects those first).
HostResult<std::unique_ptr<Trajectory>> make_trajectory(const TrajectorySpec& spec);

/// The poses of a calibration_poses trajectory in order: Table 2's six, Table 3's six (or one
/// table, trajectory.poses), then extra_poses_g; specific force sensed, body axes, g. Pose k
/// (0-based) is held over [k·(dwell + transition), k·(dwell + transition) + dwell]
/// (make_pose_sequence).
std::vector<Vec3d> calibration_pose_vectors(const TrajectorySpec& spec);

/// A vehicle drive with turns: forward at speed v along north, weaving east
/// y(t) = A (1 − cos Ωt), Ω = 2π/period, heading along the velocity ψ = atan(ẏ/v), with a bank
/// angle φ = atan(v ψ̇ / g) as a coordinated turn.
std::unique_ptr<Trajectory> make_drive(double speed_mps, double amplitude_m, double period_s);

/// The gravity model of a scenario, in the scalar T of its user (the sensor model: double; the
/// navigation core: float or double).
template <typename T = double>
nav::GravityModel<T> gravity_model(const Scenario& s) {
  switch (s.gravity) {
    case ScenarioGravity::kDown:
      return nav::GravityModel<T>::constant(static_cast<T>(s.gravity_mps2));
    case ScenarioGravity::kUp:
      // The paper's §6.3 frame has gravity along −z; the core's model is a signed constant.
      return nav::GravityModel<T>::constant(static_cast<T>(-s.gravity_mps2));
    case ScenarioGravity::kNormal:
      break;
  }
  return nav::GravityModel<T>::normal(s.latitude_rad, s.height_m);
}

// ---- Running a scenario ---------------------------------------------------------------------

/// One sample of one run: truth, estimate and their difference.
struct SampleRecord {
  double t_s = 0;
  TruthState truth;
  Quatd q_nb_est = Quatd::Identity();
  Vec3d w_b_est = Vec3d::Zero();
  Vec3d wdot_b_est = Vec3d::Zero();
  Vec3d a_n_est = Vec3d::Zero();
  Vec3d v_n_est = Vec3d::Zero();
  Vec3d r_n_est = Vec3d::Zero();

  Vec3d wdot_err_b() const { return wdot_b_est - truth.wdot_b; }  // angular accel error
  Vec3d a_err_n() const { return a_n_est - truth.a_n; }           // linear accel error
  Vec3d w_err_b() const { return w_b_est - truth.w_b; }
  Vec3d v_err_n() const { return v_n_est - truth.v_n; }
  Vec3d r_err_n() const { return r_n_est - truth.r_n; }
  /// Small-angle attitude error (rad, body): 2 vec(q_true* ⊗ q_est).
  Vec3d att_err_b() const;
  /// Roll, pitch and heading error (rad, estimate − truth, each wrapped to ±π).
  Vec3d euler_err() const;

  // The aiding filter's 1σ at this sample (roll/pitch/heading, NED velocity, NED position):
  // NaN when no filter runs (an unaided run, or before the filter starts).
  Vec3d euler_sigma_rad = Vec3d::Constant(std::numeric_limits<double>::quiet_NaN());
  Vec3d v_sigma_n = Vec3d::Constant(std::numeric_limits<double>::quiet_NaN());
  Vec3d r_sigma_n = Vec3d::Constant(std::numeric_limits<double>::quiet_NaN());
  // The standstill detector's windows decided so far and its last decision (0 / false when no
  // filter runs): a new decision is a change of the count.
  std::uint32_t detector_windows = 0;
  bool detector_at_rest = false;
};

struct RunSeries {
  std::string label;                  // "uncompensated" or "compensated (paper, true)" ...
  std::vector<SampleRecord> samples;  // the start (t = 0) and every sample that navigated
  NavReport report;                   // the navigation loop's counters (gaps, rejected, ...)
};

/// Summary of a simulated multi-attitude calibration.
struct CalibrationOutcome {
  bool ran = false;
  nav::OrientationErrors<double> estimated{};  // rad
  nav::OrientationErrors<double> std_rad{};    // 1σ from the solver's covariance
  std::array<double, 6> bias_est_g{};
  std::array<double, 6> scale_est_v_per_g{};
  double rms_angle_error_rad = 0;  // estimated − true, over the 12 angles
};

struct ScenarioOutcome {
  RunSeries uncompensated;
  RunSeries compensated;
  CalibrationOutcome calibration;
  nav::Misalignment<double> compensator_misalignment{};
  // The samples the runs navigated, as the ADC delivered them (empty for the paper's §6.3
  // m/s² scenarios, which have no converter): sample 0 is the start (start_at), then every sample
  // offered to the navigation loop. A calibration_poses scenario fills them too (its motion,
  // make_pose_sequence), so that it can be recorded. write_run_recording() stores them.
  std::vector<RawSample> raw;
  double volts_per_count = 0.0;  // of the converter, V at the sensor output
};

/// Called with the fraction done (0..1) now and then; may be empty.
using ProgressFn = std::function<void(double)>;

/// Simulates a multi-attitude calibration of the array of `s` (true misalignment and biases),
/// with its CalibrationSpec and seed. Fails when the solver fails.
HostResult<CalibrationOutcome> simulate_calibration(const Scenario& s);

/// The sensor errors of a scenario as the sample source's SensorArrayModel takes them: its
/// misalignment and temperature, QA-1100 typical errors when asked, its biases and noise; behind
/// a converter (`adc`, every scenario but the paper's §6.3) the QA-1100 scale factor.
ArrayErrors array_errors(const Scenario& s);

/// Scalar of the navigation core a run uses: float is the board's, double the host reference.
enum class NavScalar : std::uint8_t { kFloat, kDouble };

/// Samples of a run of `s`: t = 0 and every whole sample period up to duration_s,
/// floor(duration_s × rate_hz) + 1. A duration that is not a whole number of periods ends at the
/// last whole period before it (1.4 s at 1 Hz: t = 0 and 1 s); describe() says so. The product is
/// floored after a relative 1e-9 allowance, so 0.3 s × 1000 Hz (299.99999999999994 in binary) is
/// 300 periods.
std::uint64_t sample_count(const Scenario& s);

/// The simulated time a run of `s` covers: (sample_count(s) − 1) / rate_hz, s.
double covered_duration_s(const Scenario& s);

/// Longest scenario name accepted (scenario_name_problem).
inline constexpr std::size_t kMaxScenarioNameChars = 64;

/// Empty when `name` may be a scenario's name, else why not. The name becomes a folder name
/// (sim-out/<name>, sim-out/montecarlo-<name>) and a title: it must be one plain file-name
/// component ([A-Za-z0-9._-], 1 to kMaxScenarioNameChars, not starting with '.' or '-'), so a name
/// such as "../../x" or "/tmp/x" can never put output outside the folder the user runs in.
/// parse_scenario refuses other names with this message.
std::string scenario_name_problem(const std::string& name);

/// Memory a run of `s` holds (bytes): per sample the truth, the converter's output and one
/// SampleRecord per run (two with the uncompensated run), times duration × rate + 1 samples.
std::uint64_t run_memory_bytes(const Scenario& s, bool with_uncompensated = true);

/// The largest run accepted (bytes of run_memory_bytes): 2 GiB, half of the 4 GiB of a small
/// development machine or CI runner, so a run never ends in std::bad_alloc after minutes of work.
inline constexpr std::uint64_t kMaxRunMemoryBytes = std::uint64_t{2} << 30;

/// Resident memory of a host tool before any run (program, libraries, stacks): 5.1 MB measured
/// for a streamed `gfins-sim run` (getrusage ru_maxrss), rounded up. Added to the estimates.
inline constexpr std::uint64_t kProcessBaseBytes = std::uint64_t{8} << 20;

/// The memory limit in force: kMaxRunMemoryBytes, or $GFINS_MAX_RUN_MEMORY_BYTES (bytes, a
/// positive integer) when set. The variable is for tests, which show with a small limit that a
/// streamed run (run_scenario_streamed) does not depend on it.
/// Under an address-space limit (`ulimit -v`, read from /proc/self/limits) the limit is at most
/// that minus kAddressSpaceReserveBytes.
std::uint64_t max_run_memory_bytes();
/// Address space a host tool maps beside its data: program and libraries (~30 MB), and per thread
/// a glibc heap arena (up to 64 MiB reserved) and an 8 MiB stack. Measured: VmPeak − VmHWM of
/// `montecarlo -j 2` on 60 s of rest was 130 MB; 256 MiB covers three threads.
inline constexpr std::uint64_t kAddressSpaceReserveBytes = std::uint64_t{256} << 20;

/// Checks before any work: at least two samples (duration × rate ≥ 1 sample period), and the
/// memory estimate within max_run_memory_bytes(). The message names the scenario, the figures and
/// the limit. run_scenario() calls it first.
/// With `in_memory` false (a streamed run, run_scenario_streamed) only the first check applies.
HostStatus check_run_size(const Scenario& s, bool with_uncompensated = true, bool in_memory = true);

/// Runs a navigation scenario twice with the same samples (one SampleGenerator stream, computed
/// once): without compensation and with the scenario's compensator, both through the one
/// navigation loop (NavLoop). For a calibration_poses scenario only `calibration` is filled.
/// Fails when the core rejects the configuration or the converter fails.
/// With `with_uncompensated` false only the compensated run is made (Monte-Carlo).
HostResult<ScenarioOutcome> run_scenario(const Scenario& s, const ProgressFn& progress = {},
                                         bool with_uncompensated = true,
                                         NavScalar scalar = NavScalar::kDouble);

/// Smallest and largest component over all samples (t > 0) of a vector series.
struct Bounds {
  double lo = 0;
  double hi = 0;
};
Bounds linear_accel_bounds(const RunSeries& r);   // a_err_n, m/s²
Bounds angular_accel_bounds(const RunSeries& r);  // wdot_err_b, rad/s²

/// Writes a run as CSV: t, truth, estimate and errors, with units and frames in every column
/// name (docs/simulation.md, "Output files"). `decimate` N keeps every N-th sample (and the
/// last): 1 keeps all.
HostStatus write_series_csv(const RunSeries& r, const std::string& path, std::size_t decimate = 1);

/// Writes the rows of write_series_csv one at a time, as a run produces them: the same header,
/// the same row format and the same decimation (every N-th row and the last), so a streamed run
/// and a run kept in memory give the same bytes. Memory use is one pending row.
class SeriesCsvWriter {
 public:
  static HostResult<SeriesCsvWriter> open(const std::string& path, std::size_t decimate = 1);
  SeriesCsvWriter(SeriesCsvWriter&& other) noexcept;
  SeriesCsvWriter& operator=(SeriesCsvWriter&& other) noexcept;
  SeriesCsvWriter(const SeriesCsvWriter&) = delete;
  SeriesCsvWriter& operator=(const SeriesCsvWriter&) = delete;
  ~SeriesCsvWriter();

  /// Row `rows_seen()` of the series: written now when it falls on the decimation, else kept
  /// until the next one (it is written by close() if it is the last). Fails on a write error.
  HostStatus add(const SampleRecord& x);
  /// Writes the pending last row, closes the file; reports any write error.
  HostStatus close();
  std::uint64_t rows_seen() const { return seen_; }
  std::uint64_t rows_written() const { return written_; }

 private:
  SeriesCsvWriter(std::FILE* f, std::string path, std::size_t every);
  void write_row(const SampleRecord& x);

  std::FILE* file_ = nullptr;
  std::string path_;
  std::size_t every_ = 1;
  std::uint64_t seen_ = 0;
  std::uint64_t written_ = 0;
  std::optional<SampleRecord> pending_;
};

/// What the summary table of a run needs, accumulated sample by sample (bounds over t > 0, the
/// final errors, the loop's report), so that a streamed run needs no series in memory.
struct SeriesStats {
  std::string label;
  std::uint64_t samples = 0;      // SampleRecords seen (the start included)
  Bounds linear{1e300, -1e300};   // a_err_n, m/s² (linear_accel_bounds)
  Bounds angular{1e300, -1e300};  // wdot_err_b, rad/s² (angular_accel_bounds)
  double att_max_deg = 0, vel_max_mps = 0, pos_max_m = 0;
  double att_final_deg = 0, vel_final_mps = 0, pos_final_m = 0;
  double t_last_s = 0;
  NavReport report;
  void add(const SampleRecord& x);
};
/// The statistics of a series kept in memory (the same numbers as the streamed ones).
SeriesStats series_stats(const RunSeries& r);

/// Where a streamed run writes while it navigates, and how it can be stopped.
class AccuracyTracker;  // accuracy.hpp

class ConsistencyRecorder;

struct StreamTargets {
  bool uncompensated_run = true;        // false: only the compensated run navigates
  AccuracyTracker* accuracy = nullptr;  // fed every record of the compensated run (if not null)
  /// Fed the compensated run's NEES once a second and its GNSS updates' NIS (consistency.hpp).
  ConsistencyRecorder* consistency = nullptr;
  /// Added to each sensor's bias and not told to the compensator: the bias the filter is to
  /// find (a consistency run draws it from the filter's prior), m/s².
  std::array<double, 6> unknown_bias_mps2{};
  /// The GNSS fixes are offered with the receiver's σ times this (below 1: a receiver that
  /// states a better accuracy than it has; the noise stays [gnss]'s).
  double gnss_stated_sigma_scale = 1.0;
  /// The compensated run starts from the truth plus this error (estimate − truth, the filter's
  /// convention: φ in the n frame, then δr, δv, δω_b): a consistency run draws it from the
  /// filter's P0, which the filter claims at its start.
  struct StartError {
    Vec3d phi_n = Vec3d::Zero(), dr_n = Vec3d::Zero(), dv_n = Vec3d::Zero(), dw_b = Vec3d::Zero();
  } start_error;
  std::string uncompensated_csv;  // empty: not written
  std::string compensated_csv;    // empty: not written
  std::size_t decimate = 1;       // of both CSV files (write_series_csv)
  std::string recording;          // empty: none; else the .gfr of every sample offered
  /// Polled before each sample: when it reads non-zero the run stops there, closes its files
  /// (the recording's last block and record_count written: a valid file) and reports it.
  /// Set by a signal handler (SIGINT/SIGTERM), hence volatile sig_atomic_t.
  const volatile std::sig_atomic_t* stop = nullptr;
};

struct StreamedOutcome {
  SeriesStats uncompensated;
  SeriesStats compensated;
  CalibrationOutcome calibration;
  std::uint64_t samples_planned = 0;  // duration × rate + 1
  std::uint64_t samples_done = 0;     // offered to the navigation (the start included)
  std::uint64_t recorded = 0;         // records in the recording
  bool interrupted = false;           // *stop was set: the files hold samples_done samples
  double t_stop_s = 0;                // time of the last sample done
};

/// run_scenario() without keeping the series: the samples are made one at a time, both runs
/// (uncompensated and compensated) navigate each in turn (lockstep; the pipelines are separate,
/// so each gives what it gives alone), and every row goes to the CSV files and the recording as
/// it is produced. Memory does not grow with the duration. For a calibration_poses scenario only
/// the recording (if asked) and `calibration` are produced. The files are byte-identical to
/// write_series_csv / write_run_recording of run_scenario's outcome.
HostResult<StreamedOutcome> run_scenario_streamed(const Scenario& s, const StreamTargets& targets,
                                                  const ProgressFn& progress = {},
                                                  NavScalar scalar = NavScalar::kDouble);

/// Bytes a streamed run of `s` is expected to write: CSV rows (kCsvRowBytesEstimate each, both
/// files, after decimation) plus the recording when asked.
std::uint64_t run_disk_bytes(const Scenario& s, std::size_t decimate, bool with_recording);
/// Typical bytes of one CSV row: measured 615 on `drive` (94 columns of %.9g), rounded up.
inline constexpr std::uint64_t kCsvRowBytesEstimate = 700;

/// The recording header of a run of `s` (rate, the converter's LSB, the nominal Table 1
/// geometry at the scenario's ρ) and the file: exactly the samples the run navigated
/// (ScenarioOutcome::raw). kFailedPrecondition for a run without a converter (§6.3, m/s²).
HostStatus write_run_recording(const Scenario& s, const ScenarioOutcome& o,
                               const std::string& path);

}  // namespace gfins::sim
