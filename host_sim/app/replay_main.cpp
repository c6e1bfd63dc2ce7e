// gfins-replay: a raw-sample recording (.gfr, docs/recording-format.md) through the navigation
// core, or printed (docs/replay.md).
//
//   gfins-replay FILE.gfr [--cal CAL.toml] [-o DIR]   navigate: the one host navigation loop
//                                                     (NavLoop, float32 core by default), CSV,
//                                                     summary with the gap and hash report, PNG
//   gfins-replay dump FILE.gfr                        header and samples as CSV on stdout
//   gfins-replay dump FILE.gfr --frames               the CAN frames recorded, as a candump log
//
// The recording is what a board (or `gfins-sim run --record`) delivered: counts, sequence
// counter, data-ready time and flags. Navigation starts as on the board: static alignment over
// the first --align-s seconds (roll and pitch from the mean specific force, heading given), then
// strapdown navigation, driven by sample index (never wall-clock), bit-exact run to run.
#include <CLI/CLI.hpp>
#include <array>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <exception>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "common.hpp"
#include "finite_range.hpp"
#include "gfins/calib_file/calibration_data.hpp"
#include "gfins/calib_file/calibration_file.hpp"
#include "gfins/drivers/lnx/candump.hpp"
#include "gfins/host_sim/recording.hpp"
#include "gfins/host_sim/replay.hpp"
#include "gfins/host_sim/sensor_model.hpp"
#include "gfins/nav_core/pipeline.hpp"
#include "gfins/version/version.hpp"
#include "run_options.hpp"

namespace {

namespace app = gfins::sim::app;
namespace sim = gfins::sim;
namespace nav = gfins::nav;
using gfins::ErrorCode;
using gfins::RawSample;

std::string printable(const std::string& text);

/// Every message names its input; a file name may hold control characters (ESC, a newline): they
/// reach the terminal escaped.
int fail(const std::string& message, int exit_code) {
  std::fprintf(stderr, "gfins-replay: %s\n", printable(message).c_str());
  return exit_code;
}

struct ReplayOptions {
  std::string recording;
  std::string cal;
  app::OutputOptions out;
  bool still_check = true;  // !--no-still-check
  double align_s = 1.0;
  double heading_deg = 0.0;
  double gravity_mps2 = nav::kStandardGravity;
};

/// Largest standard deviation of a channel, in g, over a still alignment window: the QA-1100's
/// 70 µg rms noise (datasheet, 10-500 Hz) and a lab bench's vibration stay far below it, while
/// an array that turns (spin.gfr at 3 rad/s: 0.15-0.6 g) or is carried is far above it. The
/// calibration's static detector decides stillness the same way (channel standard deviations).
constexpr double kStillStdG = 5e-3;

/// `text` with control characters shown as \xNN, for a one-line '#' header or message (a file
/// name may contain a newline).
std::string printable(const std::string& text) {
  std::string out;
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 || u == 0x7f) {
      char esc[8];
      std::snprintf(esc, sizeof esc, "\\x%02x", static_cast<unsigned>(u));
      out += esc;
    } else {
      out += c;
    }
  }
  return out;
}

// The usage lines of all three forms: dump and means are parsed before CLI11 sees the command
// line (they are not CLI11 subcommands), so its own usage line would name the first form only.
class ReplayUsage final : public CLI::Formatter {
 public:
  std::string make_usage(const CLI::App* app, std::string name) const override {
    return CLI::Formatter::make_usage(app, std::move(name)) +
           "       gfins-replay dump RECORDING.gfr [--frames]\n"
           "       gfins-replay means RECORDING.gfr --mounting K --up X Y Z --rate-rad-s W "
           "[--header]\n";
  }
};

// ---- dump -------------------------------------------------------------------------------------

// Each sample of a block as a CSV row.
void print_samples(const std::vector<RawSample>& block, const sim::RecordingHeader& h) {
  for (const RawSample& s : block) {
    std::printf("%" PRIu32 ",%" PRId64, s.seq, s.t_ns);
    for (const auto c : s.counts) std::printf(",%" PRId32, c);
    for (std::size_t j = 0; j < 6; ++j) {
      std::printf(",%.9g", static_cast<double>(s.counts[j]) * h.volts_per_count[j]);
    }
    std::printf(",%" PRIu32 "\n", s.flags);
  }
}

// `dump --frames`: a block's frame records (version 2) as candump lines, "(sec.usec) rec ID#DATA",
// stamped with the time of the cycle that handled each (gfins-can decode reads them).
bool print_frames(const std::vector<sim::RecordedFrame>& frames) {
  std::array<char, 64> line{};
  for (const sim::RecordedFrame& r : frames) {
    const gfins::hal::CanFrame f = sim::can_frame_of(r.frame);
    // Floor division: a negative time still gives micros in 0..999999.
    std::int64_t sec = r.frame.t_ns / 1000000000;
    std::int64_t rem = r.frame.t_ns % 1000000000;
    if (rem < 0) rem += 1000000000, --sec;
    const std::size_t n = gfins::drivers::lnx::format_candump_line(
        line, sec, static_cast<std::uint32_t>(rem / 1000), "rec", f);
    if (n == 0) return false;
    std::printf("%.*s\n", static_cast<int>(n), line.data());
  }
  return true;
}

int dump(const std::string& path, bool frames) {
  auto reader = sim::RecordingReader::open(path);
  if (!reader.is_ok()) return fail(reader.error().message, app::kExitBadInput);
  const sim::RecordingHeader& h = reader.value().header();
  if (!frames) {
    std::printf("# gfins raw-sample recording %s (docs/recording-format.md)\n",
                printable(path).c_str());
    std::printf("# version %u, %u channels, %u records per block, record_count %s\n",
                static_cast<unsigned>(h.version), static_cast<unsigned>(h.channel_count),
                static_cast<unsigned>(h.records_per_block),
                h.record_count == sim::kRecordCountUnknown
                    ? "unknown (writer not closed)"
                    : std::to_string(h.record_count).c_str());
    std::printf("# sample_rate_hz %.9g\n", h.sample_rate_hz);
    for (std::size_t j = 0; j < 6; ++j) {
      const auto& r = h.geometry.rho_b[j];
      const auto& t = h.geometry.theta_b[j];
      std::printf(
          "# sensor a%zu: volts_per_count %.9g V, rho_b [%.6g %.6g %.6g] m, theta_b [%.6g %.6g "
          "%.6g] (body FRD)\n",
          j + 1, h.volts_per_count[j], r.x(), r.y(), r.z(), t.x(), t.y(), t.z());
    }
    std::printf(
        "# columns: seq (ADC counter), t_ns (data-ready time, ns), count_1..count_6 (24-bit ADC "
        "codes), v_1_V..v_6_V (volts at the sensor output = count x volts_per_count), flags (bit 0 "
        "CRC error, 1 saturated, 2 late read, 3 synthetic)\n");
    std::printf(
        "seq,t_ns,count_1,count_2,count_3,count_4,count_5,count_6,v_1_V,v_2_V,v_3_V,v_4_V,v_5_V,"
        "v_6_V,flags\n");
  }
  std::vector<RawSample> block;
  for (;;) {
    auto more = reader.value().next_block(block);
    if (!more.is_ok()) {
      (void)std::fflush(stdout);
      return fail(more.error().message, app::kExitBadInput);
    }
    if (!more.value()) break;
    if (!frames) {
      print_samples(block, h);
    } else if (!print_frames(reader.value().frames())) {
      return fail("frame record not printable as a candump line", app::kExitBadInput);
    }
  }
  if (std::fflush(stdout) != 0 || std::ferror(stdout) != 0) {
    return fail("error writing the dump to stdout", app::kExitError);
  }
  return app::kExitOk;
}

// ---- means (rate-table runs for gfins-calibrate --location-runs) -----------------------------

struct MeansOptions {
  std::string recording;
  int mounting = 0;
  std::vector<double> up_b;
  double rate_rad_s = 0.0;
  bool header = false;
};

/// One row of gfins-calibrate's --location-runs input (docs/calibration.md, §5): the mean and
/// per-sample standard deviation of each sensor's output (V) over the whole revolutions of a
/// rate-table recording, with the mounting, the body axis pointing up and the table rate.
int means(const MeansOptions& o) {
  const double up_norm =
      std::sqrt(o.up_b[0] * o.up_b[0] + o.up_b[1] * o.up_b[1] + o.up_b[2] * o.up_b[2]);
  if (!(up_norm > 0.0) || !std::isfinite(up_norm)) {
    return fail("--up: the body axis pointing up must be a non-zero vector", app::kExitBadInput);
  }
  auto rec = sim::read_recording(o.recording);
  if (!rec.is_ok()) return fail(rec.error().message, app::kExitBadInput);
  const sim::RecordingHeader& h = rec.value().header;
  const auto& smp = rec.value().samples;
  // Whole revolutions: a real table wobbles once per turn, and whole turns average it out.
  const double per_rev = 2.0 * M_PI / o.rate_rad_s * h.sample_rate_hz;  // samples
  const double revs = std::floor(static_cast<double>(smp.size()) / per_rev);
  if (revs < 1.0) {
    char buf[256];
    std::snprintf(buf, sizeof buf,
                  "%s: %zu samples at %g Hz are less than one revolution at %g rad/s (%.0f "
                  "samples)",
                  o.recording.c_str(), smp.size(), h.sample_rate_hz, o.rate_rad_s, per_rev);
    return fail(buf, app::kExitBadInput);
  }
  const auto n = static_cast<std::size_t>(std::llround(revs * per_rev));
  std::array<double, 6> sum{};
  std::array<double, 6> sum2{};
  std::size_t flagged = 0;
  for (std::size_t k = 0; k < n && k < smp.size(); ++k) {
    if ((smp[k].flags & (gfins::sample_flags::kCrcError | gfins::sample_flags::kSaturated)) != 0) {
      ++flagged;
      continue;
    }
    for (std::size_t j = 0; j < 6; ++j) {
      const double v = static_cast<double>(smp[k].counts[j]) * h.volts_per_count[j];
      sum[j] += v;
      sum2[j] += v * v;
    }
  }
  if (flagged > 0) {
    return fail(o.recording + ": " + std::to_string(flagged) +
                    " samples flagged with a CRC error or saturation inside the revolutions: "
                    "their means are not the sensors'",
                app::kExitBadInput);
  }
  const auto count = static_cast<double>(std::min(n, smp.size()));
  if (o.header) {
    std::printf(
        "mounting,axis_x,axis_y,axis_z,rate_rad_s,mean_v1,mean_v2,mean_v3,mean_v4,mean_v5,"
        "mean_v6,std_v1,std_v2,std_v3,std_v4,std_v5,std_v6,count\n");
  }
  std::printf("%d,%.9g,%.9g,%.9g,%.9g", o.mounting, o.up_b[0] / up_norm, o.up_b[1] / up_norm,
              o.up_b[2] / up_norm, o.rate_rad_s);
  for (std::size_t j = 0; j < 6; ++j) std::printf(",%.12g", sum[j] / count);
  for (std::size_t j = 0; j < 6; ++j) {
    const double m = sum[j] / count;
    // Sample standard deviation; a noise-free recording can round to a tiny negative variance.
    const double var = std::max(0.0, (sum2[j] - count * m * m) / (count - 1.0));
    std::printf(",%.6g", std::sqrt(var));
  }
  std::printf(",%.0f\n", count);
  return std::fflush(stdout) == 0 ? app::kExitOk : app::kExitError;
}

// ---- navigate ---------------------------------------------------------------------------------

/// The pipeline configuration: the recording's LSB and geometry, the QA-1100's nominal scale
/// factor, no compensation; a calibration file replaces the front end, geometry, misalignment
/// and compensator (as on the board, calib_file::apply_to).
gfins::sim::HostResult<nav::PipelineConfig<double>> config_of(const ReplayOptions& o,
                                                              const sim::RecordingHeader& h,
                                                              std::string& what) {
  nav::PipelineConfig<double> c;
  c.nominal = h.geometry;
  const double sf = sim::AccelErrors::qa1100_typical().scale_v_per_g;
  for (std::size_t j = 0; j < 6; ++j) {
    c.front_end.volts_per_count[j] = h.volts_per_count[j];
    c.front_end.scale_v_per_g[j] = sf;
    c.front_end.bias_g[j] = 0.0;
  }
  c.compensator = nav::CompensatorKind::kNone;
  what = "no calibration: nominal QA-1100 scale factor, no bias, no compensation";
  if (!o.cal.empty()) {
    const auto cal = gfins::calib_file::load_calibration_file(o.cal);
    if (!cal.is_ok()) return sim::HostError{ErrorCode::kInvalidArgument, cal.status().message()};
    const auto& d = cal.value();
    if (auto why = gfins::calib_file::converter_mismatch(d, h.volts_per_count, "the recording")) {
      return sim::HostError{ErrorCode::kInvalidArgument, o.cal + ": " + *why};
    }
    gfins::calib_file::apply_to(d, c);
    what = "calibration " + printable(o.cal) + " (device " + d.device_id + ", compensator " +
           nav::to_string(d.compensator) + ")";
  }
  c.gravity = nav::GravityModel<double>::constant(o.gravity_mps2);
  c.sample_rate_hz = h.sample_rate_hz;
  c.alignment_samples =
      static_cast<std::uint32_t>(std::max(1.0, std::round(o.align_s * h.sample_rate_hz)));
  c.heading_rad = o.heading_deg * M_PI / 180.0;
  return c;
}

template <typename T>
nav::PipelineConfig<T> cast_config(const nav::PipelineConfig<double>& c) {
  nav::PipelineConfig<T> o;
  o.nominal = c.nominal.template cast<T>();
  o.front_end = c.front_end.template cast<T>();
  for (std::size_t i = 0; i < 6; ++i) {
    o.misalignment.orientation.beta[i] = static_cast<T>(c.misalignment.orientation.beta[i]);
    o.misalignment.orientation.alpha[i] = static_cast<T>(c.misalignment.orientation.alpha[i]);
    o.misalignment.drho_b[i] = c.misalignment.drho_b[i].template cast<T>();
  }
  o.compensator = c.compensator;
  o.gravity = nav::GravityModel<T>::constant(static_cast<T>(c.gravity.magnitude_at_origin()));
  o.max_condition = static_cast<T>(c.max_condition);
  o.sample_rate_hz = static_cast<T>(c.sample_rate_hz);
  o.alignment_samples = c.alignment_samples;
  o.heading_rad = static_cast<T>(c.heading_rad);
  o.r0_n = c.r0_n.template cast<T>();
  return o;
}

/// CSV columns: the estimate columns of `gfins-sim run` (same names and units) and the sample's
/// counter and status bits.
void write_header(std::FILE* f) {
  std::string h = "t_s,seq,status";
  for (const char* c : {"w", "x", "y", "z"}) h += std::string(",est_q_nb_") + c;
  const auto v = [&h](const char* name, const char* unit) {
    for (const char* c : {"x", "y", "z"}) h += std::string(",") + name + "_" + c + "_" + unit;
  };
  v("est_w_b", "rps");
  v("est_wdot_b", "rps2");
  v("est_f_b", "mps2");
  v("est_a_n", "mps2");
  v("est_v_n", "mps");
  v("est_r_n", "m");
  std::fprintf(f, "%s\n", h.c_str());
}

template <typename T>
void write_row(std::FILE* f, double t_s, const nav::NavState<T>& s) {
  std::fprintf(f, "%.6f,%" PRIu32 ",%" PRIu32 ",%.9g,%.9g,%.9g,%.9g", t_s, s.seq, s.status,
               static_cast<double>(s.q_nb.w()), static_cast<double>(s.q_nb.x()),
               static_cast<double>(s.q_nb.y()), static_cast<double>(s.q_nb.z()));
  for (const auto* v : {&s.w_b, &s.wdot_b, &s.f_b, &s.a_n, &s.v_n, &s.r_n}) {
    std::fprintf(f, ",%.9g,%.9g,%.9g", static_cast<double>(v->x()), static_cast<double>(v->y()),
                 static_cast<double>(v->z()));
  }
  std::fprintf(f, "\n");
}

void print_report(std::FILE* f, const sim::NavReport& r, double rate_hz) {
  std::fprintf(f,
               "samples offered %" PRIu64 ", navigating %" PRIu64 " (alignment: the first %" PRIu64
               "), rejected %" PRIu64 " (CRC error %" PRIu64 ", saturated %" PRIu64 ")\n",
               r.samples, r.navigating, r.samples - r.navigating - r.rejected, r.rejected,
               r.invalid, r.flagged_saturated);
  std::fprintf(f,
               "gaps in the sample counter: %zu, samples missing: %" PRIu64
               ", out of order (repeated or went back, not integrated): %" PRIu64 "\n",
               r.gaps.size(), r.missed_samples, r.out_of_order);
  constexpr std::size_t kListed = 20;
  for (std::size_t i = 0; i < r.gaps.size() && i < kListed; ++i) {
    const sim::NavGap& g = r.gaps[i];
    std::fprintf(f,
                 "  gap at sample %" PRIu64 " (t = %.6f s): expected seq %" PRIu32 ", saw %" PRIu32
                 ", %" PRIu32 " missing\n",
                 g.index, static_cast<double>(g.index) / rate_hz, g.expected_seq, g.seq, g.missing);
  }
  if (r.gaps.size() > kListed) std::fprintf(f, "  ... %zu more\n", r.gaps.size() - kListed);
  if (r.frames_not_applied > 0) {
    std::fprintf(f,
                 "CAN frames in the recording (what the recording board received: aiding inputs, "
                 "commands): %" PRIu64
                 ", not applied by gfins-replay (unaided navigation); gfins-fw --replay applies "
                 "them in their cycles\n",
                 r.frames_not_applied);
  }
  std::fprintf(f, "output hash (FNV-1a-64 of every navigation state): %016" PRIx64 "\n",
               r.output_hash);
}

template <typename T>
int navigate(const ReplayOptions& o, const sim::RecordingHeader& h,
             const nav::PipelineConfig<double>& cfg, const std::string& cal_text,
             const std::string& out_dir) {
  auto pipeline = std::make_unique<nav::NavPipeline<T>>();
  if (const auto st = pipeline->configure(cast_config<T>(cfg)); !st.is_ok()) {
    return fail(std::string("the navigation core rejected the configuration: ") + st.message(),
                app::kExitBadInput);
  }
  const std::string csv_path = out_dir + "/navigation.csv";
  std::FILE* csv = std::fopen(csv_path.c_str(), "w");
  if (csv == nullptr) return fail("cannot write " + csv_path, app::kExitError);
  write_header(csv);
  const std::size_t every = std::max<std::size_t>(o.out.decimate, 1);
  bool have_t0 = false;
  std::int64_t t0_ns = 0;
  std::uint64_t written = 0;
  nav::NavState<T> last{};
  std::uint64_t since = every;  // write the first state
  // Progress (a terminal: percentage; a log: a line every few seconds), from the record count of
  // a closed recording.
  const sim::ProgressFn progress =
      h.record_count != sim::kRecordCountUnknown
          ? app::log_progress("replay", static_cast<double>(h.record_count), "samples")
          : sim::ProgressFn{};
  const std::uint64_t step = std::max<std::uint64_t>(h.record_count / 100, 1);
  const app::StopSignals handlers;  // Ctrl-C/SIGTERM: stop between two samples, files complete
  const auto result = sim::replay_recording<T>(
      o.recording, *pipeline,
      [&](std::uint64_t index, const nav::NavState<T>& s) {
        if (progress && (index % step == 0 || index + 1 == h.record_count)) {
          progress(static_cast<double>(index + 1) / static_cast<double>(h.record_count));
        }
        if (!have_t0) {
          have_t0 = true;
          t0_ns = s.t_ns;
        }
        last = s;
        if (since++ % every != 0) return;
        write_row(csv, static_cast<double>(s.t_ns - t0_ns) * 1e-9, s);
        ++written;
      },
      &app::g_stop_signal);
  const int stop_signal = app::g_stop_signal;
  // The last state always ends the file (decimated or not), so the CSV reaches the end.
  if (result.is_ok() && have_t0 && (since - 1) % every != 0) {
    write_row(csv, static_cast<double>(last.t_ns - t0_ns) * 1e-9, last);
    ++written;
  }
  if (auto c = app::close_output(csv, csv_path); !c.is_ok()) {
    return fail(c.error().message, app::kExitError);
  }
  if (!result.is_ok()) {
    return fail(result.error().message + " (navigation.csv holds the samples before it)",
                app::kExitBadInput);
  }
  const sim::NavReport& r = result.value();
  const std::string summary_path = out_dir + "/summary.txt";
  std::FILE* summary = std::fopen(summary_path.c_str(), "w");
  if (summary == nullptr) return fail("cannot write " + summary_path, app::kExitError);
  for (std::FILE* f : {stdout, summary}) {
    std::fprintf(f, "gfins-replay %s: %g Hz, %s, %s\n", printable(o.recording).c_str(),
                 h.sample_rate_hz, cal_text.c_str(),
                 app::scalar_text(std::is_same_v<T, float> ? sim::NavScalar::kFloat
                                                           : sim::NavScalar::kDouble));
    print_report(f, r, h.sample_rate_hz);
    if (stop_signal != 0) {
      std::fprintf(f,
                   "interrupted (signal %d) after %" PRIu64
                   " samples: navigation.csv holds the states up to there\n",
                   stop_signal, r.samples);
    }
    if (r.navigating > 0) {
      const auto& v = last.v_n;
      const auto& p = last.r_n;
      std::fprintf(f, "final state (t = %.3f s after alignment): |v_n| %.6g m/s, |r_n| %.6g m\n",
                   static_cast<double>(last.t_ns - t0_ns) * 1e-9, static_cast<double>(v.norm()),
                   static_cast<double>(p.norm()));
    }
  }
  if (auto c = app::close_output(summary, summary_path); !c.is_ok()) {
    return fail(c.error().message, app::kExitError);
  }
  std::printf("written: %s (%" PRIu64 " states%s), %s\n", csv_path.c_str(), written,
              every > 1 ? (", every " + std::to_string(every) + "th state").c_str() : "",
              summary_path.c_str());
  if (stop_signal != 0) {
    std::fprintf(stderr, "gfins-replay: interrupted after %" PRIu64 " samples (%s)\n", r.samples,
                 summary_path.c_str());
    return app::kExitInterrupted;
  }
  // Only a recording whose writer was not closed (record count unknown) gets here: a closed
  // one too short for the alignment is refused before any work (run_navigate).
  if (r.navigating == 0) {
    return fail("no navigation state: the recording (" + std::to_string(r.samples) +
                    " samples) ends within the alignment of " +
                    std::to_string(cfg.alignment_samples) + " samples (--align-s)",
                app::kExitBadInput);
  }
  if (!o.out.plot) return app::kExitOk;
  std::string title = std::filesystem::path(o.recording).filename().string() + ", " +
                      (o.cal.empty() ? std::string("no calibration")
                                     : std::filesystem::path(o.cal).filename().string()) +
                      ", compensator " + nav::to_string(cfg.compensator) + ", " +
                      (std::is_same_v<T, float> ? "float32" : "double") + " core";
  if (const int rc = app::plot_step("gfins-replay", "plot_sim.py", {"replay", out_dir, title});
      rc != app::kExitOk) {
    return rc;
  }
  std::printf("figures: %s/replay.png\n", out_dir.c_str());
  return app::kExitOk;
}

/// Static alignment takes roll and pitch from the mean specific force of its window, which is
/// gravity only when the array is still. The window's samples are read first and each channel's
/// standard deviation, in g through the front end's LSB and scale factor, must stay within
/// kStillStdG; otherwise the run is refused with the figures (--no-still-check overrides).
gfins::sim::HostStatus check_still(const std::string& path, const nav::PipelineConfig<double>& c) {
  auto reader = sim::RecordingReader::open(path);
  if (!reader.is_ok()) return reader.error();
  const std::uint64_t n = c.alignment_samples;
  std::array<double, 6> mean{};
  std::array<double, 6> m2{};
  std::uint64_t k = 0;
  std::vector<RawSample> block;
  while (k < n) {
    auto more = reader.value().next_block(block);
    if (!more.is_ok()) return more.error();
    if (!more.value()) break;
    for (const RawSample& x : block) {
      if (k >= n) break;
      if ((x.flags & (gfins::sample_flags::kCrcError | gfins::sample_flags::kSaturated)) != 0) {
        continue;  // rejected by the pipeline too
      }
      ++k;
      for (std::size_t j = 0; j < 6; ++j) {  // Welford's running mean and sum of squares
        const double g = static_cast<double>(x.counts[j]) * c.front_end.volts_per_count[j] /
                         c.front_end.scale_v_per_g[j];
        const double d = g - mean[j];
        mean[j] += d / static_cast<double>(k);
        m2[j] += d * (g - mean[j]);
      }
    }
  }
  if (k < 2) return gfins::sim::Done{};  // too short to tell; the length checks report it
  std::size_t worst = 0;
  std::array<double, 6> sd{};
  for (std::size_t j = 0; j < 6; ++j) {
    sd[j] = std::sqrt(m2[j] / static_cast<double>(k - 1));
    if (sd[j] > sd[worst]) worst = j;
  }
  if (!(sd[worst] > kStillStdG)) return gfins::sim::Done{};
  char buf[640];
  std::snprintf(buf, sizeof buf,
                "%s: the array is not still during the alignment (the first %llu samples, %.6g "
                "s): standard deviation of the sensor outputs a1..a6 = %.3g %.3g %.3g %.3g %.3g "
                "%.3g g, largest a%zu, where a still array stays below %.3g g. Alignment takes "
                "roll and pitch from the mean specific force, which is gravity only at rest: "
                "start the recording at rest, shorten --align-s to the still part, or pass "
                "--no-still-check",
                printable(path).c_str(), static_cast<unsigned long long>(k),
                static_cast<double>(n) / c.sample_rate_hz, sd[0], sd[1], sd[2], sd[3], sd[4], sd[5],
                worst + 1, kStillStdG);
  return gfins::sim::HostError{ErrorCode::kInvalidArgument, buf};
}

int run_navigate(ReplayOptions& o) {
  if (!(o.align_s > 0.0) || !std::isfinite(o.align_s)) {
    return fail("--align-s " + std::to_string(o.align_s) + ": must be a positive number of seconds",
                app::kExitBadInput);
  }
  auto reader = sim::RecordingReader::open(o.recording);
  if (!reader.is_ok()) return fail(reader.error().message, app::kExitBadInput);
  const sim::RecordingHeader h = reader.value().header();
  // (record_count of an unclosed recording is kRecordCountUnknown, the largest value.)
  if (h.record_count < 2) {
    return fail(o.recording + ": " + std::to_string(h.record_count) +
                    " samples: navigation needs at least 2",
                app::kExitBadInput);
  }
  const auto scalar = app::nav_scalar(o.out.scalar);
  if (!scalar.is_ok()) return fail(scalar.error().message, app::kExitBadInput);
  const std::string stem = std::filesystem::path(o.recording).stem().string();
  const auto dir = app::output_dir(o.out, "replay-out/" + stem);
  if (!dir.is_ok()) return fail(dir.error().message, app::kExitBadInput);
  std::string cal_text;
  const auto cfg = config_of(o, h, cal_text);
  if (!cfg.is_ok()) return fail(cfg.error().message, app::kExitBadInput);
  if (h.record_count != sim::kRecordCountUnknown &&
      cfg.value().alignment_samples >= h.record_count) {
    char buf[320];
    std::snprintf(buf, sizeof buf,
                  "--align-s %g: the alignment takes %u samples, the recording has %llu (%.6g s at "
                  "%g Hz): nothing would be left to navigate; give --align-s below %.6g s",
                  o.align_s, static_cast<unsigned>(cfg.value().alignment_samples),
                  static_cast<unsigned long long>(h.record_count),
                  static_cast<double>(h.record_count) / h.sample_rate_hz, h.sample_rate_hz,
                  static_cast<double>(h.record_count - 1) / h.sample_rate_hz);
    return fail(buf, app::kExitBadInput);
  }
  if (o.still_check) {
    if (auto st = check_still(o.recording, cfg.value()); !st.is_ok()) {
      return fail(st.error().message, app::kExitBadInput);
    }
  }
  if (auto d = app::make_dir(dir.value(), "gfins-replay", {"summary.txt", "navigation.csv"});
      !d.is_ok()) {
    return fail(d.error().message, app::kExitError);
  }
  return scalar.value() == sim::NavScalar::kFloat
             ? navigate<float>(o, h, cfg.value(), cal_text, dir.value())
             : navigate<double>(o, h, cfg.value(), cal_text, dir.value());
}

int replay_main(int argc, char** argv) {
  const char* footer =
      "Exit codes: 0 ok; 1 an output could not be written; 2 command line, recording or "
      "calibration file rejected (also: --align-s longer than the recording, an array that is "
      "not still during the alignment); 3 CSV written but plotting failed (PNG asked for); 130 "
      "stopped by Ctrl-C/SIGINT or SIGTERM, navigation.csv and summary.txt complete up to the "
      "sample in summary.txt (while plotting: everything but the PNG).";
  // dump and means write to stdout only: no folder, no plot.
  const char* stdout_footer =
      "Exit codes: 0 ok; 1 stdout could not be written; 2 command line or recording rejected.";
  if (argc >= 2 && std::string(argv[1]) == "dump") {
    CLI::App cli{"gfins-replay dump: a recording's header and samples as CSV on stdout",
                 "gfins-replay dump"};
    cli.footer(stdout_footer);
    std::string path;
    bool frames = false;
    cli.add_option("recording", path, "raw-sample recording (.gfr)")->required();
    cli.add_flag("--frames", frames,
                 "print the CAN frames the recording board received (version 2) as a candump "
                 "log instead of the samples");
    try {
      cli.parse(argc - 1, argv + 1);
    } catch (const CLI::ParseError& e) {
      return cli.exit(e) == 0 ? app::kExitOk : app::kExitBadInput;
    }
    return dump(path, frames);
  }
  if (argc >= 2 && std::string(argv[1]) == "means") {
    CLI::App cli{
        "gfins-replay means: one row of gfins-calibrate --location-runs (docs/calibration.md "
        "§5) from a rate-table recording: per-sensor mean and standard deviation (V) over its "
        "whole revolutions",
        "gfins-replay means"};
    cli.footer(stdout_footer);
    MeansOptions m;
    cli.add_option("recording", m.recording, "rate-table recording (.gfr)")->required();
    cli.add_option("--mounting", m.mounting, "fixture pose of the run (0..7)")
        ->check(CLI::Range(0, 7))
        ->required();
    cli.add_option("--up", m.up_b, "body axis pointing up (x y z)")->expected(3)->required();
    cli.add_option("--rate-rad-s", m.rate_rad_s, "table rate, rad/s")
        ->check(app::finite_range(0.1, 100.0))
        ->required();
    cli.add_flag("--header", m.header, "print the CSV header line first");
    try {
      cli.parse(argc - 1, argv + 1);
    } catch (const CLI::ParseError& e) {
      return cli.exit(e) == 0 ? app::kExitOk : app::kExitBadInput;
    }
    return means(m);
  }
  CLI::App cli{
      "gfins-replay: navigate a raw-sample recording (.gfr) through the navigation core, or "
      "print it (gfins-replay dump FILE.gfr), or average a rate-table run (gfins-replay means)",
      "gfins-replay"};
  cli.formatter(std::make_shared<ReplayUsage>());
  cli.footer(footer);
  cli.set_version_flag("--version", gfins::version::version_line("gfins-replay"));
  ReplayOptions o;
  bool no_plot = false;
  cli.add_option("recording", o.recording, "raw-sample recording (.gfr)")->required();
  cli.add_option("--cal", o.cal,
                 "calibration file (docs/calibration-file.md); without it: nominal scale "
                 "factor, no compensation");
  auto* out_opt =
      cli.add_option("-o,--out", o.out.dir, "output folder (default replay-out/<stem>)");
  cli.add_flag("--no-plot", no_plot, "write CSV only, no PNG");
  cli.add_option("--scalar", o.out.scalar,
                 "navigation core scalar: float (the board's float32 core) or double")
      ->check(CLI::IsMember({"float", "double"}))
      ->capture_default_str();
  cli.add_option("--decimate", o.out.decimate, "write every N-th state to navigation.csv")
      ->check(CLI::Range(std::size_t{1}, std::size_t{1000000}))
      ->capture_default_str();
  cli.add_option("--align-s", o.align_s, "static alignment at the start, s")
      ->check(app::finite_range(1e-3, 3600.0))
      ->capture_default_str();
  bool no_still_check = false;
  cli.add_flag("--no-still-check", no_still_check,
               "navigate even when the alignment window is not still (channel standard deviation "
               "above 5 mg)");
  cli.add_option("--heading-deg", o.heading_deg,
                 "initial heading (nothing on board senses it), deg")
      ->check(app::finite_range(-360.0, 360.0))
      ->capture_default_str();
  cli.add_option("--gravity", o.gravity_mps2, "local gravity of the navigation model, m/s^2")
      ->check(app::finite_range(9.7, 9.9))
      ->capture_default_str();
  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return cli.exit(e) == 0 ? app::kExitOk : app::kExitBadInput;
  }
  o.out.plot = !no_plot;
  o.still_check = !no_still_check;
  o.out.dir_given = out_opt->count() > 0;
  return run_navigate(o);
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return replay_main(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gfins-replay: %s\n", e.what());
    return app::kExitError;
  }
}
