#include "calibrate.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>
#include <span>

#include "gfins/nav_core/filter/chi_square.hpp"

namespace gfins::tools {
namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;
constexpr std::array<const char*, 6> kAngleNames = {"xy", "xz", "yx", "yz", "zx", "zy"};

bool in_set(const std::array<int, 3>& set, int sensor0) {
  return set[0] == sensor0 || set[1] == sensor0 || set[2] == sensor0;
}

// The solver's Status, lifted with the words the exit status of gfins-calibrate keys on.
HostError solver_failure(const Status& s) {
  return sim::host_error(s, std::string("calibration failed (") + to_string(s.code()) + "): ");
}

// σ of a mean: std/√count, passed to the solver as a σ with count 1 so rows may differ in count.
void set_sigma(calib::AttitudeObservation<double>& o, std::size_t sensor0, const MeanRow& m) {
  if (m.count == 0) return;
  o.sample_std_v[sensor0] = m.std_v / std::sqrt(static_cast<double>(m.count));
  o.sample_count = 1;
}

HostResult<CalibrationRun> run_paper_layout(const CalibrationInputs& in, const std::string& file) {
  // Tables 4/5: every sensor in attitudes 1..6 of its set's table (2 for β, 3 for α).
  calib::PaperTableOutputs<double> p;
  std::array<std::array<const MeanRow*, 6>, 6> at{};
  for (const MeanRow& m : in.means) {
    if (m.attitude > 6) {
      return sim::invalid_argument(
          file + ":" + std::to_string(m.line) + ": attitude " + std::to_string(m.attitude) +
          " does not exist in Tables 2/3 (1..6); give a poses file (--poses) for other poses");
    }
    at[static_cast<std::size_t>(m.sensor - 1)][static_cast<std::size_t>(m.attitude - 1)] = &m;
  }
  for (std::size_t i = 0; i < 6; ++i) {
    for (std::size_t j = 0; j < 6; ++j) {
      if (at[i][j] == nullptr) {
        return sim::invalid_argument(file + ": no mean for sensor " + std::to_string(i + 1) +
                                     " in attitude " + std::to_string(j + 1) +
                                     " (Tables 4/5 need all 36)");
      }
      p.mean_v[i][j] = at[i][j]->mean_v;
      // σ of the mean from std_v and count where given: both routes use it.
      if (at[i][j]->count > 0) {
        p.sigma_v[i][j] = at[i][j]->std_v / std::sqrt(static_cast<double>(at[i][j]->count));
      }
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

HostResult<CalibrationRun> run_with_poses(const CalibrationInputs& in, const std::string& file) {
  if (in.method == Method::kPaper) {
    return sim::invalid_argument(
        "the paper procedure needs the Table 2/3 poses; use --method general with --poses");
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
      return sim::invalid_argument(file + ":" + std::to_string(m.line) + ": attitude " +
                                   std::to_string(m.attitude) + " is not in the poses file");
    }
    auto& o = obs[it->second];
    const auto s = static_cast<std::size_t>(m.sensor - 1);
    o.mean_v[s] = m.mean_v;
    o.used_mask = static_cast<std::uint8_t>(o.used_mask | (1u << s));
    set_sigma(o, s, m);
  }
  for (const auto& o : obs) run.pose_used_mask.push_back(o.used_mask);
  if (obs.size() > calib::kMaxAttitudes) {
    return sim::invalid_argument("more than " + std::to_string(calib::kMaxAttitudes) + " poses");
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

// P(|t| <= 3) for Student's t with `dof` degrees of freedom: twice the density integrated over
// [0, 3] (Simpson, 600 intervals: the density is smooth there, error far below the 0.1 % shown).
double student_t_within_3(int dof) {
  const double nu = dof;
  const double c = std::exp(std::lgamma((nu + 1.0) / 2.0) - std::lgamma(nu / 2.0)) /
                   std::sqrt(nu * std::numbers::pi);
  const auto pdf = [&](double t) { return c * std::pow(1.0 + t * t / nu, -(nu + 1.0) / 2.0); };
  constexpr int kIntervals = 600;
  const double h = 3.0 / kIntervals;
  double sum = pdf(0.0) + pdf(3.0);
  for (int i = 1; i < kIntervals; ++i) sum += (i % 2 == 1 ? 4.0 : 2.0) * pdf(i * h);
  return 2.0 * sum * h / 3.0;
}

// Which σ the ± figures below are: the report says it once, in words, for all sensors. With σ
// from the residuals, how many degrees of freedom each sensor's fit had (its poses − 4 unknowns)
// and what a Student-t with that many puts within 3σ: few poses per sensor make such σ weak.
std::string sigma_statement(const CalibrationRun& run) {
  const calib::MultiAttitudeResult<double>& r = run.result;
  int stated = 0;
  int residual = 0;
  for (const auto src : r.covariance_source) {
    stated += src == calib::CovarianceSource::kStatedSigma ? 1 : 0;
    residual += src == calib::CovarianceSource::kResiduals ? 1 : 0;
  }
  if (stated == 6) {
    return "uncertainties (± 1σ): from the stated σ of every mean (std_v/√count of the input), "
           "propagated through the fit";
  }
  if (residual == 6) {
    std::size_t lo = r.num_attitudes;
    std::size_t hi = 0;
    for (std::size_t j = 0; j < 6; ++j) {
      std::size_t n = 0;
      for (const std::uint8_t mask : run.pose_used_mask) n += (mask >> j) & 1u;
      lo = std::min(lo, n);
      hi = std::max(hi, n);
    }
    const std::string poses =
        lo == hi ? std::to_string(lo) : std::to_string(lo) + ".." + std::to_string(hi);
    const int dof_lo = static_cast<int>(lo) - 4;
    std::string coverage = "no redundancy: nothing to estimate them from";
    if (dof_lo > 0) {
      coverage = "a Student-t with " + std::to_string(dof_lo) + " dof puts " +
                 fmt("%.1f", 100.0 * student_t_within_3(dof_lo)) +
                 " % of true values within 3σ, a Gaussian 99.7 %";
    }
    return "uncertainties (± 1σ): no σ stated with the means, so from the fit residuals: each "
           "sensor is fitted from " +
           poses + " of the " + std::to_string(r.num_attitudes) + " poses, 4 unknowns, so " +
           (lo == hi ? "" : "at least ") + std::to_string(dof_lo) + " degrees of freedom (" +
           coverage +
           "); give std_v and count for honest "
           "uncertainties";
  }
  return "uncertainties (± 1σ): per sensor as the last column says (stated σ where every mean "
         "of the sensor has one, else residuals)";
}

}  // namespace

namespace {

std::string channel_list(std::uint8_t mask) {
  std::string out;
  for (int j = 0; j < 6; ++j) {
    if ((mask >> j) & 1u) out += (out.empty() ? "" : ", ") + std::to_string(j + 1);
  }
  return out;
}

std::string span_text(std::uint64_t start, std::uint64_t end, double rate_hz) {
  return fmt("%.2f", static_cast<double>(start) / rate_hz) + "-" +
         fmt("%.2f", static_cast<double>(end) / rate_hz) + " s";
}

// Why a pose the detector rejected cannot be used, in the user's terms.
std::string rejection_text(const calib::RejectedPose<double>& r, const RecordingOptions& o) {
  if (r.reason == calib::PoseRejection::kTooNoisy) {
    double worst = 0.0;
    for (std::size_t c = 0; c < 6; ++c) {
      if ((r.noisy_channels >> c) & 1u) worst = std::max(worst, r.std_v[c]);
    }
    return "the board moved (or vibrated) during it: channel(s) " + channel_list(r.noisy_channels) +
           " have a standard deviation up to " + fmt("%.3g", worst * 1e3) +
           " mV, above the still limit " + fmt("%.3g", o.still_std_v * 1e3) + " mV (--still-std-v)";
  }
  return "held still for only " + fmt("%.2f", static_cast<double>(r.count) / o.rate_hz) +
         " s, less than the " + fmt("%.3g", o.min_still_s) + " s a pose needs";
}

}  // namespace

HostResult<CalibrationRun> run_recording_calibration(const Recording& rec,
                                                     const std::optional<std::vector<Pose>>& poses,
                                                     const RecordingOptions& options_in,
                                                     const std::string& recording_file) {
  RecordingOptions options = options_in;
  if (!(options.rate_hz > 0.0)) options.rate_hz = rec.rate_hz;
  if (!(options.rate_hz > 0.0)) {
    return sim::invalid_argument(recording_file +
                                 ": the sample rate is unknown: give --rate (Hz) for a CSV "
                                 "recording");
  }
  calib::StaticDetectorConfig<double> cfg;
  cfg.sample_rate_hz = options.rate_hz;
  cfg.window_s = options.window_s;
  cfg.min_still_s = options.min_still_s;
  cfg.max_std_v.fill(options.still_std_v);
  auto created = calib::StaticDetector<double>::create(cfg);
  if (!created.is_ok())
    return sim::invalid_argument(recording_file + ": " + created.status().message());
  calib::StaticDetector<double>& detector = created.value();
  for (const auto& sample : rec.samples_v) (void)detector.push(sample);
  (void)detector.finish();
  if (detector.dropped() > 0) {
    return sim::invalid_argument(recording_file +
                                 ": more static intervals than the detector holds (" +
                                 std::to_string(calib::kMaxAttitudes) + ")");
  }

  // Every pose the detector found or rejected, with the reason a pose cannot be used: it moved
  // or was too short (the detector), or a channel saturated / a frame failed its CRC inside it
  // (the recording's flags). A refused pose is left out; the others are used.
  CalibrationRun run;
  std::vector<std::string> refused;
  for (const auto& r : detector.rejected()) {
    refused.push_back("pose at " + span_text(r.start_index, r.end_index, options.rate_hz) +
                      " refused: " + rejection_text(r, options));
  }
  std::vector<calib::StaticInterval<double>> usable;
  const auto intervals = detector.intervals();
  for (const auto& it : intervals) {
    std::uint8_t sat = 0;
    std::uint64_t n_sat = 0;
    std::uint64_t n_crc = 0;
    for (std::uint64_t k = it.start_index; k < it.end_index && k < rec.saturated_mask.size(); ++k) {
      const auto i = static_cast<std::size_t>(k);  // < size(): fits size_t on 32-bit boards too
      sat = static_cast<std::uint8_t>(sat | rec.saturated_mask[i]);
      n_sat += rec.saturated_mask[i] != 0 ? 1 : 0;
      n_crc += rec.crc_error[i];
    }
    const std::string where = "pose at " + span_text(it.start_index, it.end_index, options.rate_hz);
    if (sat != 0) {
      refused.push_back(where + " refused: channel(s) " + channel_list(sat) +
                        " saturated (ADC code at full scale) in " + std::to_string(n_sat) +
                        " samples: the output is clipped, its mean is not the sensor's");
    } else if (n_crc > 0) {
      refused.push_back(where + " refused: " + std::to_string(n_crc) +
                        " ADC frames with a CRC error inside it: its samples are not all valid");
    } else {
      usable.push_back(it);
    }
  }
  run.notes.push_back(recording_file + ": " + std::to_string(rec.samples_v.size()) +
                      " samples at " + fmt("%g", options.rate_hz) + " Hz, " +
                      std::to_string(intervals.size()) + " static intervals, " +
                      std::to_string(usable.size()) + " usable, " + std::to_string(refused.size()) +
                      " poses refused");
  for (const auto& r : refused) run.notes.push_back(r);
  if (usable.size() < calib::kMinAttitudes) {
    std::string what = recording_file + ": " + std::to_string(usable.size()) +
                       " usable still intervals, at least " + std::to_string(calib::kMinAttitudes) +
                       " non-coplanar poses are needed.";
    what += "\n  still intervals found:";
    if (intervals.empty()) what += " none";
    for (const auto& it : intervals) {
      what += "\n    " + span_text(it.start_index, it.end_index, options.rate_hz);
    }
    what += "\n  poses refused:";
    if (refused.empty()) what += " none";
    for (const auto& r : refused) what += "\n    " + r;
    return sim::invalid_argument(what);
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
  std::vector<calib::AttitudeObservation<double>> obs(usable.size());
  std::vector<int> attitude_of(usable.size(), -1);
  const auto assign_all = [&]() -> Status {
    obs.assign(usable.size(), {});
    attitude_of.assign(usable.size(), -1);
    const auto n = calib::intervals_to_observations<double>(
        std::span<const calib::StaticInterval<double>>(usable.data(), usable.size()),
        std::span<const std::array<double, 3>>(expected.data(), expected.size()), assign,
        std::span<calib::AttitudeObservation<double>>(obs.data(), obs.size()),
        std::span<int>(attitude_of.data(), attitude_of.size()));
    if (n.is_ok()) obs.resize(n.value());
    return n.status();
  };
  if (const Status st = assign_all(); !st.is_ok()) {
    return sim::invalid_argument(recording_file + ": " + st.message());
  }
  // Two intervals nearest to one expected pose: a repeat of that pose (their directions agree
  // within kRepeatDeg, far above the repositioning of a fixture, far below the 45° between the
  // poses of Tables 2/3) is kept; otherwise only the closer one is that pose, and the other (a
  // verification pose, say, 20-30° away) would enter the fit with the wrong attitude: skipped.
  constexpr double kRepeatDeg = 5.0;
  std::vector<nav::Vec3<double>> direction(usable.size());
  for (std::size_t k = 0; k < usable.size(); ++k) {
    direction[k] = calib::specific_force_estimate<double>(usable[k], assign).normalized();
  }
  const auto degrees = [](const nav::Vec3<double>& a, const nav::Vec3<double>& b) {
    return std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / std::numbers::pi;
  };
  std::vector<std::string> not_repeats(usable.size());
  for (std::size_t k = 0; k < usable.size(); ++k) {
    if (attitude_of[k] < 0) continue;
    const auto a = static_cast<std::size_t>(attitude_of[k]);
    const nav::Vec3<double> e = nav::Vec3<double>(expected[a][0], expected[a][1], expected[a][2]);
    for (std::size_t m = 0; m < usable.size(); ++m) {
      if (m == k || attitude_of[m] != attitude_of[k]) continue;
      const double dk = degrees(direction[k], e);
      const double dm = degrees(direction[m], e);
      const double apart = degrees(direction[k], direction[m]);
      if (apart > kRepeatDeg && (dk > dm || (dk == dm && k > m))) {
        not_repeats[k] = "nearest to pose " + labels[a] + " (" + fmt("%.1f", dk) +
                         " degrees) but " + fmt("%.1f", apart) + " degrees from interval " +
                         std::to_string(m + 1) + ", which is closer to it: not that pose, skipped";
      }
    }
  }
  std::vector<calib::StaticInterval<double>> all = usable;
  std::vector<std::string> fate(usable.size());
  {
    std::vector<calib::StaticInterval<double>> kept;
    for (std::size_t k = 0; k < all.size(); ++k) {
      if (not_repeats[k].empty()) kept.push_back(all[k]);
    }
    if (kept.size() != all.size()) {
      usable = kept;
      if (const Status st = assign_all(); !st.is_ok()) {
        return sim::invalid_argument(recording_file + ": " + st.message());
      }
    }
  }
  for (std::size_t k = 0, u = 0; k < all.size(); ++k) {
    const auto& it = all[k];
    const int a = not_repeats[k].empty() ? attitude_of[u++] : -1;
    const std::string what = !not_repeats[k].empty() ? not_repeats[k]
                             : a >= 0                ? "pose " + labels[static_cast<std::size_t>(a)]
                                      : std::string("no expected pose within 20 degrees: skipped");
    run.notes.push_back("interval " + std::to_string(k + 1) + ": " +
                        span_text(it.start_index, it.end_index, options.rate_hz) + ", " + what);
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

HostResult<CalibrationRun> run_calibration(const CalibrationInputs& in,
                                           const std::string& means_file) {
  return in.poses ? run_with_poses(in, means_file) : run_paper_layout(in, means_file);
}

namespace {

// What the file says about sensor j's σ (sensor.N.sigma_source): stated, from the residuals of
// its fit (poses that used it, minus the 4 unknowns), or not estimated.
calib_file::SigmaSource sigma_source_of(const CalibrationRun& run, std::size_t j) {
  switch (run.result.covariance_source[j]) {
    case calib::CovarianceSource::kStatedSigma:
      return {calib_file::SigmaBasis::kStated, 0};
    case calib::CovarianceSource::kResiduals: {
      std::int32_t poses = 0;
      for (const std::uint8_t mask : run.pose_used_mask) poses += (mask >> j) & 1u;
      return {calib_file::SigmaBasis::kResiduals, std::max(1, poses - 4)};
    }
    case calib::CovarianceSource::kNone:
      break;
  }
  return {calib_file::SigmaBasis::kNone, 0};
}

}  // namespace

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
    // The solver's 4×4 covariance is over (SF, b, angle 2r, angle 2r+1): the order of
    // calib_file::sensor_angles() and of the file's correlation keys (format version 3).
    const auto& c = r.covariance[j];
    const auto cov = [&c](std::size_t a, std::size_t b) { return c[a * 4 + b]; };
    const std::array<std::array<std::size_t, 2>, 6> pairs = {
        {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}}};
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      const double den = std::sqrt(cov(pairs[k][0], pairs[k][0]) * cov(pairs[k][1], pairs[k][1]));
      // No covariance (exactly determined, no σ stated): nothing is known, 0 is written.
      s.correlation[k] =
          den > 0.0 ? std::clamp(cov(pairs[k][0], pairs[k][1]) / den, -1.0, 1.0) : 0.0;
    }
    s.sigma_source = sigma_source_of(run, j);
  }
  d.gravity_mps2 = settings.gravity_mps2;
  d.gravity_source = settings.gravity_source;
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
  out << sigma_statement(run) << "\n\n";
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

HostStatus check_settings(const FileSettings& settings) {
  // A trial file with these settings and neutral calibrated values: the file's own validation
  // (docs/calibration-file.md, ranges) names the first setting it would refuse.
  calib_file::CalibrationData d;
  d.device_id = settings.device_id;
  d.created_utc = "2000-01-01T00:00:00Z";
  d.geometry = settings.geometry;
  d.gravity_mps2 = settings.gravity_mps2;
  d.gravity_source = settings.gravity_source;
  for (std::size_t j = 0; j < 6; ++j) {
    d.sensors[j].adc_lsb_v_per_count = settings.adc_lsb_v_per_count[j];
    d.sensors[j].scale_v_per_g = 1.0;
    d.sensors[j].location_error_m = settings.location[j].location_error_m;
    d.sensors[j].location_error_sigma_m = settings.location[j].location_error_sigma_m;
  }
  const calib_file::Problem p = calib_file::validate(d);
  if (!p.found()) return Done{};
  std::string option = p.key;
  if (p.key == "device_id") option = "--device-id";
  if (p.key.find("adc_lsb") != std::string::npos) option = "--adc-lsb";
  if (p.key == "geometry.rho_m") option = "--rho";
  if (p.key.rfind("gravity.", 0) == 0) option = "--gravity / --latitude";
  return sim::invalid_argument(option + " (" + p.key + "): " + p.problem);
}

namespace {

// The covariance the file states for sensor j's own parameters (SF [V/g], b [g], angle a1 [rad],
// angle a2 [rad]; a1, a2 the row of C of eqs. (14)/(15) it owns, calib_file::sensor_angles()):
// Σ_j = D R D, D the σ, R the correlations of SensorCalibration::correlation in the order
// (SF,b) (SF,a1) (SF,a2) (b,a1) (b,a2) (a1,a2). A file older than format version 3 carries
// zeros there (correlations_known false): R = I, "correlations unknown: taken as 0".
Eigen::Matrix4d sensor_parameter_cov(const calib_file::CalibrationData& cal, std::size_t j) {
  const auto& s = cal.sensors[j];
  const calib_file::SensorAngles angles = calib_file::sensor_angles(j);
  const auto& angle_sigma = angles.alpha ? cal.alpha.angle_sigma_deg : cal.beta.angle_sigma_deg;
  const Eigen::Vector4d sd(s.scale_sigma_v_per_g, s.bias_sigma_g,
                           angle_sigma[angles.angle[0]] * calib_file::kRadPerDeg,
                           angle_sigma[angles.angle[1]] * calib_file::kRadPerDeg);
  Eigen::Matrix4d r = Eigen::Matrix4d::Identity();
  const std::array<std::array<Eigen::Index, 2>, 6> pairs = {
      {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}}};
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    r(pairs[k][0], pairs[k][1]) = s.correlation[k];
    r(pairs[k][1], pairs[k][0]) = s.correlation[k];
  }
  return sd.asDiagonal() * r * sd.asDiagonal();
}

// ∂θ*_j/∂a (per radian) for sensor j's two angles a1, a2: θ*_j = Σ_k C_rk θ_k (eqs. (14)/(15),
// r its row in its set) and C is affine in its angles, so ∂C/∂a = C(e_a) − I exactly.
std::array<nav::Vec3<double>, 2> axis_derivatives(std::size_t j,
                                                  const nav::ArrayGeometry<double, 6>& nominal) {
  const calib_file::SensorAngles angles = calib_file::sensor_angles(j);
  const auto& set = angles.alpha ? nav::kSetAlpha : nav::kSetBeta;
  std::size_t row = 0;
  for (std::size_t r = 0; r < 3; ++r) {
    if (static_cast<std::size_t>(set[r]) == j) row = r;
  }
  std::array<nav::Vec3<double>, 2> out{};
  for (std::size_t m = 0; m < 2; ++m) {
    std::array<double, 6> unit{};
    unit[angles.angle[m]] = 1.0;
    const nav::Mat3<double> dc = nav::set_matrix(unit) - nav::Mat3<double>::Identity();
    out[m].setZero();
    for (std::size_t k = 0; k < 3; ++k) {
      out[m] += dc(static_cast<Eigen::Index>(row), static_cast<Eigen::Index>(k)) *
                nominal.theta_b[static_cast<std::size_t>(set[k])];
    }
  }
  return out;
}

// Covariance of sensor j's generic base perturbations (calib::kBaseOffset, kBaseGain, kBaseAxis)
// from the file's σ and correlations of its (SF, b, angle a1, angle a2) (docs/calibration.md,
// location σ). With T = ∂(c, k, δθ)/∂(SF, b, a1, a2), first order in the errors of eq. (21)
// s* = (P/SF − b)·g and of θ*_j = Σ_k C_rk θ_k (eqs. (14)/(15)):
//   SF → SF(1 + ε), ε = δSF/SF: s* → s* − ε(s* + b g), i.e. k = −ε, c = −ε b g;
//   b → b + δb:     c = −g δb;
//   angle a:        δθ = Σ_k ∂C_rk/∂a θ_k.
// Returns T Σ Tᵀ with Σ = sensor_parameter_cov().
Eigen::Matrix<double, calib::kNumBaseParams, calib::kNumBaseParams> base_perturbation_cov(
    const calib_file::CalibrationData& cal, std::size_t j,
    const nav::ArrayGeometry<double, 6>& nominal) {
  const auto& s = cal.sensors[j];
  const double g = cal.gravity_mps2;
  Eigen::Matrix<double, calib::kNumBaseParams, 4> t =
      Eigen::Matrix<double, calib::kNumBaseParams, 4>::Zero();
  t(calib::kBaseOffset, 0) = -s.bias_g * g / s.scale_v_per_g;
  t(calib::kBaseGain, 0) = -1.0 / s.scale_v_per_g;
  t(calib::kBaseOffset, 1) = -g;
  const auto d_theta = axis_derivatives(j, nominal);
  for (std::size_t m = 0; m < 2; ++m) {
    t.block<3, 1>(calib::kBaseAxis, static_cast<Eigen::Index>(2 + m)) = d_theta[m];
  }
  return t * sensor_parameter_cov(cal, j) * t.transpose();
}

}  // namespace

HostResult<LocationReport> run_location_calibration(const std::vector<LocationRunRow>& rows,
                                                    const calib_file::CalibrationData& cal,
                                                    double prior_sigma_m,
                                                    const std::string& runs_file) {
  // θ*_j from the orientation calibration (eqs. (14)/(15)), ρ_j nominal: what §4.2 assumes known.
  nav::Misalignment<double> orientation = calib_file::misalignment<double>(cal);
  for (auto& d : orientation.drho_b) d.setZero();
  const auto calibrated =
      nav::misaligned_geometry(calib_file::nominal_geometry<double>(cal), orientation);
  const double g = cal.gravity_mps2;  // the g of V/g: outputs → m/s² as the front end does
  std::vector<calib::LocationRun<double>> runs;
  for (const LocationRunRow& row : rows) {
    calib::LocationRun<double> r;
    const nav::Vec3<double> up =
        nav::Vec3<double>(row.axis_up_b[0], row.axis_up_b[1], row.axis_up_b[2]).normalized();
    r.w_b = row.rate_rad_s * up;
    r.g_b = -g * up;  // table axis vertical, pointing up: gravity is down along it
    r.mounting = row.mounting;
    for (int j = 0; j < 6; ++j) {
      const auto& sj = cal.sensors[static_cast<std::size_t>(j)];
      // eq. (21): s*_j = (P/SF − b)·g, and its per-sample σ.
      r.s_mean(j) = (row.mean_v[static_cast<std::size_t>(j)] / sj.scale_v_per_g - sj.bias_g) * g;
      r.sigma(j) = row.std_v[static_cast<std::size_t>(j)] / sj.scale_v_per_g * g;
    }
    r.count = row.count;
    runs.push_back(r);
  }
  const auto solved = calib::calibrate_location<double>(
      calibrated, std::span<const calib::LocationRun<double>>(runs.data(), runs.size()));
  if (!solved.is_ok()) {
    return sim::host_error(solved.status(), runs_file + ": location calibration failed (" +
                                                to_string(solved.status().code()) + "): ");
  }
  LocationReport rep;
  rep.solution = solved.value();
  const auto& sol = rep.solution;
  // The base calibration's uncertainty, first order: Σ_j J_ij C_j J_ijᵀ (docs/calibration.md).
  std::array<Eigen::Matrix<double, calib::kNumBaseParams, calib::kNumBaseParams>, 6> base_cov{};
  const auto nominal = calib_file::nominal_geometry<double>(cal);
  for (std::size_t j = 0; j < 6; ++j) base_cov[j] = base_perturbation_cov(cal, j, nominal);
  rep.base_cov_m2 = calib::base_covariance(sol, base_cov);
  rep.lines.push_back("location errors (paper §4.2) from " + std::to_string(rows.size()) +
                      " rate-table runs in " + std::to_string(sol.num_mountings) +
                      " mounting(s); chi2/dof " +
                      fmt("%.3g", sol.dof > 0 ? sol.chi2 / sol.dof : 0.0) + " (" +
                      std::to_string(sol.dof) + " dof, the runs' noise alone)");
  rep.lines.push_back(
      std::string("sigma = the runs' noise (their std_v/sqrt(count)) and the base calibration's "
                  "uncertainty (its sigma of SF, bias and angles") +
      (cal.correlations_known
           ? " and their correlations"
           : "; its file predates format version 3 and states no correlations: taken as 0") +
      ", propagated to first order); the last column splits it as sigma_runs / sigma_base (mm, "
      "largest component)");
  std::string no_sigma;  // sensors whose base states no uncertainty at all
  for (std::size_t j = 0; j < 6; ++j) {
    if (base_cov[j].isZero(0.0)) no_sigma += " a" + std::to_string(j + 1);
  }
  if (!no_sigma.empty()) {
    rep.lines.push_back("  note: the base states sigma = 0 for SF, bias and angles of" + no_sigma +
                        " (an exactly determined calibration without stated sigma): their "
                        "uncertainty cannot be counted, the sigma below is the runs' alone");
  }
  rep.lines.push_back(
      "sensor  drho_x (mm)          drho_y (mm)          drho_z (mm)          runs / base"
      "           not observable");
  for (std::size_t j = 0; j < 6; ++j) {
    // Unobservable directions are held at 0; their σ is the mechanical prior, not the data's.
    nav::Mat3<double> cov = sol.drho_cov_m2[j] + rep.base_cov_m2[j];
    const nav::Vec3<double> dir = sol.unobservable_dir_b[j];
    if (sol.unobservable_dims[j] > 0) cov += prior_sigma_m * prior_sigma_m * dir * dir.transpose();
    std::string line = "a" + std::to_string(j + 1) + "     ";
    for (int k = 0; k < 3; ++k) {
      rep.drho_m[j][static_cast<std::size_t>(k)] = sol.drho_b[j](k);
      rep.sigma_m[j][static_cast<std::size_t>(k)] = std::sqrt(std::max(0.0, cov(k, k)));
      line += fmt(" %8.4f", sol.drho_b[j](k) * 1e3) + " ± " +
              fmt("%-8.2g", rep.sigma_m[j][static_cast<std::size_t>(k)] * 1e3);
    }
    const double sd_runs = std::sqrt(std::max(0.0, sol.drho_cov_m2[j].diagonal().maxCoeff()));
    const double sd_base = std::sqrt(std::max(0.0, rep.base_cov_m2[j].diagonal().maxCoeff()));
    line += "  " + fmt("%.2g", sd_runs * 1e3) + " / " + fmt("%-8.2g", sd_base * 1e3);
    if (sol.unobservable_dims[j] > 0) {
      line += "  " + std::to_string(sol.unobservable_dims[j]) + " direction(s), e.g. [" +
              fmt("%.2f", dir.x()) + " " + fmt("%.2f", dir.y()) + " " + fmt("%.2f", dir.z()) +
              "]: held at 0, sigma = prior " + fmt("%.3g", prior_sigma_m * 1e3) + " mm";
    } else {
      line += "  none";
    }
    rep.lines.push_back(line);
  }
  if (!sol.fully_observable()) {
    rep.lines.push_back(
        "  note: runs about body x, y, z alone never see the radial component of a sensor's "
        "offset; add the two face-diagonal mountings (docs/calibration.md, location runs)");
  }
  return rep;
}

namespace {

/// I_x(a, b), the regularized incomplete beta function (0 ≤ x ≤ 1, a, b > 0): the continued
/// fraction of Abramowitz & Stegun 26.5.8 by the modified Lentz method, on the side where it
/// converges fast (x < (a + 1) / (a + b + 2)), the symmetry I_x(a, b) = 1 − I_{1−x}(b, a) on the
/// other.
double incomplete_beta(double x, double a, double b) {
  if (x <= 0.0) return 0.0;
  if (x >= 1.0) return 1.0;
  if (x > (a + 1.0) / (a + b + 2.0)) return 1.0 - incomplete_beta(1.0 - x, b, a);
  const double log_front =
      std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b) + a * std::log(x) + b * std::log1p(-x);
  constexpr double kTiny = 1e-300;
  double c = 1.0, d = 1.0 - (a + b) * x / (a + 1.0);
  if (std::abs(d) < kTiny) d = kTiny;
  d = 1.0 / d;
  double f = d;
  for (int m = 1; m <= 1000; ++m) {
    const double md = m;
    for (const double num : {md * (b - md) * x / ((a + 2 * md - 1) * (a + 2 * md)),
                             -(a + md) * (a + b + md) * x / ((a + 2 * md) * (a + 2 * md + 1))}) {
      d = 1.0 + num * d;
      if (std::abs(d) < kTiny) d = kTiny;
      c = 1.0 + num / c;
      if (std::abs(c) < kTiny) c = kTiny;
      d = 1.0 / d;
      f *= c * d;
    }
    if (std::abs(c * d - 1.0) < 1e-15) break;
  }
  return std::exp(log_front) * f / a;
}

}  // namespace

double student_t_two_sided_p(double t, double dof) {
  if (!std::isfinite(dof)) return std::erfc(std::abs(t) / std::sqrt(2.0));
  return incomplete_beta(dof / (dof + t * t), dof / 2.0, 0.5);
}

HostResult<VerifyReport> verify_calibration(const std::vector<MeanRow>& means,
                                            const std::optional<std::vector<Pose>>& poses,
                                            const calib_file::CalibrationData& cal,
                                            const std::string& means_file) {
  std::map<int, std::array<double, 3>> pose_of;
  if (poses) {
    for (const Pose& p : *poses) pose_of[p.attitude] = p.f_b_g;
  }
  const auto nominal = calib_file::nominal_geometry<double>(cal);
  const auto theta =
      nav::misaligned_geometry(nominal, calib_file::misalignment<double>(cal)).theta_b;
  VerifyReport rep;
  rep.lines.push_back("verification against the calibration of device " + cal.device_id +
                      ": residual P - SF (b + theta*.a) per pose and sensor (mV), z = residual / "
                      "predicted sigma");
  rep.lines.push_back(
      std::string("predicted sigma = the capture's noise (std_v/sqrt(count), where given) and the "
                  "file's covariance of each sensor's SF, bias and two angles (their sigma") +
      (cal.correlations_known
           ? " and correlations"
           : "; correlations unknown: taken as 0, the file predates format version 3") +
      "), propagated to first order through eq. (16)");
  std::string residual_based, unknown;
  for (std::size_t j = 0; j < 6; ++j) {
    const calib_file::SigmaBasis b = cal.sensors[j].sigma_source.basis;
    if (b == calib_file::SigmaBasis::kResiduals) residual_based += " a" + std::to_string(j + 1);
    if (b == calib_file::SigmaBasis::kUnknown) unknown += " a" + std::to_string(j + 1);
  }
  if (!residual_based.empty()) {
    rep.lines.push_back("  sigma of" + residual_based +
                        " from fit residuals (sensor.N.sigma_source): their z is a Student-t, "
                        "judged by the Gaussian z of the same tail probability");
  }
  if (!unknown.empty()) {
    rep.lines.push_back(
        "  note: the file predates format version 4 and does not say where the "
        "sigma of" +
        unknown +
        " came from: taken as stated (Gaussian); if they came from residuals, "
        "the verdict is too strict");
  }
  std::array<Eigen::Matrix4d, 6> cov{};
  std::array<std::array<nav::Vec3<double>, 2>, 6> d_theta{};
  for (std::size_t j = 0; j < 6; ++j) {
    cov[j] = sensor_parameter_cov(cal, j);
    d_theta[j] = axis_derivatives(j, nominal);
  }
  for (const MeanRow& m : means) {
    std::array<double, 3> a{};
    if (poses) {
      const auto it = pose_of.find(m.attitude);
      if (it == pose_of.end()) {
        return sim::invalid_argument(means_file + ":" + std::to_string(m.line) + ": attitude " +
                                     std::to_string(m.attitude) + " is not in the poses file");
      }
      a = it->second;
    } else {
      if (m.attitude > 6) {
        return sim::invalid_argument(means_file + ":" + std::to_string(m.line) + ": attitude " +
                                     std::to_string(m.attitude) +
                                     " is not in Tables 2/3; give --poses");
      }
      const bool alpha = in_set(nav::kSetAlpha, m.sensor - 1);
      a = (alpha ? calib::table3_attitudes<double>()
                 : calib::table2_attitudes<double>())[static_cast<std::size_t>(m.attitude - 1)];
    }
    const auto j = static_cast<std::size_t>(m.sensor - 1);
    const auto& s = cal.sensors[j];
    const nav::Vec3<double> av(a[0], a[1], a[2]);
    const double proj = theta[j].dot(av);
    const double predicted = s.scale_v_per_g * (s.bias_g + proj);  // eq. (16), g = T = 1
    const double res = m.mean_v - predicted;
    // Predicted σ, first order: h = SF (b + θ*(a1, a2)·a) (eq. (16), θ* of eqs. (14)/(15)) has
    // ∂h/∂(SF, b, a1, a2) = (b + θ*·a, SF, SF ∂θ*/∂a1·a, SF ∂θ*/∂a2·a); the residual's variance
    // is the mean's own plus J Σ_j Jᵀ with the file's whole 4×4 covariance Σ_j of the sensor.
    // Sensors are independent, so no other sensor's parameters enter.
    const Eigen::Vector4d jac(s.bias_g + proj, s.scale_v_per_g,
                              s.scale_v_per_g * d_theta[j][0].dot(av),
                              s.scale_v_per_g * d_theta[j][1].dot(av));
    const double var_mean = m.count > 0 ? m.std_v * m.std_v / static_cast<double>(m.count) : 0.0;
    // A valid file's Σ_j is positive semidefinite (checked on load); max() guards rounding.
    const double var_par = std::max(0.0, jac.dot(cov[j] * jac));
    const double var = var_mean + var_par;
    const double sigma = std::sqrt(var);
    VerifyRow row{m.attitude, m.sensor, res, sigma, std::sqrt(var_mean)};
    row.z = sigma > 0.0 ? res / sigma : 0.0;
    row.z_gauss = row.z;
    std::string how;
    // σ from fit residuals with K degrees of freedom are an estimate: z is then a Student-t, whose
    // tails are far wider (|t| > 5 has probability 3.8 % with 2 dof, 5.7e-7 for a Gaussian). Its
    // dof, with the capture's stated part added: Welch–Satterthwaite, ν = var² / (var_par² / K).
    // The verdict takes the Gaussian z of the same tail probability.
    if (s.sigma_source.basis == calib_file::SigmaBasis::kResiduals && var_par > 0.0) {
      row.dof = static_cast<double>(s.sigma_source.dof) * (var * var) / (var_par * var_par);
      const double p = student_t_two_sided_p(row.z, row.dof);
      row.z_gauss = p > 1e-300 ? -nav::normal_quantile(p / 2.0) : 40.0;
      row.z_gauss = std::copysign(row.z_gauss, row.z);
      how = " (Student-t, " + fmt("%.1f", row.dof) + " dof: " + fmt("%.2f", row.z_gauss) +
            " as a Gaussian)";
    }
    rep.rows.push_back(row);
    if (std::abs(row.z_gauss) > rep.max_abs_z) {
      rep.max_abs_z = std::abs(row.z_gauss);
      rep.worst_sensor = m.sensor;
      rep.worst_pose = m.attitude;
    }
    rep.lines.push_back("  pose " + std::to_string(m.attitude) + " sensor a" +
                        std::to_string(m.sensor) + ": residual " + fmt("%9.4f", res * 1e3) +
                        " mV, sigma " + fmt("%.3g", sigma * 1e3) + " mV, z " + fmt("%6.2f", row.z) +
                        how);
  }
  return rep;
}

}  // namespace gfins::tools
