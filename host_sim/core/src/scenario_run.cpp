// Running a scenario: the one sample source (trajectory → sensor model → ADC → RawSample,
// sample_source.hpp) makes the stream once, and the one navigation loop (nav_loop.hpp) runs it
// through nav::NavPipeline<T>, once without compensation and once with the scenario's
// compensator; the simulated multi-attitude calibration gives the compensator its parameters on
// request.
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>

#include "gfins/host_sim/adc_model.hpp"
#include "gfins/host_sim/nav_loop.hpp"
#include "gfins/host_sim/recording.hpp"
#include "gfins/host_sim/sample_source.hpp"
#include "gfins/host_sim/scenario.hpp"
#include "gfins/host_sim/sensor_model.hpp"
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
};

HostResult<Stream> make_stream(const Scenario& s, const Trajectory& traj) {
  const ArrayErrors errors = array_errors(s);
  SensorArrayModel model(nav::table1_geometry<double>(s.rho_m), errors, gravity_model(s), s.rate_hz,
                         s.seed);
  AdcConfig adc_config;
  adc_config.sample_rate_hz = s.rate_hz;
  SampleSource source(traj, std::move(model), s.adc ? make_source_adc(adc_config) : nullptr,
                      s.rate_hz);
  if (s.noise_uniform) source.set_uniform_noise_mps2(s.noise_mps2, s.seed);
  const auto steps = static_cast<std::size_t>(std::llround(s.duration_s * s.rate_hz));
  Stream st;
  st.volts_per_count = source.volts_per_count();
  for (std::size_t j = 0; j < 6; ++j) st.scale_v_per_g[j] = errors.sensors[j].scale_v_per_g;
  st.truth.reserve(steps + 1);
  (s.adc ? st.raw.reserve(steps + 1) : st.outputs_mps2.reserve(steps + 1));
  for (std::size_t k = 0; k <= steps; ++k) {
    const Result<SourceSample> x = source.next();
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

template <typename T>
HostResult<RunSeries> navigate(const Scenario& s, const Stream& st, nav::CompensatorKind kind,
                               const nav::Misalignment<double>& m,
                               const std::array<double, 6>& bias_mps2, const std::string& label,
                               const ProgressFn& progress, double progress_base) {
  nav::PipelineConfig<double> cfg;
  cfg.nominal = nav::table1_geometry<double>(s.rho_m);
  // The real front end: the converter's LSB, the sensors' scale factors, the biases the
  // compensator is told (true or calibrated). Unused by the §6.3 m/s² entry.
  for (std::size_t j = 0; j < 6; ++j) {
    cfg.front_end.volts_per_count[j] = s.adc ? st.volts_per_count : 1.0;
    cfg.front_end.scale_v_per_g[j] = st.scale_v_per_g[j];
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
  // Heap-allocated: the pipeline is a large object (on the board it lives in static storage).
  auto pipeline = std::make_unique<nav::NavPipeline<T>>();
  if (const auto status = pipeline->configure(cfg_t); !status.is_ok()) {
    return host_error(status,
                      "scenario " + s.name + ": navigation core rejected the configuration: ");
  }
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
  r.samples.push_back(record_of(st.truth.front(), pipeline->state().template cast<double>()));
  const std::size_t n = st.truth.size();
  const std::size_t every = std::max<std::size_t>(n / 100, 1);
  NavLoop<T> loop(*pipeline, [&](std::uint64_t, const nav::NavState<T>& e) {
    r.samples.push_back(record_of(st.truth[e.seq], e.template cast<double>()));
  });
  for (std::size_t k = 1; k < n; ++k) {
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
    // Gaussian white noise is the model's own; uniform noise is the source's (sample_source.hpp).
    if (s.noise_mps2 > 0 || !s.qa1100) e.noise_g = s.noise_uniform ? 0.0 : s.noise_mps2 / g;
  }
  return errors;
}

Vec3d SampleRecord::att_err_b() const {
  Quatd dq = truth.q_nb.conjugate() * q_nb_est;
  if (dq.w() < 0) dq.coeffs() *= -1.0;
  return 2.0 * dq.vec();
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
  const double samples = std::floor(s.duration_s * s.rate_hz + 0.5) + 1.0;
  const std::uint64_t per_sample = sizeof(TruthState) +
                                   (s.adc ? 2 * sizeof(RawSample) : sizeof(Vec6d)) +
                                   (with_uncompensated ? 2u : 1u) * sizeof(SampleRecord);
  const double bytes = samples * static_cast<double>(per_sample);
  return bytes >= 1.8e19 ? UINT64_MAX : static_cast<std::uint64_t>(bytes);
}

HostStatus check_run_size(const Scenario& s, bool with_uncompensated) {
  char buf[320];
  const double periods = s.duration_s * s.rate_hz;
  if (!(std::floor(periods + 0.5) >= 1.0)) {
    std::snprintf(buf, sizeof buf,
                  "scenario %s: duration_s %g x rate_hz %g = %.3g sample periods: a run needs at "
                  "least 2 samples (duration_s >= %g s at this rate)",
                  s.name.c_str(), s.duration_s, s.rate_hz, periods, 1.0 / s.rate_hz);
    return HostError{ErrorCode::kInvalidArgument, buf};
  }
  const std::uint64_t bytes = run_memory_bytes(s, with_uncompensated);
  if (bytes > kMaxRunMemoryBytes) {
    std::snprintf(buf, sizeof buf,
                  "scenario %s: duration_s %g x rate_hz %g = %.4g samples would need %.3g GiB "
                  "of memory, above the limit of %.3g GiB: shorten the run or lower the rate",
                  s.name.c_str(), s.duration_s, s.rate_hz, std::floor(periods + 0.5) + 1.0,
                  static_cast<double>(bytes) / double(1u << 30),
                  static_cast<double>(kMaxRunMemoryBytes) / double(1u << 30));
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

HostStatus write_series_csv(const RunSeries& r, const std::string& path, std::size_t decimate) {
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
  std::fprintf(f, "%s\n", head.c_str());
  const auto v3 = [f](const Vec3d& v) { std::fprintf(f, ",%.9g,%.9g,%.9g", v.x(), v.y(), v.z()); };
  const auto q4 = [f](const Quatd& q) {
    std::fprintf(f, ",%.9g,%.9g,%.9g,%.9g", q.w(), q.x(), q.y(), q.z());
  };
  const std::size_t every = std::max<std::size_t>(decimate, 1);
  for (std::size_t k = 0; k < r.samples.size(); ++k) {
    if (k % every != 0 && k + 1 != r.samples.size()) continue;
    const SampleRecord& x = r.samples[k];
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
    std::fprintf(f, "\n");
  }
  // The fprintf results above are not checked one by one: a failed write sets the error flag,
  // and fclose alone reports only the last flush (glibc returns 0 after an earlier ENOSPC).
  const bool write_failed = std::ferror(f) != 0;
  if (std::fclose(f) != 0 || write_failed) {
    return HostError{ErrorCode::kIoError, "error writing " + path};
  }
  return Done{};
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

}  // namespace gfins::sim
