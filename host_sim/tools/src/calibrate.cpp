#include "calibrate.hpp"

#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>
#include <span>

namespace gfins::tools {
namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;
constexpr std::array<const char*, 6> kAngleNames = {"xy", "xz", "yx", "yz", "zx", "zy"};

bool in_set(const std::array<int, 3>& set, int sensor0) {
  return set[0] == sensor0 || set[1] == sensor0 || set[2] == sensor0;
}

FileStatus bad(const std::string& what) { return FileStatus(ErrorCode::kInvalidArgument, what); }

FileStatus solver_failure(Status s) {
  return FileStatus(
      s.code(), std::string("calibration failed (") + to_string(s.code()) + "): " + s.message());
}

// σ of a mean: std/√count, passed to the solver as a σ with count 1 so rows may differ in count.
void set_sigma(calib::AttitudeObservation<double>& o, std::size_t sensor0, const MeanRow& m) {
  if (m.count == 0) return;
  o.sample_std_v[sensor0] = m.std_v / std::sqrt(static_cast<double>(m.count));
  o.sample_count = 1;
}

FileResult<CalibrationRun> run_paper_layout(const CalibrationInputs& in, const std::string& file) {
  // Tables 4/5: every sensor in attitudes 1..6 of its set's table (2 for β, 3 for α).
  calib::PaperTableOutputs<double> p;
  std::array<std::array<const MeanRow*, 6>, 6> at{};
  for (const MeanRow& m : in.means) {
    if (m.attitude > 6) {
      return bad(
          file + ":" + std::to_string(m.line) + ": attitude " + std::to_string(m.attitude) +
          " does not exist in Tables 2/3 (1..6); give a poses file (--poses) for other poses");
    }
    at[static_cast<std::size_t>(m.sensor - 1)][static_cast<std::size_t>(m.attitude - 1)] = &m;
  }
  for (std::size_t i = 0; i < 6; ++i) {
    for (std::size_t j = 0; j < 6; ++j) {
      if (at[i][j] == nullptr) {
        return bad(file + ": no mean for sensor " + std::to_string(i + 1) + " in attitude " +
                   std::to_string(j + 1) + " (Tables 4/5 need all 36)");
      }
      p.mean_v[i][j] = at[i][j]->mean_v;
    }
  }
  CalibrationRun run;
  const auto t2 = calib::table2_attitudes<double>();
  const auto t3 = calib::table3_attitudes<double>();
  for (std::size_t j = 0; j < 6; ++j) {
    run.pose_f_b_g.push_back(t2[j]);
    run.pose_labels.push_back("T2." + std::to_string(j + 1));
    run.pose_used_mask.push_back(0x16);  // sensors 2, 3, 5
  }
  for (std::size_t j = 0; j < 6; ++j) {
    run.pose_f_b_g.push_back(t3[j]);
    run.pose_labels.push_back("T3." + std::to_string(j + 1));
    run.pose_used_mask.push_back(0x29);  // sensors 1, 4, 6
  }
  if (in.method == Method::kPaper) {
    auto r = calib::calibrate_paper_procedure<double>(p);
    if (!r.is_ok()) return solver_failure(r.status());
    run.result = r.value();
    run.method_text = "paper procedure: SF from eqs. (17)/(18), bias and angles by least squares";
    return run;
  }
  auto obs = calib::paper_observations<double>(p);
  for (std::size_t k = 0; k < obs.size(); ++k) {
    const auto& set = k < 6 ? nav::kSetBeta : nav::kSetAlpha;
    for (const int s : set) {
      set_sigma(obs[k], static_cast<std::size_t>(s), *at[static_cast<std::size_t>(s)][k % 6]);
    }
  }
  auto r = calib::calibrate_multi_attitude<double>(
      std::span<const calib::AttitudeObservation<double>>(obs.data(), obs.size()));
  if (!r.is_ok()) return solver_failure(r.status());
  run.result = r.value();
  run.method_text = "general solver: per-sensor least squares over the Table 2/3 poses";
  return run;
}

FileResult<CalibrationRun> run_with_poses(const CalibrationInputs& in, const std::string& file) {
  if (in.method == Method::kPaper) {
    return bad("the paper procedure needs the Table 2/3 poses; use --method general with --poses");
  }
  std::map<int, std::size_t> index;  // attitude number → observation
  std::vector<calib::AttitudeObservation<double>> obs;
  CalibrationRun run;
  for (const Pose& p : *in.poses) {
    index[p.attitude] = obs.size();
    calib::AttitudeObservation<double> o;
    o.f_b_g = p.f_b_g;
    o.used_mask = 0;
    obs.push_back(o);
    run.pose_f_b_g.push_back(p.f_b_g);
    run.pose_labels.push_back("P" + std::to_string(p.attitude));
  }
  for (const MeanRow& m : in.means) {
    const auto it = index.find(m.attitude);
    if (it == index.end()) {
      return bad(file + ":" + std::to_string(m.line) + ": attitude " + std::to_string(m.attitude) +
                 " is not in the poses file");
    }
    auto& o = obs[it->second];
    const auto s = static_cast<std::size_t>(m.sensor - 1);
    o.mean_v[s] = m.mean_v;
    o.used_mask = static_cast<std::uint8_t>(o.used_mask | (1u << s));
    set_sigma(o, s, m);
  }
  for (const auto& o : obs) run.pose_used_mask.push_back(o.used_mask);
  if (obs.size() > calib::kMaxAttitudes) {
    return bad("more than " + std::to_string(calib::kMaxAttitudes) + " poses");
  }
  auto r = calib::calibrate_multi_attitude<double>(
      std::span<const calib::AttitudeObservation<double>>(obs.data(), obs.size()));
  if (!r.is_ok()) return solver_failure(r.status());
  run.result = r.value();
  run.method_text =
      "general solver: per-sensor least squares over " + std::to_string(obs.size()) + " poses";
  return run;
}

std::string fmt(const char* format, double x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, x);
  return buf;
}

}  // namespace

FileResult<CalibrationRun> run_recording_calibration(const Recording& rec,
                                                     const std::optional<std::vector<Pose>>& poses,
                                                     const RecordingOptions& options,
                                                     const std::string& recording_file) {
  calib::StaticDetectorConfig<double> cfg;
  cfg.sample_rate_hz = options.rate_hz;
  cfg.window_s = options.window_s;
  cfg.min_still_s = options.min_still_s;
  cfg.max_std_v.fill(options.still_std_v);
  auto created = calib::StaticDetector<double>::create(cfg);
  if (!created.is_ok()) return bad(recording_file + ": " + created.status().message());
  calib::StaticDetector<double>& detector = created.value();
  for (const auto& sample : rec.samples_v) (void)detector.push(sample);
  (void)detector.finish();

  CalibrationRun run;
  const auto intervals = detector.intervals();
  run.notes.push_back(recording_file + ": " + std::to_string(rec.samples_v.size()) +
                      " samples at " + fmt("%g", options.rate_hz) + " Hz, " +
                      std::to_string(intervals.size()) + " static intervals, " +
                      std::to_string(detector.rejected().size()) + " poses rejected");
  for (const auto& r : detector.rejected()) {
    run.notes.push_back("rejected pose at " +
                        fmt("%.2f", static_cast<double>(r.start_index) / options.rate_hz) +
                        " s: " + calib::to_string(r.reason));
  }
  if (detector.dropped() > 0) {
    return bad(recording_file + ": more static intervals than the detector holds (" +
               std::to_string(calib::kMaxAttitudes) + ")");
  }

  std::vector<std::array<double, 3>> expected;
  std::vector<std::string> labels;
  if (poses) {
    for (const Pose& p : *poses) {
      expected.push_back(p.f_b_g);
      labels.push_back("P" + std::to_string(p.attitude));
    }
  } else {
    const auto t2 = calib::table2_attitudes<double>();
    const auto t3 = calib::table3_attitudes<double>();
    for (std::size_t j = 0; j < 6; ++j) {
      expected.push_back(t2[j]);
      labels.push_back("T2." + std::to_string(j + 1));
    }
    for (std::size_t j = 0; j < 6; ++j) {
      expected.push_back(t3[j]);
      labels.push_back("T3." + std::to_string(j + 1));
    }
  }
  calib::PoseAssignmentConfig<double> assign;
  assign.nominal_scale_v_per_g = options.nominal_scale_v_per_g;
  std::vector<calib::AttitudeObservation<double>> obs(intervals.size());
  std::vector<int> attitude_of(intervals.size(), -1);
  const auto n = calib::intervals_to_observations<double>(
      intervals, std::span<const std::array<double, 3>>(expected.data(), expected.size()), assign,
      std::span<calib::AttitudeObservation<double>>(obs.data(), obs.size()),
      std::span<int>(attitude_of.data(), attitude_of.size()));
  if (!n.is_ok()) return bad(recording_file + ": " + n.status().message());
  obs.resize(n.value());
  for (std::size_t k = 0; k < intervals.size(); ++k) {
    const auto& it = intervals[k];
    const int a = attitude_of[k];
    run.notes.push_back("interval " + std::to_string(k + 1) + ": " +
                        fmt("%.2f", static_cast<double>(it.start_index) / options.rate_hz) + "-" +
                        fmt("%.2f", static_cast<double>(it.end_index) / options.rate_hz) + " s, " +
                        (a >= 0 ? "pose " + labels[static_cast<std::size_t>(a)]
                                : std::string("no expected pose within 20 degrees: skipped")));
    if (a >= 0) {
      run.pose_labels.push_back(labels[static_cast<std::size_t>(a)]);
      run.pose_f_b_g.push_back(expected[static_cast<std::size_t>(a)]);
      run.pose_used_mask.push_back(calib::kAllSensors);
    }
  }
  auto r = calib::calibrate_multi_attitude<double>(
      std::span<const calib::AttitudeObservation<double>>(obs.data(), obs.size()));
  if (!r.is_ok()) return solver_failure(r.status());
  run.result = r.value();
  run.method_text = "general solver over " + std::to_string(obs.size()) +
                    " static intervals of a recording (weighted by their sample noise)";
  return run;
}

FileResult<CalibrationRun> run_calibration(const CalibrationInputs& in,
                                           const std::string& means_file) {
  return in.poses ? run_with_poses(in, means_file) : run_paper_layout(in, means_file);
}

calib_file::CalibrationData make_calibration_data(const CalibrationRun& run,
                                                  const FileSettings& settings) {
  const auto& r = run.result;
  calib_file::CalibrationData d;
  d.device_id = settings.device_id;
  d.created_utc = calib_file::utc_now_iso8601();
  d.source = settings.source;
  d.geometry = settings.geometry;
  d.compensator = settings.compensator;
  for (std::size_t j = 0; j < 6; ++j) {
    auto& s = d.sensors[j];
    s.adc_lsb_v_per_count = settings.adc_lsb_v_per_count[j];
    s.scale_v_per_g = r.scale_v_per_g[j];
    s.scale_sigma_v_per_g = r.scale_std_v_per_g[j];
    s.bias_g = r.bias_g[j];
    s.bias_sigma_g = r.bias_std_g[j];
    s.location_error_m = settings.location[j].location_error_m;
    s.location_error_sigma_m = settings.location[j].location_error_sigma_m;
  }
  for (std::size_t i = 0; i < 6; ++i) {
    d.beta.angle_deg[i] = r.orientation.beta[i] * kDegPerRad;
    d.alpha.angle_deg[i] = r.orientation.alpha[i] * kDegPerRad;
    d.beta.angle_sigma_deg[i] = r.orientation_std.beta[i] * kDegPerRad;
    d.alpha.angle_sigma_deg[i] = r.orientation_std.alpha[i] * kDegPerRad;
  }
  return d;
}

std::vector<std::string> verdict_warnings(const calib::MultiAttitudeResult<double>& r) {
  std::vector<std::string> w;
  for (std::size_t j = 0; j < 6; ++j) {
    const std::uint8_t f = r.sensor_flags[j];
    const std::string s = "sensor " + std::to_string(j + 1) + ": ";
    if (f & calib::kFlagNegativeScaleFactor) {
      w.push_back(s +
                  "negative scale factor (wiring reversed, or gravity given instead of the "
                  "specific force sensed)");
    }
    if (f & calib::kFlagLargeAngle)
      w.push_back(s + "orientation error beyond the small-angle model");
    if (f & calib::kFlagHighResidual) {
      w.push_back(s + "RMS residual " + fmt("%.3g", r.rms_residual_g[j] * 1e3) +
                  " mg: the poses or the means are inconsistent");
    }
    if (f & calib::kFlagResidualsExceedNoise) {
      w.push_back(s + "residuals exceed the stated noise (chi2/dof " +
                  fmt("%.3g", r.chi2_per_dof[j]) + ")");
    }
    if (f & calib::kFlagNoRedundancy) {
      w.push_back(s + "exactly determined: nothing checks the fit, uncertainty unknown");
    }
  }
  return w;
}

void print_report(std::ostream& out, const CalibrationRun& run) {
  const auto& r = run.result;
  for (const std::string& n : run.notes) out << n << "\n";
  out << "method: " << run.method_text << "\n"
      << "poses: " << r.num_attitudes
      << ", largest condition number of a sensor's design: " << fmt("%.3g", r.max_condition_number)
      << "\n\n";
  out << "sensor set   SF (V/g)              bias (g)                RMS resid (mg)  cond   "
         "uncertainty from\n";
  for (std::size_t j = 0; j < 6; ++j) {
    const bool beta = in_set(nav::kSetBeta, static_cast<int>(j));
    out << "a" << j + 1 << "     " << (beta ? "beta " : "alpha") << "  "
        << fmt("%9.6f", r.scale_v_per_g[j]) << " ± " << fmt("%-9.2g", r.scale_std_v_per_g[j]) << " "
        << fmt("%10.7f", r.bias_g[j]) << " ± " << fmt("%-9.2g", r.bias_std_g[j]) << "  "
        << fmt("%10.4f", r.rms_residual_g[j] * 1e3) << "  " << fmt("%5.2f", r.condition_number[j])
        << "  " << calib::to_string(r.covariance_source[j]) << "\n";
  }
  out << "\norientation errors (deg, ± 1σ), paper eqs. (14)/(15), Table 6 order\n";
  const auto angles = [&](const char* name, const std::array<double, 6>& a,
                          const std::array<double, 6>& sd) {
    for (std::size_t i = 0; i < 6; ++i) {
      out << "  Δ" << name << "_" << kAngleNames[i] << " " << fmt("%10.6f", a[i] * kDegPerRad)
          << " ± " << fmt("%.2g", sd[i] * kDegPerRad) << "\n";
    }
  };
  angles("β", r.orientation.beta, r.orientation_std.beta);
  angles("α", r.orientation.alpha, r.orientation_std.alpha);

  out << "\nresiduals (mV), measured − model; '-' where the sensor was not recorded\n"
      << "pose     f_b (g)                     a1       a2       a3       a4       a5       a6\n";
  for (std::size_t k = 0; k < r.num_attitudes && k < run.pose_labels.size(); ++k) {
    const auto& f = run.pose_f_b_g[k];
    char head[80];
    std::snprintf(head, sizeof head, "%-7s [%6.3f %6.3f %6.3f]  ", run.pose_labels[k].c_str(), f[0],
                  f[1], f[2]);
    out << head;
    for (std::size_t j = 0; j < 6; ++j) {
      const bool used = (run.pose_used_mask[k] >> j) & 1u;
      out << (used ? fmt("%8.4f", r.residual_v[k][j] * 1e3) : std::string("       -")) << " ";
    }
    out << "\n";
  }
  out << "\nverdict: " << calib::to_string(r.verdict) << "\n";
  for (const std::string& w : verdict_warnings(r)) out << "  warning: " << w << "\n";
}

}  // namespace gfins::tools
