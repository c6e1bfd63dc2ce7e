// Running a scenario through nav::NavPipeline<double>: the sensor outputs of the true (misaligned)
// array plus noise, once without compensation and once with the scenario's compensator, and the
// simulated multi-attitude calibration that gives the compensator its parameters on request.
#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>

#include "gfins/host_sim/array_model.hpp"
#include "gfins/host_sim/scenario.hpp"
#include "gfins/host_sim/sensor_model.hpp"
#include "gfins/nav_core/pipeline.hpp"

namespace gfins::sim {
namespace {

/// Draws the per-sensor noise of one sample: Gaussian, or uniform of the same σ (±√3 σ).
class Noise {
 public:
  Noise(double sigma, bool uniform, std::uint64_t seed)
      : sigma_(sigma), uniform_(uniform), rng_(seed) {}
  Vec6d draw() {
    Vec6d n = Vec6d::Zero();
    if (sigma_ <= 0) return n;
    for (int j = 0; j < 6; ++j) {
      n(j) = uniform_ ? std::sqrt(3.0) * sigma_ * (2.0 * u01_(rng_) - 1.0) : sigma_ * n01_(rng_);
    }
    return n;
  }

 private:
  double sigma_;
  bool uniform_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> n01_{0.0, 1.0};
  std::uniform_real_distribution<double> u01_{0.0, 1.0};
};

/// The sensor outputs (m/s²) of every sample, computed once so both runs see the same noise.
struct Stream {
  std::vector<TruthState> truth;
  std::vector<Vec6d> outputs;
};

Stream make_stream(const Scenario& s, const Trajectory& traj) {
  // The array's outputs come from the project's sensor model (sensor_model.hpp), in volts; the
  // front end's division by the (known) scale factor brings them back to m/s². Gaussian white
  // noise is the model's own; uniform noise (not in the model) is added here instead.
  ArrayErrors errors;
  errors.misalignment = s.misalignment;
  errors.temperature_c = s.temperature_c;
  const double g = nav::kStandardGravity;
  for (std::size_t j = 0; j < 6; ++j) {
    AccelErrors& e = errors.sensors[j];
    if (s.qa1100) e = AccelErrors::qa1100_typical();
    e.bias_g += s.bias_mps2[j] / g;
    if (s.noise_mps2 > 0 || !s.qa1100) e.noise_g = s.noise_uniform ? 0.0 : s.noise_mps2 / g;
  }
  SensorArrayModel model(nav::table1_geometry<double>(s.rho_m), errors, gravity_model(s), s.rate_hz,
                         s.seed);
  Noise uniform(s.noise_uniform ? s.noise_mps2 : 0.0, true, s.seed);
  const auto steps = static_cast<std::size_t>(std::llround(s.duration_s * s.rate_hz));
  Stream st;
  st.truth.reserve(steps + 1);
  st.outputs.reserve(steps + 1);
  for (std::size_t k = 0; k <= steps; ++k) {
    const TruthState x = traj.at(static_cast<double>(k) / s.rate_hz);
    const SensorArrayModel::Volts v = model.volts(x);
    Vec6d out = uniform.draw();
    for (int j = 0; j < 6; ++j) {
      out(j) += v(j) / errors.sensors[static_cast<std::size_t>(j)].scale_v_per_g * g;
    }
    st.truth.push_back(x);
    st.outputs.push_back(out);
  }
  return st;
}

RunSeries navigate(const Scenario& s, const Stream& st, nav::CompensatorKind kind,
                   const nav::Misalignment<double>& m, const std::array<double, 6>& bias_mps2,
                   const std::string& label, const ProgressFn& progress, double progress_base) {
  nav::PipelineConfig<double> cfg;
  cfg.nominal = nav::table1_geometry<double>(s.rho_m);
  cfg.front_end.volts_per_count.fill(1.0);
  cfg.front_end.scale_v_per_g.fill(1.0);
  cfg.misalignment = m;
  cfg.compensator = kind;
  cfg.gravity = gravity_model(s);
  cfg.sample_rate_hz = s.rate_hz;
  // Heap-allocated: the pipeline is a large object (on the board it lives in static storage).
  auto pipeline = std::make_unique<nav::NavPipeline<double>>();
  if (const auto status = pipeline->configure(cfg); !status.is_ok()) {
    throw std::runtime_error(std::string("navigation core rejected the configuration: ") +
                             status.message());
  }
  const auto corrected = [&](std::size_t k) {
    Vec6d out = st.outputs[k];
    for (int j = 0; j < 6; ++j) out(j) -= bias_mps2[static_cast<std::size_t>(j)];
    return out;
  };
  RunSeries r;
  r.label = label;
  r.samples.reserve(st.truth.size());
  // The truth is given at the first sample (no alignment): the experiment measures what the
  // array errors do to navigation, not the alignment.
  nav::NavState<double> init;
  const TruthState& x0 = st.truth.front();
  init.q_nb = x0.q_nb;
  init.w_b = x0.w_b;
  init.wdot_b = x0.wdot_b;
  init.v_n = x0.v_n;
  init.r_n = x0.r_n;
  pipeline->start_at_outputs(init, corrected(0));
  const std::size_t n = st.truth.size();
  const std::size_t every = std::max<std::size_t>(n / 100, 1);
  for (std::size_t k = 0; k < n; ++k) {
    if (k > 0) {
      pipeline->process_outputs(corrected(k),
                                static_cast<std::int64_t>(std::llround(st.truth[k].t_s * 1e9)),
                                static_cast<std::uint32_t>(k));
    }
    const nav::NavState<double>& e = pipeline->state();
    SampleRecord rec;
    rec.t_s = st.truth[k].t_s;
    rec.truth = st.truth[k];
    rec.q_nb_est = e.q_nb;
    rec.w_b_est = e.w_b;
    rec.wdot_b_est = e.wdot_b;
    rec.a_n_est = e.a_n;
    rec.v_n_est = e.v_n;
    rec.r_n_est = e.r_n;
    r.samples.push_back(rec);
    if (progress && k % every == 0) {
      progress(progress_base + 0.5 * static_cast<double>(k) / static_cast<double>(n));
    }
  }
  return r;
}

std::string source_name(MisalignmentSource m) {
  return m == MisalignmentSource::kTrue ? "true misalignment" : "calibrated misalignment";
}

}  // namespace

Vec3d SampleRecord::att_err_b() const {
  Quatd dq = truth.q_nb.conjugate() * q_nb_est;
  if (dq.w() < 0) dq.coeffs() *= -1.0;
  return 2.0 * dq.vec();
}

CalibrationOutcome simulate_calibration(const Scenario& s) {
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
    throw std::runtime_error(std::string("simulated calibration failed: ") +
                             res.status().message());
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

ScenarioOutcome run_scenario(const Scenario& s, const ProgressFn& progress,
                             bool with_uncompensated) {
  ScenarioOutcome out;
  const bool calibrated = s.misalignment_source == MisalignmentSource::kCalibrated;
  if (calibrated || s.trajectory.kind == "calibration_poses") {
    out.calibration = simulate_calibration(s);
  }
  if (s.trajectory.kind == "calibration_poses") return out;

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
  const auto traj = make_trajectory(s.trajectory);
  const Stream st = make_stream(s, *traj);
  if (with_uncompensated) {
    out.uncompensated = navigate(s, st, nav::CompensatorKind::kNone, nav::Misalignment<double>{},
                                 std::array<double, 6>{}, "uncompensated", progress, 0.0);
  }
  out.compensated = navigate(s, st, s.compensator, out.compensator_misalignment, bias_comp,
                             std::string("compensated (") + nav::to_string(s.compensator) + ", " +
                                 source_name(s.misalignment_source) + ")",
                             progress, 0.5);
  if (progress) progress(1.0);
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

void write_series_csv(const RunSeries& r, const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) throw std::runtime_error("cannot write " + path);
  std::fprintf(f,
               "t_s,"
               "true_qw,true_qx,true_qy,true_qz,true_wx,true_wy,true_wz,"
               "true_ax,true_ay,true_az,true_vx,true_vy,true_vz,true_rx,true_ry,true_rz,"
               "est_qw,est_qx,est_qy,est_qz,est_wx,est_wy,est_wz,"
               "est_ax,est_ay,est_az,est_vx,est_vy,est_vz,est_rx,est_ry,est_rz,"
               "err_wdotx,err_wdoty,err_wdotz,err_ax,err_ay,err_az,err_wx,err_wy,err_wz,"
               "err_attx,err_atty,err_attz,err_vx,err_vy,err_vz,err_rx,err_ry,err_rz\n");
  const auto v3 = [f](const Vec3d& v) { std::fprintf(f, ",%.9g,%.9g,%.9g", v.x(), v.y(), v.z()); };
  const auto q4 = [f](const Quatd& q) {
    std::fprintf(f, ",%.9g,%.9g,%.9g,%.9g", q.w(), q.x(), q.y(), q.z());
  };
  for (const auto& x : r.samples) {
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
  if (std::fclose(f) != 0 || write_failed) throw std::runtime_error("error writing " + path);
}

}  // namespace gfins::sim
