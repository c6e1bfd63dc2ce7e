#include "gfins/host_sim/accuracy.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace gfins::sim {

const std::array<const char*, kConsistencyComponents> kConsistencyNames = {
    "roll", "pitch", "heading", "v_N", "v_E", "v_D", "r_N", "r_E", "r_D"};

namespace {
constexpr double kDeg = 180.0 / 3.14159265358979323846;
}  // namespace

AccuracyTracker::AccuracyTracker(std::vector<double> checkpoints_s, double rms_from_s,
                                 const std::vector<std::pair<double, double>>& windows,
                                 double after_s)
    : checkpoints_s_(std::move(checkpoints_s)),
      at_(checkpoints_s_.size()),
      rms_from_s_(rms_from_s),
      after_s_(after_s) {
  for (const auto& [a, b] : windows) {
    Window w;
    w.start_s = a;
    w.end_s = b;
    windows_.push_back(w);
  }
}

ErrorSnapshot AccuracyTracker::snapshot(const SampleRecord& x) {
  const Vec3d e = x.euler_err();
  const Vec3d r = x.r_err_n();
  ErrorSnapshot s;
  s.t_s = x.t_s;
  s.tilt_deg = std::max(std::abs(e.x()), std::abs(e.y())) * kDeg;
  s.heading_deg = std::abs(e.z()) * kDeg;
  s.vel_mps = x.v_err_n().norm();
  s.pos_h_m = std::hypot(r.x(), r.y());
  s.pos_v_m = std::abs(r.z());
  s.seen = true;
  return s;
}

void AccuracyTracker::keep_worst(ErrorSnapshot& w, const ErrorSnapshot& e) {
  // NaN (a diverged run) counts as worst: a comparison with NaN is false, so test for it.
  const auto worse = [](double a, double b) {
    if (std::isnan(b)) return false;  // already the worst there is
    return std::isnan(a) || a > b;
  };
  if (!w.seen || worse(e.tilt_deg, w.tilt_deg)) {
    w.tilt_deg = e.tilt_deg;
    w.t_s = e.t_s;
  }
  if (!w.seen || worse(e.heading_deg, w.heading_deg)) w.heading_deg = e.heading_deg;
  if (!w.seen || worse(e.vel_mps, w.vel_mps)) w.vel_mps = e.vel_mps;
  if (!w.seen || worse(e.pos_h_m, w.pos_h_m)) w.pos_h_m = e.pos_h_m;
  if (!w.seen || worse(e.pos_v_m, w.pos_v_m)) w.pos_v_m = e.pos_v_m;
  w.seen = true;
}

void DetectorTally::add(const SampleRecord& x) {
  const TruthState& t = x.truth;
  const bool rest = t.v_n.isZero(0.0) && t.w_b.isZero(0.0);
  // The body's kinematic acceleration and rate against the window's first sample: a steady turn
  // at constant speed keeps both (and so every sensor's output) constant.
  const Vec3d a_b = t.q_nb.conjugate() * t.a_n;
  if (window_first_) {
    a_b0_ = a_b;
    window_first_ = false;
  }
  const bool dynamic = (a_b - a_b0_).norm() > kLikeRestAccel || t.wdot_b.norm() > kLikeRestWdot;
  window_moves_ = window_moves_ || !rest;
  window_rests_ = window_rests_ || rest;
  window_dynamic_ = window_dynamic_ || dynamic;
  if (rest && !in_stop_) {
    in_stop_ = true;
    stop_seen_ = false;
    ++stops_;
  } else if (!rest) {
    in_stop_ = false;
  }
  if (x.detector_windows == last_windows_) return;
  // A decision: about the samples since the previous one, this one included.
  last_windows_ = x.detector_windows;
  if (window_moves_ && window_rests_) {
    ++mixed_;
    if (x.detector_at_rest) ++mixed_rest_;
  } else if (!window_moves_) {
    ++rest_;
    if (!x.detector_at_rest) ++false_alarms_;
    if (x.detector_at_rest && in_stop_ && !stop_seen_) {
      stop_seen_ = true;
      ++stops_seen_;
    }
  } else {
    ++moving_;
    if (!window_dynamic_) ++like_rest_;
    if (x.detector_at_rest) {
      ++missed_;
      if (!window_dynamic_) ++missed_like_rest_;
    }
  }
  window_moves_ = false;
  window_rests_ = false;
  window_dynamic_ = false;
  window_first_ = true;
}

void AccuracyTracker::add(const SampleRecord& x) {
  detector_.add(x);
  const ErrorSnapshot e = snapshot(x);
  for (std::size_t i = 0; i < checkpoints_s_.size(); ++i) {
    if (!at_[i].seen && x.t_s >= checkpoints_s_[i]) at_[i] = e;
  }
  for (Window& w : windows_) {
    if (x.t_s >= w.start_s && x.t_s < w.end_s) keep_worst(w.worst_inside, e);
    if (!w.after.seen && x.t_s >= w.end_s + after_s_) w.after = e;
  }
  if (x.t_s < rms_from_s_) return;
  ++n_;
  tilt2_ += e.tilt_deg * e.tilt_deg;
  heading2_ += e.heading_deg * e.heading_deg;
  vel2_ += e.vel_mps * e.vel_mps;
  pos2_ += e.pos_h_m * e.pos_h_m;
  keep_worst(worst_, e);
  bool outside = !windows_.empty();
  for (const Window& w : windows_) {
    if (x.t_s >= w.start_s && x.t_s < w.end_s + after_s_) outside = false;
  }
  if (outside) {
    ++n_out_;
    tilt2_out_ += e.tilt_deg * e.tilt_deg;
    heading2_out_ += e.heading_deg * e.heading_deg;
    vel2_out_ += e.vel_mps * e.vel_mps;
    pos2_out_ += e.pos_h_m * e.pos_h_m;
  }
  const Vec3d ee = x.euler_err();
  const std::array<double, kConsistencyComponents> err = {
      ee.x(),          ee.y(),          ee.z(),          x.v_err_n().x(), x.v_err_n().y(),
      x.v_err_n().z(), x.r_err_n().x(), x.r_err_n().y(), x.r_err_n().z()};
  const std::array<double, kConsistencyComponents> sig = {
      x.euler_sigma_rad.x(), x.euler_sigma_rad.y(), x.euler_sigma_rad.z(),
      x.v_sigma_n.x(),       x.v_sigma_n.y(),       x.v_sigma_n.z(),
      x.r_sigma_n.x(),       x.r_sigma_n.y(),       x.r_sigma_n.z()};
  coverage_.add(err, sig);
  if (outside || windows_.empty()) {
    ++rp_n_;
    roll2_ += err[0] * err[0];
    pitch2_ += err[1] * err[1];
    if (std::isfinite(sig[0]) && std::isfinite(sig[1])) {
      ++rp_sigma_n_;
      roll_sigma2_ += sig[0] * sig[0];
      pitch_sigma2_ += sig[1] * sig[1];
    }
  }
  for (Window& w : windows_) {
    if (x.t_s >= w.start_s && x.t_s < w.end_s) w.inside.add(err, sig);
  }
}

void Coverage::add(const std::array<double, kConsistencyComponents>& err,
                   const std::array<double, kConsistencyComponents>& sigma) {
  ++all_;
  bool any = false;
  for (std::size_t i = 0; i < kConsistencyComponents; ++i) {
    if (!std::isfinite(sigma[i])) continue;  // not available here (no filter, or marked)
    any = true;
    ++n_[i];
    if (std::abs(err[i]) <= 3.0 * sigma[i]) ++within_[i];
  }
  if (any) ++any_;
}

std::uint64_t Coverage::published(std::size_t component) const {
  return component < kConsistencyComponents ? n_[component] : 0;
}

double Coverage::fraction(std::size_t component) const {
  if (component >= kConsistencyComponents || n_[component] == 0) return std::nan("");
  return static_cast<double>(within_[component]) / static_cast<double>(n_[component]);
}

namespace {
double rms(double sum2, std::uint64_t n) {
  return n == 0 ? std::nan("") : std::sqrt(sum2 / static_cast<double>(n));
}
}  // namespace

double AccuracyTracker::tilt_rms_deg() const { return rms(tilt2_, n_); }
AccuracyTracker::RollPitch AccuracyTracker::roll_pitch() const {
  RollPitch r;
  r.roll_rms_deg = rms(roll2_, rp_n_) * kDeg;
  r.pitch_rms_deg = rms(pitch2_, rp_n_) * kDeg;
  r.roll_sigma_rms_deg = rms(roll_sigma2_, rp_sigma_n_) * kDeg;
  r.pitch_sigma_rms_deg = rms(pitch_sigma2_, rp_sigma_n_) * kDeg;
  return r;
}
double AccuracyTracker::heading_rms_deg() const { return rms(heading2_, n_); }
double AccuracyTracker::vel_rms_mps() const { return rms(vel2_, n_); }
double AccuracyTracker::pos_h_rms_m() const { return rms(pos2_, n_); }

ErrorSnapshot AccuracyTracker::rms_outside() const {
  ErrorSnapshot e;
  e.seen = n_out_ > 0;
  e.tilt_deg = rms(tilt2_out_, n_out_);
  e.heading_deg = rms(heading2_out_, n_out_);
  e.vel_mps = rms(vel2_out_, n_out_);
  e.pos_h_m = rms(pos2_out_, n_out_);
  return e;
}

std::string AccuracyTracker::describe_rms() const {
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "RMS over t >= %g s: tilt %.3g deg, heading %.3g deg, velocity %.3g m/s, "
                "horizontal position %.3g m",
                rms_from_s_, tilt_rms_deg(), heading_rms_deg(), vel_rms_mps(), pos_h_rms_m());
  return buf;
}

}  // namespace gfins::sim
