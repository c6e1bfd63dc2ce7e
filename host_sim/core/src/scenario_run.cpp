// Running a scenario: the one sample source (trajectory → sensor model → ADC → RawSample,
// sample_generator.hpp) makes the stream once, and the one navigation loop (nav_loop.hpp) runs it
// through nav::NavPipeline<T>, once without compensation and once with the scenario's
// compensator; the simulated multi-attitude calibration gives the compensator its parameters on
// request.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <utility>

#include "gfins/host_sim/accuracy.hpp"
#include "gfins/host_sim/adc_model.hpp"
#include "gfins/host_sim/consistency.hpp"
#include "gfins/host_sim/nav_loop.hpp"
#include "gfins/host_sim/recording.hpp"
#include "gfins/host_sim/sample_generator.hpp"
#include "gfins/host_sim/scenario.hpp"
#include "gfins/host_sim/sensor_model.hpp"
#include "gfins/nav_core/filter/euler_error.hpp"
#include "gfins/nav_core/math.hpp"
#include "gfins/nav_core/pipeline.hpp"

namespace gfins::sim {
namespace {

/// The samples of one scenario, computed once so both runs see the same noise.
struct Stream {
  std::vector<TruthState> truth;
  std::vector<RawSample> raw;       // what the ADC delivered (scenario.adc)
  std::vector<Vec6d> outputs_mps2;  // the paper's §6.3 only (!scenario.adc): m/s², no converter
  double volts_per_count = 0.0;     // of the converter, V at the sensor
  std::array<double, 6> scale_v_per_g{};  // nominal SF of each sensor, what the front end is told
  std::vector<GnssSample> gnss;           // [gnss] fixes for an aided run, in sending order
};

/// The fixes of [gnss] the navigation is aided with: none without [aiding] enabled (the
/// receiver then only feeds `gfins-can gnss`).
std::vector<GnssSample> aiding_fixes(const Scenario& s, const Trajectory& traj) {
  if (!s.gnss || !s.aiding.enabled) return {};
  return GnssModel(*s.gnss, traj).fixes(s.duration_s);
}

/// Offers the fixes sent by t_s (t_send ≤ t_s) to the pipeline, each with its time of validity
/// and the receiver's stated σ: what the board does with the frames of `gfins-can gnss`.
class GnssFeeder {
 public:
  GnssFeeder(const std::vector<GnssSample>& fixes, const std::optional<GnssSpec>& spec,
             ConsistencyRecorder* consistency = nullptr, double stated_sigma_scale = 1.0)
      : fixes_(fixes), spec_(spec), consistency_(consistency), scale_(stated_sigma_scale) {}

  template <typename T>
  void offer_due(nav::NavPipeline<T>& p, double t_s) {
    if (!spec_) return;  // fixes come with a [gnss] table only
    for (; next_ < fixes_.size() && fixes_[next_].t_send_s <= t_s; ++next_) {
      const GnssSample& g = fixes_[next_];
      nav::GnssFix<T> pos;
      pos.t_valid_ns = static_cast<std::int64_t>(std::llround(g.t_valid_s * 1e9));
      pos.value_n = g.r_n_m.template cast<T>();
      pos.sigma = nav::Vec3<T>(static_cast<T>(scale_ * spec_->sigma_pos_h_m),
                               static_cast<T>(scale_ * spec_->sigma_pos_h_m),
                               static_cast<T>(scale_ * spec_->sigma_pos_v_m));
      nav::GnssFix<T> vel = pos;
      vel.value_n = g.v_n_mps.template cast<T>();
      vel.sigma.setConstant(static_cast<T>(scale_ * spec_->sigma_vel_mps));
      const nav::UpdateOutcome op = p.offer_gnss_position(pos);
      const nav::UpdateOutcome ov = p.offer_gnss_velocity(vel);
      if (consistency_ != nullptr) consistency_->add_fix(next_, op, ov);
    }
  }

 private:
  const std::vector<GnssSample>& fixes_;
  const std::optional<GnssSpec>& spec_;
  ConsistencyRecorder* consistency_;
  double scale_;
  std::size_t next_ = 0;
};

HostResult<Stream> make_stream(const Scenario& s, const Trajectory& traj) {
  const ArrayErrors errors = array_errors(s);
  std::vector<GnssSample> gnss = aiding_fixes(s, traj);
  SensorArrayModel model(nav::table1_geometry<double>(s.rho_m), errors, gravity_model(s), s.rate_hz,
                         s.seed);
  AdcConfig adc_config;
  adc_config.sample_rate_hz = s.rate_hz;
  SampleGenerator source(traj, std::move(model), s.adc ? make_source_adc(adc_config) : nullptr,
                         s.rate_hz);
  if (s.noise_uniform) source.set_uniform_noise_mps2(s.noise_mps2, s.seed);
  const auto steps = static_cast<std::size_t>(sample_count(s) - 1);
  Stream st;
  st.gnss = std::move(gnss);
  st.volts_per_count = source.volts_per_count();
  for (std::size_t j = 0; j < 6; ++j) st.scale_v_per_g[j] = errors.sensors[j].scale_v_per_g;
  st.truth.reserve(steps + 1);
  (s.adc ? st.raw.reserve(steps + 1) : st.outputs_mps2.reserve(steps + 1));
  for (std::size_t k = 0; k <= steps; ++k) {
    const Result<GeneratedSample> x = source.next();
    if (!x.is_ok()) return host_error(x.status(), "scenario " + s.name + ": converter: ");
    st.truth.push_back(x->truth);
    if (s.adc) {
      st.raw.push_back(x->raw);
    } else {
      Vec6d out;
      for (int j = 0; j < 6; ++j) {
        out(j) =
            x->volts(j) / st.scale_v_per_g[static_cast<std::size_t>(j)] * nav::kStandardGravity;
      }
      st.outputs_mps2.push_back(out);
    }
  }
  return st;
}

template <typename T>
nav::Misalignment<T> cast_misalignment(const nav::Misalignment<double>& m) {
  nav::Misalignment<T> o;
  for (std::size_t i = 0; i < 6; ++i) {
    o.orientation.beta[i] = static_cast<T>(m.orientation.beta[i]);
    o.orientation.alpha[i] = static_cast<T>(m.orientation.alpha[i]);
    o.drho_b[i] = m.drho_b[i].template cast<T>();
  }
  return o;
}

SampleRecord record_of(const TruthState& truth, const nav::NavState<double>& e) {
  SampleRecord rec;
  rec.t_s = truth.t_s;
  rec.truth = truth;
  rec.q_nb_est = e.q_nb;
  rec.w_b_est = e.w_b;
  rec.wdot_b_est = e.wdot_b;
  rec.a_n_est = e.a_n;
  rec.v_n_est = e.v_n;
  rec.r_n_est = e.r_n;
  return rec;
}

/// record_of, with the filter's 1σ when the pipeline's filter runs.
template <typename T>
SampleRecord record_of(const TruthState& truth, const nav::NavPipeline<T>& p) {
  SampleRecord rec = record_of(truth, p.state().template cast<double>());
  if (p.aiding().started()) {
    const nav::NavAccuracy<T> a = p.accuracy();
    rec.euler_sigma_rad = a.euler_sigma_rad.template cast<double>();
    rec.v_sigma_n = a.vel_sigma_mps.template cast<double>();
    rec.r_sigma_n = a.pos_sigma_m.template cast<double>();
    rec.detector_windows = p.aiding().detector().windows();
    rec.detector_at_rest = p.aiding().at_rest();
  }
  return rec;
}

/// The truth moved by a start error (StreamTargets::start_error): attitude_error_n(q, q_true) = φ
/// for q = exp(−φ) ⊗ q_true (error_model.hpp).
TruthState with_start_error(TruthState x, const StreamTargets::StartError& e) {
  x.q_nb = nav::quat_from_rotation_vector<double>(-e.phi_n) * x.q_nb;
  x.r_n += e.dr_n;
  x.v_n += e.dv_n;
  x.w_b += e.dw_b;
  return x;
}

/// Epoch k of a consistency run (consistency.hpp): the filter's first nine error states against
/// the truth, in its own convention (error_model.hpp: φ from attitude_error_n, then δr, δv,
/// estimate − truth), with their covariance and what the board publishes of them now.
template <typename T>
void record_epoch(ConsistencyRecorder& c, long k, const TruthState& truth,
                  const nav::NavPipeline<T>& p) {
  if (!p.aiding().started()) return;  // nothing published: the epoch stays empty
  const nav::NavState<double> e = p.state().template cast<double>();
  Eigen::Matrix<double, 9, 1> x;
  x.segment<3>(nav::filt_idx::kPhi) = nav::attitude_error_n<double>(e.q_nb, truth.q_nb);
  x.segment<3>(nav::filt_idx::kPos) = e.r_n - truth.r_n;
  x.segment<3>(nav::filt_idx::kVel) = e.v_n - truth.v_n;
  const Eigen::Matrix<double, 9, 9> cov =
      p.aiding().filter().covariance().template topLeftCorner<9, 9>().template cast<double>();
  c.add_epoch(k, x, cov, p.accuracy().valid);
}

/// The filter and standstill detector of [aiding], with the noise the scenario's sensors have
/// (white σ per sample: the stated noise, else the QA-1100 model's 70 µg, never below the
/// converter's 1 µg class quantisation) and the bias prior and walk [aiding] states.
template <typename T>
nav::AidingConfig<T> aiding_config(const Scenario& s, const nav::GravityModel<T>& gravity) {
  const double g = nav::kStandardGravity;
  double white = s.noise_mps2 > 0 ? s.noise_mps2 : (s.qa1100 ? 70e-6 * g : 0.0);
  white = std::max(white, 1e-6 * g);
  const AidingSpec& a = s.aiding;
  nav::AidingConfig<T> c;
  c.enabled = a.enabled;
  c.decimation = a.decimation;
  c.standstill_updates = a.standstill;
  c.filter.sample_rate_hz = static_cast<T>(s.rate_hz);
  c.filter.noise.white_sigma_mps2.fill(static_cast<T>(white));
  c.filter.noise.bias_sigma_mps2.fill(static_cast<T>(a.bias_sigma_ug * 1e-6 * g));
  c.filter.noise.bias_rw_mps2_sqrt_s.fill(static_cast<T>(a.bias_rw_ug_sqrt_s * 1e-6 * g));
  c.filter.track_heading_sigma_rad = static_cast<T>(a.track_heading_sigma_deg * M_PI / 180.0);
  c.filter.zupt_sigma_mps = static_cast<T>(a.zupt_sigma_mps);
  c.filter.zaru_sigma_rps = static_cast<T>(a.zaru_sigma_rps);
  c.standstill.window = a.window;
  c.standstill.false_alarm_probability = static_cast<T>(a.false_alarm);
  c.standstill.white_sigma_mps2 = static_cast<T>(white);
  c.standstill.gravity_mps2 = gravity.magnitude_at_origin();
  // The board knows where its antenna is mounted: the receiver's lever arm.
  if (s.gnss) c.filter.gnss_lever_arm_b = s.gnss->lever_arm_b_m.template cast<T>();
  return c;
}

/// The navigation core of one run, configured: the real front end (the converter's LSB, the
/// sensors' scale factors, the biases the compensator is told, true or calibrated; unused by the
/// §6.3 m/s² entry), the compensator and its misalignment, gravity, the rate.
template <typename T>
HostResult<std::unique_ptr<nav::NavPipeline<T>>> make_pipeline(
    const Scenario& s, double volts_per_count, const std::array<double, 6>& scale_v_per_g,
    nav::CompensatorKind kind, const nav::Misalignment<double>& m,
    const std::array<double, 6>& bias_mps2) {
  nav::PipelineConfig<double> cfg;
  cfg.nominal = nav::table1_geometry<double>(s.rho_m);
  for (std::size_t j = 0; j < 6; ++j) {
    cfg.front_end.volts_per_count[j] = s.adc ? volts_per_count : 1.0;
    cfg.front_end.scale_v_per_g[j] = scale_v_per_g[j];
    cfg.front_end.bias_g[j] = bias_mps2[j] / nav::kStandardGravity;
  }
  cfg.sample_rate_hz = s.rate_hz;
  nav::PipelineConfig<T> cfg_t;
  cfg_t.nominal = cfg.nominal.template cast<T>();
  cfg_t.front_end = cfg.front_end.template cast<T>();
  cfg_t.misalignment = cast_misalignment<T>(m);
  cfg_t.compensator = kind;
  cfg_t.gravity = gravity_model<T>(s);
  cfg_t.sample_rate_hz = static_cast<T>(cfg.sample_rate_hz);
  cfg_t.aiding = aiding_config<T>(s, cfg_t.gravity);
  // Heap-allocated: the pipeline is a large object (on the board it lives in static storage).
  auto pipeline = std::make_unique<nav::NavPipeline<T>>();
  if (const auto status = pipeline->configure(cfg_t); !status.is_ok()) {
    return host_error(status,
                      "scenario " + s.name + ": navigation core rejected the configuration: ");
  }
  return pipeline;
}

template <typename T>
HostResult<RunSeries> navigate(const Scenario& s, const Stream& st, nav::CompensatorKind kind,
                               const nav::Misalignment<double>& m,
                               const std::array<double, 6>& bias_mps2, const std::string& label,
                               const ProgressFn& progress, double progress_base) {
  GFINS_TRY(auto pipeline,
            make_pipeline<T>(s, st.volts_per_count, st.scale_v_per_g, kind, m, bias_mps2));
  RunSeries r;
  r.label = label;
  r.samples.reserve(st.truth.size());
  // The truth is given at the first sample (no alignment): the experiment measures what the
  // array errors do to navigation, not the alignment.
  const nav::NavState<T> init = to_nav_state<T>(st.truth.front(), 0);
  if (s.adc) {
    pipeline->start_at(init, st.raw.front());
  } else {
    Vec6d first = st.outputs_mps2.front();
    for (int j = 0; j < 6; ++j) first(j) -= bias_mps2[static_cast<std::size_t>(j)];
    pipeline->start_at_specific_force(init, first.template cast<T>());
  }
  r.samples.push_back(record_of(st.truth.front(), *pipeline));
  const std::size_t n = st.truth.size();
  const std::size_t every = std::max<std::size_t>(n / 100, 1);
  NavLoop<T> loop(*pipeline, [&](std::uint64_t, const nav::NavState<T>& e) {
    r.samples.push_back(record_of(st.truth[e.seq], *pipeline));
  });
  GnssFeeder gnss(st.gnss, s.gnss);
  for (std::size_t k = 1; k < n; ++k) {
    gnss.offer_due(*pipeline, st.truth[k - 1].t_s);
    if (s.adc) {
      loop.step(st.raw[k]);
    } else {
      // The paper's §6.3: m/s² after the front end, bias removed here (NavPipeline says why).
      Vec6d out = st.outputs_mps2[k];
      for (int j = 0; j < 6; ++j) out(j) -= bias_mps2[static_cast<std::size_t>(j)];
      loop.step_specific_force(out.template cast<T>(),
                               static_cast<std::int64_t>(std::llround(st.truth[k].t_s * 1e9)),
                               static_cast<std::uint32_t>(k));
    }
    if (progress && k % every == 0) {
      progress(progress_base + 0.5 * static_cast<double>(k) / static_cast<double>(n));
    }
  }
  r.report = loop.report();
  return r;
}

std::string source_name(MisalignmentSource m) {
  return m == MisalignmentSource::kTrue ? "true misalignment" : "calibrated misalignment";
}

}  // namespace

ArrayErrors array_errors(const Scenario& s) {
  ArrayErrors errors;
  errors.misalignment = s.misalignment;
  errors.temperature_c = s.temperature_c;
  errors.failures = s.failures;
  const double g = nav::kStandardGravity;
  const double qa1100_sf = AccelErrors::qa1100_typical().scale_v_per_g;
  for (std::size_t j = 0; j < 6; ++j) {
    AccelErrors& e = errors.sensors[j];
    if (s.qa1100) e = AccelErrors::qa1100_typical();
    // Through the converter the sensors have the QA-1100's scale factor (1.33 V/g into 1 kΩ), so
    // the counts carry the real LSB in g; the paper's §6.3 sensors are unit gain (m/s² in, m/s²
    // out).
    if (s.adc) e.scale_v_per_g = s.scale_v_per_g[j] > 0 ? s.scale_v_per_g[j] : qa1100_sf;
    e.bias_g += s.bias_mps2[j] / g;
    // Gaussian white noise is the model's own; uniform noise is the source's
    // (sample_generator.hpp).
    if (s.noise_mps2 > 0 || !s.qa1100) e.noise_g = s.noise_uniform ? 0.0 : s.noise_mps2 / g;
  }
  return errors;
}

Vec3d SampleRecord::att_err_b() const {
  Quatd dq = truth.q_nb.conjugate() * q_nb_est;
  if (dq.w() < 0) dq.coeffs() *= -1.0;
  return 2.0 * dq.vec();
}

Vec3d SampleRecord::euler_err() const {
  const Vec3d d = nav::euler_from_quat(q_nb_est) - nav::euler_from_quat(truth.q_nb);
  return Vec3d(nav::wrap_pi(d.x()), nav::wrap_pi(d.y()), nav::wrap_pi(d.z()));
}

HostResult<CalibrationOutcome> simulate_calibration(const Scenario& s) {
  // The array's true axes θ*_i (eqs. (14)/(15)); positions do not matter at rest.
  const auto truth = nav::misaligned_geometry(nav::table1_geometry<double>(1.0), s.misalignment);
  const auto t2 = calib::table2_attitudes<double>();
  const auto t3 = calib::table3_attitudes<double>();
  const double sf = s.calibration.scale_v_per_g;
  std::mt19937_64 rng(s.calibration.seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  calib::PaperTableOutputs<double> p;
  for (std::size_t i = 0; i < 6; ++i) {
    const bool in_beta = i == 1 || i == 2 || i == 4;  // set {2,3,5}: Table 2 poses
    for (std::size_t j = 0; j < 6; ++j) {
      const auto& a = in_beta ? t2[j] : t3[j];
      const Vec3d a_g(a[0], a[1], a[2]);
      // Model (16) with g = 1: P_ij = SF_i (b_i + θ*_i·a_j), plus the noise of the mean.
      const double b_g = s.bias_mps2[i] / nav::kStandardGravity;
      p.mean_v[i][j] =
          sf * (b_g + truth.theta_b[i].dot(a_g)) + sf * s.calibration.mean_noise_g * n01(rng);
    }
  }
  auto obs = calib::paper_observations(p);
  for (auto& o : obs) {
    o.sample_std_v.fill(sf * s.calibration.mean_noise_g);
    o.sample_count = 1;  // σ of the mean given directly
  }
  const auto res = calib::calibrate_multi_attitude<double>(std::span(obs.data(), obs.size()));
  if (!res.is_ok()) {
    return host_error(res.status(), "scenario " + s.name + ": simulated calibration failed: ");
  }
  const auto& r = res.value();
  CalibrationOutcome c;
  c.ran = true;
  c.estimated = r.orientation;
  c.std_rad = r.orientation_std;
  c.bias_est_g = r.bias_g;
  c.scale_est_v_per_g = r.scale_v_per_g;
  double sum2 = 0;
  for (std::size_t i = 0; i < 6; ++i) {
    sum2 += std::pow(r.orientation.beta[i] - s.misalignment.orientation.beta[i], 2);
    sum2 += std::pow(r.orientation.alpha[i] - s.misalignment.orientation.alpha[i], 2);
  }
  c.rms_angle_error_rad = std::sqrt(sum2 / 12.0);
  return c;
}

std::uint64_t run_memory_bytes(const Scenario& s, bool with_uncompensated) {
  const auto samples = static_cast<double>(sample_count(s));
  const std::uint64_t per_sample = sizeof(TruthState) +
                                   (s.adc ? 2 * sizeof(RawSample) : sizeof(Vec6d)) +
                                   (with_uncompensated ? 2u : 1u) * sizeof(SampleRecord);
  const double bytes = samples * static_cast<double>(per_sample);
  return bytes >= 1.8e19 ? UINT64_MAX : static_cast<std::uint64_t>(bytes);
}

namespace {
/// The soft address-space limit of this process (`ulimit -v`), bytes, from /proc/self/limits
/// (read as a file: no OS header here); 0 when unlimited or unknown.
std::uint64_t address_space_limit_bytes() {
  std::ifstream f("/proc/self/limits");
  const std::string key = "Max address space";
  for (std::string line; std::getline(f, line);) {
    if (line.rfind(key, 0) != 0) continue;
    std::istringstream in(line.substr(key.size()));
    std::string soft;
    in >> soft;
    if (soft == "unlimited") return 0;
    return std::strtoull(soft.c_str(), nullptr, 10);
  }
  return 0;
}
}  // namespace

std::uint64_t max_run_memory_bytes() {
  std::uint64_t limit = kMaxRunMemoryBytes;
  const char* v = std::getenv("GFINS_MAX_RUN_MEMORY_BYTES");
  if (v != nullptr && *v != '\0') {
    char* end = nullptr;
    const unsigned long long n = std::strtoull(v, &end, 10);
    if (*end == '\0' && n > 0) limit = static_cast<std::uint64_t>(n);
  }
  // Under `ulimit -v` the series must fit in what the address space leaves after the program's
  // own mappings (std::bad_alloc otherwise, the review's case).
  if (const std::uint64_t as = address_space_limit_bytes(); as > 0) {
    limit = std::min(limit, as > kAddressSpaceReserveBytes ? as - kAddressSpaceReserveBytes : 0);
  }
  return limit;
}

HostStatus check_run_size(const Scenario& s, bool with_uncompensated, bool in_memory) {
  char buf[320];
  const double periods = s.duration_s * s.rate_hz;
  if (sample_count(s) < 2) {
    std::snprintf(buf, sizeof buf,
                  "scenario %s: duration_s %g x rate_hz %g = %.3g sample periods: a run needs at "
                  "least 2 samples (duration_s >= %g s at this rate)",
                  s.name.c_str(), s.duration_s, s.rate_hz, periods, 1.0 / s.rate_hz);
    return HostError{ErrorCode::kInvalidArgument, buf};
  }
  if (!in_memory) return Done{};  // a streamed run holds no series
  const std::uint64_t bytes = run_memory_bytes(s, with_uncompensated);
  const std::uint64_t limit = max_run_memory_bytes();
  if (bytes > limit) {
    std::snprintf(buf, sizeof buf,
                  "scenario %s: duration_s %g x rate_hz %g = %.4g samples would need %.3g GiB "
                  "of memory, above the limit of %.3g GiB: shorten the run or lower the rate",
                  s.name.c_str(), s.duration_s, s.rate_hz, static_cast<double>(sample_count(s)),
                  static_cast<double>(bytes) / double(1u << 30),
                  static_cast<double>(limit) / double(1u << 30));
    return HostError{ErrorCode::kOutOfRange, buf};
  }
  return Done{};
}

HostResult<ScenarioOutcome> run_scenario(const Scenario& s, const ProgressFn& progress,
                                         bool with_uncompensated, NavScalar scalar) {
  GFINS_TRY_STATUS(check_run_size(s, with_uncompensated));
  ScenarioOutcome out;
  const bool calibrated = s.misalignment_source == MisalignmentSource::kCalibrated;
  if (calibrated || s.trajectory.kind == "calibration_poses") {
    GFINS_TRY(out.calibration, simulate_calibration(s));
  }
  if (s.trajectory.kind == "calibration_poses") {
    // No navigation run (the array turns between poses; the calibration is the product), but the
    // samples of the pose sequence, so that the calibration can be recorded and replayed.
    // The same motion as the simulated board's (make_trajectory, make_pose_sequence).
    GFINS_TRY(const auto traj, make_trajectory(s.trajectory));
    GFINS_TRY(Stream st, make_stream(s, *traj));
    out.raw = std::move(st.raw);
    out.volts_per_count = st.volts_per_count;
    return out;
  }

  // What the compensator is told: the truth, or the calibration's estimates (angles and biases;
  // the location errors are not estimated by the multi-attitude calibration and stay as given).
  std::array<double, 6> bias_comp = s.bias_mps2;
  out.compensator_misalignment = s.misalignment;
  if (calibrated) {
    out.compensator_misalignment.orientation = out.calibration.estimated;
    for (std::size_t j = 0; j < 6; ++j) {
      bias_comp[j] = out.calibration.bias_est_g[j] * nav::kStandardGravity;
    }
  }
  GFINS_TRY(const auto traj, make_trajectory(s.trajectory));
  GFINS_TRY(const Stream st, make_stream(s, *traj));
  const auto run = [&](nav::CompensatorKind kind, const nav::Misalignment<double>& m,
                       const std::array<double, 6>& bias, const std::string& label, double base) {
    return scalar == NavScalar::kFloat
               ? navigate<float>(s, st, kind, m, bias, label, progress, base)
               : navigate<double>(s, st, kind, m, bias, label, progress, base);
  };
  if (with_uncompensated) {
    GFINS_TRY(out.uncompensated, run(nav::CompensatorKind::kNone, nav::Misalignment<double>{},
                                     std::array<double, 6>{}, "uncompensated", 0.0));
  }
  GFINS_TRY(out.compensated, run(s.compensator, out.compensator_misalignment, bias_comp,
                                 std::string("compensated (") + nav::to_string(s.compensator) +
                                     ", " + source_name(s.misalignment_source) + ")",
                                 0.5));
  if (progress) progress(1.0);
  out.volts_per_count = st.volts_per_count;
  out.raw = st.raw;
  return out;
}

namespace {
template <typename F>
Bounds bounds_of(const RunSeries& r, F f) {
  Bounds b{1e300, -1e300};
  for (const auto& x : r.samples) {
    if (x.t_s <= 0) continue;  // t = 0 is the given initial state
    const Vec3d v = f(x);
    b.lo = std::min(b.lo, v.minCoeff());
    b.hi = std::max(b.hi, v.maxCoeff());
  }
  return b;
}
}  // namespace

Bounds linear_accel_bounds(const RunSeries& r) {
  return bounds_of(r, [](const SampleRecord& x) { return x.a_err_n(); });
}
Bounds angular_accel_bounds(const RunSeries& r) {
  return bounds_of(r, [](const SampleRecord& x) { return x.wdot_err_b(); });
}

SeriesCsvWriter::SeriesCsvWriter(std::FILE* f, std::string path, std::size_t every)
    : file_(f), path_(std::move(path)), every_(std::max<std::size_t>(every, 1)) {}

SeriesCsvWriter::SeriesCsvWriter(SeriesCsvWriter&& other) noexcept
    : file_(std::exchange(other.file_, nullptr)),
      path_(std::move(other.path_)),
      every_(other.every_),
      seen_(other.seen_),
      written_(other.written_),
      pending_(std::move(other.pending_)) {}

SeriesCsvWriter& SeriesCsvWriter::operator=(SeriesCsvWriter&& other) noexcept {
  if (this != &other) {
    if (file_ != nullptr)
      (void)std::fclose(file_);  // moved-over writer: errors are not reported (close() does)
    file_ = std::exchange(other.file_, nullptr);
    path_ = std::move(other.path_);
    every_ = other.every_;
    seen_ = other.seen_;
    written_ = other.written_;
    pending_ = std::move(other.pending_);
  }
  return *this;
}

SeriesCsvWriter::~SeriesCsvWriter() {
  if (file_ != nullptr)
    (void)std::fclose(file_);  // unclosed: errors are not reported (close() does)
}

HostResult<SeriesCsvWriter> SeriesCsvWriter::open(const std::string& path, std::size_t decimate) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) return HostError{ErrorCode::kIoError, "cannot write " + path};
  // Units and frames in every name: q_nb (body to NED, unitless), w_b (rad/s, body FRD),
  // a_n (m/s², NED), v_n (m/s, NED), r_n (m, NED), wdot_b (rad/s², body), att_b (small-angle
  // attitude error, rad, body).
  std::string head = "t_s";
  const auto quat_cols = [&](const char* who) {
    for (const char* c : {"w", "x", "y", "z"}) head += std::string(",") + who + "_q_nb_" + c;
  };
  const auto vec_cols = [&](const std::string& name, const char* unit) {
    for (const char* c : {"x", "y", "z"}) head += "," + name + "_" + c + "_" + unit;
  };
  for (const char* who : {"true", "est"}) {
    quat_cols(who);
    vec_cols(std::string(who) + "_w_b", "rps");
    vec_cols(std::string(who) + "_a_n", "mps2");
    vec_cols(std::string(who) + "_v_n", "mps");
    vec_cols(std::string(who) + "_r_n", "m");
  }
  vec_cols("err_wdot_b", "rps2");
  vec_cols("err_a_n", "mps2");
  vec_cols("err_w_b", "rps");
  vec_cols("err_att_b", "rad");
  vec_cols("err_v_n", "mps");
  vec_cols("err_r_n", "m");
  // Euler-angle errors and the aiding filter's 1σ (nan: no filter), docs/simulation.md.
  const auto euler_cols = [&](const char* name) {
    for (const char* c : {"roll", "pitch", "heading"})
      head += std::string(",") + name + "_" + c + "_rad";
  };
  euler_cols("err_euler");
  euler_cols("sigma_euler");
  vec_cols("sigma_v_n", "mps");
  vec_cols("sigma_r_n", "m");
  std::fprintf(f, "%s\n", head.c_str());
  return SeriesCsvWriter(f, path, decimate);
}

void SeriesCsvWriter::write_row(const SampleRecord& x) {
  std::FILE* f = file_;
  const auto v3 = [f](const Vec3d& v) { std::fprintf(f, ",%.9g,%.9g,%.9g", v.x(), v.y(), v.z()); };
  const auto q4 = [f](const Quatd& q) {
    std::fprintf(f, ",%.9g,%.9g,%.9g,%.9g", q.w(), q.x(), q.y(), q.z());
  };
  std::fprintf(f, "%.6f", x.t_s);
  q4(x.truth.q_nb);
  v3(x.truth.w_b);
  v3(x.truth.a_n);
  v3(x.truth.v_n);
  v3(x.truth.r_n);
  q4(x.q_nb_est);
  v3(x.w_b_est);
  v3(x.a_n_est);
  v3(x.v_n_est);
  v3(x.r_n_est);
  v3(x.wdot_err_b());
  v3(x.a_err_n());
  v3(x.w_err_b());
  v3(x.att_err_b());
  v3(x.v_err_n());
  v3(x.r_err_n());
  v3(x.euler_err());
  v3(x.euler_sigma_rad);
  v3(x.v_sigma_n);
  v3(x.r_sigma_n);
  std::fprintf(f, "\n");
  ++written_;
}

HostStatus SeriesCsvWriter::add(const SampleRecord& x) {
  if (file_ == nullptr) return HostError{ErrorCode::kFailedPrecondition, path_ + ": closed"};
  // Row k is written when k is a multiple of the decimation; otherwise it waits, in case it is
  // the last one (write_series_csv keeps every N-th sample and the last).
  if (seen_ % every_ == 0) {
    write_row(x);
    pending_.reset();
  } else {
    pending_ = x;
  }
  ++seen_;
  // The fprintf results are not checked one by one: a failed write sets the error flag.
  if (std::ferror(file_) != 0) return HostError{ErrorCode::kIoError, "error writing " + path_};
  return Done{};
}

HostStatus SeriesCsvWriter::close() {
  if (file_ == nullptr) return Done{};
  if (pending_) write_row(*pending_);
  pending_.reset();
  // fclose alone reports only the last flush (glibc returns 0 after an earlier ENOSPC).
  const bool write_failed = std::ferror(file_) != 0;
  const int rc = std::fclose(std::exchange(file_, nullptr));
  if (rc != 0 || write_failed) return HostError{ErrorCode::kIoError, "error writing " + path_};
  return Done{};
}

HostStatus write_series_csv(const RunSeries& r, const std::string& path, std::size_t decimate) {
  GFINS_TRY(auto w, SeriesCsvWriter::open(path, decimate));
  for (const SampleRecord& x : r.samples) GFINS_TRY_STATUS(w.add(x));
  return w.close();
}

void SeriesStats::add(const SampleRecord& x) {
  ++samples;
  t_last_s = x.t_s;
  if (x.t_s > 0) {  // t = 0 is the given initial state (bounds_of)
    const Vec3d a = x.a_err_n();
    const Vec3d w = x.wdot_err_b();
    linear.lo = std::min(linear.lo, a.minCoeff());
    linear.hi = std::max(linear.hi, a.maxCoeff());
    angular.lo = std::min(angular.lo, w.minCoeff());
    angular.hi = std::max(angular.hi, w.maxCoeff());
  }
  const double att = x.att_err_b().norm() * 180.0 / M_PI;
  att_max_deg = std::max(att_max_deg, att);
  vel_max_mps = std::max(vel_max_mps, x.v_err_n().norm());
  pos_max_m = std::max(pos_max_m, x.r_err_n().norm());
  att_final_deg = att;
  vel_final_mps = x.v_err_n().norm();
  pos_final_m = x.r_err_n().norm();
}

SeriesStats series_stats(const RunSeries& r) {
  SeriesStats st;
  st.label = r.label;
  st.report = r.report;
  for (const SampleRecord& x : r.samples) st.add(x);
  return st;
}

HostStatus write_run_recording(const Scenario& s, const ScenarioOutcome& o,
                               const std::string& path) {
  if (o.raw.empty() || !(o.volts_per_count > 0.0)) {
    return HostError{ErrorCode::kFailedPrecondition,
                     "scenario " + s.name +
                         ": nothing to record: its samples do not go through the ADC (sensors.adc "
                         "= false, the paper's §6.3 in m/s²); a recording holds ADC counts"};
  }
  RecordingHeader h;
  h.sample_rate_hz = s.rate_hz;
  h.volts_per_count.fill(o.volts_per_count);
  h.geometry = nav::table1_geometry<double>(s.rho_m);
  return write_recording(path, h, o.raw);
}

namespace {

/// One run of a streamed scenario: its pipeline, loop, CSV and statistics.
template <typename T>
struct StreamedSeries {
  std::unique_ptr<nav::NavPipeline<T>> pipeline;
  std::unique_ptr<NavLoop<T>> loop;
  std::optional<SeriesCsvWriter> csv;
  const std::string* csv_path = nullptr;
  SeriesStats* stats = nullptr;
  AccuracyTracker* accuracy = nullptr;
  ConsistencyRecorder* consistency = nullptr;
  std::array<double, 6> bias_mps2{};
  HostStatus sink_status = Done{};
  std::unique_ptr<GnssFeeder> gnss;

  HostStatus take(const SampleRecord& rec) {
    stats->add(rec);
    if (accuracy != nullptr) accuracy->add(rec);
    if (csv) return csv->add(rec);
    return Done{};
  }
};

template <typename T>
HostStatus stream_runs(const Scenario& s, SampleGenerator& source, const StreamTargets& targets,
                       const ProgressFn& progress,
                       const nav::Misalignment<double>& comp_misalignment,
                       const std::array<double, 6>& bias_comp, const std::array<double, 6>& sf,
                       std::optional<RecordingWriter>& rec,
                       const std::vector<GnssSample>& gnss_fixes, StreamedOutcome& out) {
  const bool navigate_runs = s.trajectory.kind != "calibration_poses";
  const std::uint64_t steps = sample_count(s) - 1;
  out.samples_planned = steps + 1;
  const double vpc = source.volts_per_count();
  std::vector<std::unique_ptr<StreamedSeries<T>>> runs;
  const TruthState* current = nullptr;
  if (navigate_runs) {
    struct Spec {
      nav::CompensatorKind kind = nav::CompensatorKind::kNone;
      nav::Misalignment<double> m{};
      std::array<double, 6> bias{};
      const std::string* csv = nullptr;
      SeriesStats* stats = nullptr;
    };
    const Spec specs[] = {
        {nav::CompensatorKind::kNone, nav::Misalignment<double>{}, std::array<double, 6>{},
         &targets.uncompensated_csv, &out.uncompensated},
        {s.compensator, comp_misalignment, bias_comp, &targets.compensated_csv, &out.compensated}};
    for (const Spec& sp : specs) {
      if (sp.stats == &out.uncompensated && !targets.uncompensated_run) continue;
      auto r = std::make_unique<StreamedSeries<T>>();
      if (sp.stats == &out.compensated) {
        r->accuracy = targets.accuracy;
        r->consistency = targets.consistency;
      }
      GFINS_TRY(auto p, make_pipeline<T>(s, vpc, sf, sp.kind, sp.m, sp.bias));
      r->pipeline = std::move(p);
      r->stats = sp.stats;
      r->bias_mps2 = sp.bias;
      r->gnss = std::make_unique<GnssFeeder>(gnss_fixes, s.gnss, r->consistency,
                                             targets.gnss_stated_sigma_scale);
      r->csv_path = sp.csv;
      StreamedSeries<T>* self = r.get();
      r->loop = std::make_unique<NavLoop<T>>(
          *r->pipeline, [self, &current](std::uint64_t, const nav::NavState<T>&) {
            // The sink runs inside step(), for the sample just offered: its truth is `current`.
            if (!self->sink_status.is_ok()) return;
            self->sink_status = self->take(record_of(*current, *self->pipeline));
            if (self->consistency == nullptr) return;
            if (const long k = self->consistency->due(current->t_s); k >= 0) {
              record_epoch(*self->consistency, k, *current, *self->pipeline);
            }
          });
      runs.push_back(std::move(r));
    }
    // The tables are opened once every run's pipeline is accepted: a geometry or calibration the
    // core refuses leaves no header-only CSV behind.
    for (auto& r : runs) {
      if (r->csv_path->empty()) continue;
      GFINS_TRY(auto w, SeriesCsvWriter::open(*r->csv_path, targets.decimate));
      r->csv.emplace(std::move(w));
    }
  }
  const auto specific_force = [&](const GeneratedSample& x, const std::array<double, 6>& bias) {
    // The paper's §6.3: m/s² after the front end, bias removed here (NavPipeline says why).
    Vec6d o;
    for (int j = 0; j < 6; ++j) {
      const auto ju = static_cast<std::size_t>(j);
      o(j) = x.volts(j) / sf[ju] * nav::kStandardGravity - bias[ju];
    }
    return o;
  };
  const std::uint64_t every = std::max<std::uint64_t>(out.samples_planned / 1000, 1);
  double t_prev_s = 0.0;  // fixes sent by the previous sample are offered before this one
  for (std::uint64_t k = 0; k <= steps; ++k) {
    if (k > 0 && targets.stop != nullptr && *targets.stop != 0) {
      out.interrupted = true;
      break;
    }
    const Result<GeneratedSample> x = source.next();
    if (!x.is_ok()) return host_error(x.status(), "scenario " + s.name + ": converter: ");
    current = &x->truth;
    if (rec) GFINS_TRY_STATUS(rec->append(x->raw));
    for (auto& r : runs) {
      if (k == 0) {
        // The truth is given at the first sample (no alignment), as run_scenario does; the
        // compensated run may start off it by targets.start_error.
        const nav::NavState<T> init =
            r->stats == &out.compensated
                ? to_nav_state<T>(with_start_error(x->truth, targets.start_error), 0)
                : to_nav_state<T>(x->truth, 0);
        if (s.adc) {
          r->pipeline->start_at(init, x->raw);
        } else {
          r->pipeline->start_at_specific_force(init,
                                               specific_force(*x, r->bias_mps2).template cast<T>());
        }
        GFINS_TRY_STATUS(r->take(record_of(x->truth, *r->pipeline)));
        continue;
      }
      r->gnss->offer_due(*r->pipeline, t_prev_s);
      if (s.adc) {
        r->loop->step(x->raw);
      } else {
        r->loop->step_specific_force(specific_force(*x, r->bias_mps2).template cast<T>(),
                                     static_cast<std::int64_t>(std::llround(x->truth.t_s * 1e9)),
                                     static_cast<std::uint32_t>(k));
      }
      GFINS_TRY_STATUS(r->sink_status);
    }
    out.samples_done = k + 1;
    out.t_stop_s = x->truth.t_s;
    t_prev_s = x->truth.t_s;
    if (progress && k % every == 0) {
      progress(static_cast<double>(k) / static_cast<double>(out.samples_planned));
    }
  }
  for (auto& r : runs) {
    r->stats->report = r->loop->report();
    if (r->csv) GFINS_TRY_STATUS(r->csv->close());
  }
  if (progress && !out.interrupted) progress(1.0);
  return Done{};
}

}  // namespace

HostResult<StreamedOutcome> run_scenario_streamed(const Scenario& s, const StreamTargets& targets,
                                                  const ProgressFn& progress, NavScalar scalar) {
  GFINS_TRY_STATUS(check_run_size(s, true, /*in_memory=*/false));
  StreamedOutcome out;
  const bool calibrated = s.misalignment_source == MisalignmentSource::kCalibrated;
  if (calibrated || s.trajectory.kind == "calibration_poses") {
    GFINS_TRY(out.calibration, simulate_calibration(s));
  }
  std::array<double, 6> bias_comp = s.bias_mps2;
  nav::Misalignment<double> comp_m = s.misalignment;
  if (calibrated) {
    comp_m.orientation = out.calibration.estimated;
    for (std::size_t j = 0; j < 6; ++j) {
      bias_comp[j] = out.calibration.bias_est_g[j] * nav::kStandardGravity;
    }
  }
  out.uncompensated.label = "uncompensated";
  out.compensated.label = std::string("compensated (") + nav::to_string(s.compensator) + ", " +
                          source_name(s.misalignment_source) + ")";
  GFINS_TRY(const auto traj, make_trajectory(s.trajectory));
  // The same source as make_stream: the same samples, the same noise.
  ArrayErrors errors = array_errors(s);
  for (std::size_t j = 0; j < 6; ++j) {
    errors.sensors[j].bias_g += targets.unknown_bias_mps2[j] / nav::kStandardGravity;
  }
  SensorArrayModel model(nav::table1_geometry<double>(s.rho_m), errors, gravity_model(s), s.rate_hz,
                         s.seed);
  AdcConfig adc_config;
  adc_config.sample_rate_hz = s.rate_hz;
  SampleGenerator source(*traj, std::move(model), s.adc ? make_source_adc(adc_config) : nullptr,
                         s.rate_hz);
  if (s.noise_uniform) source.set_uniform_noise_mps2(s.noise_mps2, s.seed);
  std::array<double, 6> sf{};
  for (std::size_t j = 0; j < 6; ++j) sf[j] = errors.sensors[j].scale_v_per_g;
  const std::vector<GnssSample> gnss = aiding_fixes(s, *traj);
  std::optional<RecordingWriter> rec;
  if (!targets.recording.empty()) {
    if (!s.adc || !(source.volts_per_count() > 0.0)) {
      return HostError{ErrorCode::kFailedPrecondition,
                       "scenario " + s.name +
                           ": nothing to record: its samples do not go through the ADC "
                           "(sensors.adc = false, the paper's §6.3 in m/s²); a recording holds "
                           "ADC counts"};
    }
    RecordingHeader h;  // as write_run_recording
    h.sample_rate_hz = s.rate_hz;
    h.volts_per_count.fill(source.volts_per_count());
    h.geometry = nav::table1_geometry<double>(s.rho_m);
    GFINS_TRY(auto w, RecordingWriter::open(targets.recording, h));
    rec.emplace(std::move(w));
  }
  const HostStatus st =
      scalar == NavScalar::kFloat
          ? stream_runs<float>(s, source, targets, progress, comp_m, bias_comp, sf, rec, gnss, out)
          : stream_runs<double>(s, source, targets, progress, comp_m, bias_comp, sf, rec, gnss,
                                out);
  if (rec) {
    out.recorded = rec->records_written();
    // Closed even after an error, so that what was written stays a valid recording.
    const HostStatus c = rec->close();
    GFINS_TRY_STATUS(st);
    GFINS_TRY_STATUS(c);
  }
  GFINS_TRY_STATUS(st);
  return out;
}

std::uint64_t run_disk_bytes(const Scenario& s, std::size_t decimate, bool with_recording) {
  const auto samples = static_cast<double>(sample_count(s));
  const double rows = std::ceil(samples / static_cast<double>(std::max<std::size_t>(decimate, 1)));
  double bytes = 0;
  if (s.trajectory.kind != "calibration_poses") {
    bytes += 2.0 * rows * static_cast<double>(kCsvRowBytesEstimate);
  }
  if (with_recording) {
    // docs/recording-format.md: the header, 32 bytes per record, a CRC-32 per block.
    bytes += static_cast<double>(kRecordingHeaderBytes) +
             samples * static_cast<double>(kRecordingRecordBytes) +
             std::ceil(samples / kDefaultRecordsPerBlock) * static_cast<double>(kRecordingCrcBytes);
  }
  return bytes >= 1.8e19 ? UINT64_MAX : static_cast<std::uint64_t>(bytes);
}

}  // namespace gfins::sim
