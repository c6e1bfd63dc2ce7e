// Filter consistency by Monte-Carlo over a whole scenario (consistency.hpp).
#include "gfins/host_sim/consistency.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <random>
#include <string>

#include "gfins/host_sim/parallel.hpp"

namespace gfins::sim {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
/// z of the normal distribution at 0.975 (the two-sided 95 % bounds).
constexpr double kZ975 = 1.959963984540054;
/// A consistent filter leaves 5 % of the epochs outside the 95 % bounds; the verdict allows 10 %.
constexpr double kOutsideProbability = 0.05;

/// The states of each group (kNeesGroupNames) and the validity bit that publishes it.
struct Group {
  std::uint8_t bit;
  int first, count;
};
constexpr std::array<Group, kNeesGroups> kGroups = {
    Group{nav::filter_valid::kRollPitch, nav::filt_idx::kPhi, 2},
    Group{nav::filter_valid::kHeading, nav::filt_idx::kPhi + 2, 1},
    Group{nav::filter_valid::kVelocity, nav::filt_idx::kVel, 3},
    Group{nav::filter_valid::kPosition, nav::filt_idx::kPos, 3}};

/// The error states published at a moment, from NavAccuracy::valid (consistency.hpp); only
/// group `only` when it is below kNeesGroups.
std::vector<int> published_states(std::uint8_t valid, std::size_t only = kNeesGroups) {
  std::vector<int> idx;
  for (std::size_t g = 0; g < kNeesGroups; ++g) {
    if ((valid & kGroups[g].bit) == 0 || (only < kNeesGroups && g != only)) continue;
    for (int i = 0; i < kGroups[g].count; ++i) idx.push_back(kGroups[g].first + i);
  }
  return idx;
}

/// xᵀ P⁻¹ x over the states `idx`, NaN when that block is not positive definite.
double nees_of(const std::vector<int>& idx, const Eigen::Matrix<double, 9, 1>& err,
               const Eigen::Matrix<double, 9, 9>& p) {
  const auto d = static_cast<Eigen::Index>(idx.size());
  Eigen::VectorXd x(d);
  Eigen::MatrixXd pp(d, d);
  for (Eigen::Index i = 0; i < d; ++i) {
    x(i) = err(idx[static_cast<std::size_t>(i)]);
    for (Eigen::Index j = 0; j < d; ++j) {
      pp(i, j) = p(idx[static_cast<std::size_t>(i)], idx[static_cast<std::size_t>(j)]);
    }
  }
  const Eigen::LLT<Eigen::MatrixXd> llt(pp);
  if (llt.info() != Eigen::Success) return kNaN;
  return x.dot(llt.solve(x));
}

/// Σ statistic and Σ d of one epoch (fix) into a series.
struct Sums {
  std::vector<double> sum;
  std::vector<double> dof;
  void add(std::size_t i, double value, double d) {
    if (!std::isfinite(value) || d <= 0) return;
    sum[i] += value;
    dof[i] += d;
  }
};

ConsistencySeries finish(const Sums& s, const std::vector<double>& t_s,
                         const std::vector<bool>& counted) {
  ConsistencySeries out;
  out.t_s = t_s;
  const std::size_t n = s.sum.size();
  out.value.assign(n, kNaN);
  out.lo.assign(n, kNaN);
  out.hi.assign(n, kNaN);
  out.dof = s.dof;
  out.judged = counted;
  for (std::size_t i = 0; i < n; ++i) {
    const double d = s.dof[i];
    if (d <= 0) continue;
    out.value[i] = s.sum[i] / d;
    out.lo[i] = chi_square_quantile(0.025, d) / d;
    out.hi[i] = chi_square_quantile(0.975, d) / d;
    if (!counted[i]) continue;
    ++out.offered;
    if (out.value[i] > out.hi[i]) ++out.above;
    if (out.value[i] >= out.lo[i] && out.value[i] <= out.hi[i]) ++out.inside;
  }
  out.false_failure = binomial_upper_tail(out.offered, kOutsideProbability, out.offered / 10);
  return out;
}

/// The scenario's GNSS fix times of validity (the same in every run: only the noise has a seed).
HostResult<std::vector<double>> fix_times(const Scenario& s) {
  std::vector<double> t;
  if (!s.gnss) return t;
  GFINS_TRY(const auto traj, make_trajectory(s.trajectory));
  for (const GnssSample& g : GnssModel(*s.gnss, *traj).fixes(s.duration_s)) {
    t.push_back(g.t_valid_s);
  }
  return t;
}

/// Run k: its seeds and its unknown biases come from (seed0, k) only, so it is the same on any
/// thread and in any order (parallel.hpp).
HostResult<ConsistencyRun> one_run(const Scenario& base, std::uint64_t seed0, std::size_t k,
                                   std::size_t fixes, NavScalar scalar, double stated_sigma_scale,
                                   const volatile std::sig_atomic_t* stop) {
  Scenario s = base;
  s.seed = seed0 + k;
  s.calibration.seed = seed0 + 100003 * k;  // as run_montecarlo: each run its own calibration
  if (s.gnss) s.gnss->seed = (seed0 + k) * 2654435761u + 1u;
  StreamTargets targets;
  targets.uncompensated_run = false;
  targets.gnss_stated_sigma_scale = stated_sigma_scale;
  targets.stop = stop;
  std::mt19937_64 rng((seed0 + k) ^ 0x9e3779b97f4a7c15ULL);
  std::normal_distribution<double> n01(0.0, 1.0);
  const double sigma_b = s.aiding.bias_sigma_ug * 1e-6 * nav::kStandardGravity;
  for (double& b : targets.unknown_bias_mps2) b = sigma_b * n01(rng);
  // The start error the filter claims (its P0, FilterConfig's defaults, which the scenario's
  // [aiding] does not change): tilt, heading, position, velocity, rate.
  const nav::FilterConfig<double> f{};
  const auto draw = [&](double s0, double s1, double s2) {
    const double a = s0 * n01(rng), b = s1 * n01(rng), c = s2 * n01(rng);
    return Vec3d(a, b, c);
  };
  targets.start_error.phi_n =
      draw(f.init_sigma_tilt_rad, f.init_sigma_tilt_rad, f.init_sigma_heading_rad);
  targets.start_error.dr_n = draw(f.init_sigma_pos_m, f.init_sigma_pos_m, f.init_sigma_pos_m);
  targets.start_error.dv_n = draw(f.init_sigma_vel_mps, f.init_sigma_vel_mps, f.init_sigma_vel_mps);
  targets.start_error.dw_b =
      draw(f.init_sigma_rate_rps, f.init_sigma_rate_rps, f.init_sigma_rate_rps);
  const auto epochs = static_cast<std::size_t>(std::floor(s.duration_s + 1e-9));
  ConsistencyRecorder rec(epochs, fixes);
  targets.consistency = &rec;
  GFINS_TRY(const StreamedOutcome o, run_scenario_streamed(s, targets, {}, scalar));
  if (o.interrupted) {
    // A run cut short is not a run: the statistics take whole runs only.
    return HostError{ErrorCode::kFailedPrecondition, "consistency: stopped"};
  }
  return rec.run();
}

}  // namespace

ConsistencyRecorder::ConsistencyRecorder(std::size_t epochs, std::size_t fixes) {
  run_.nees.assign(epochs, kNaN);
  run_.dof.assign(epochs, 0);
  for (std::size_t g = 0; g < kNeesGroups; ++g) {
    run_.group_nees[g].assign(epochs, kNaN);
    run_.group_dof[g].assign(epochs, 0);
  }
  run_.nis_pos.assign(fixes, kNaN);
  run_.nis_vel.assign(fixes, kNaN);
}

long ConsistencyRecorder::due(double t_s) const {
  // Epoch k is the first sample at or after (k + 1) s; a stretch without samples offered (the
  // alignment) leaves its epochs empty.
  const long k = static_cast<long>(std::floor(t_s + 1e-9)) - 1;
  if (k < next_ || k >= static_cast<long>(run_.nees.size())) return -1;
  return k;
}

void ConsistencyRecorder::add_epoch(long k, const Eigen::Matrix<double, 9, 1>& err,
                                    const Eigen::Matrix<double, 9, 9>& p, std::uint8_t valid) {
  if (k < 0 || k >= static_cast<long>(run_.nees.size())) return;
  next_ = k + 1;
  const auto ku = static_cast<std::size_t>(k);
  const auto put = [&](const std::vector<int>& idx, std::vector<double>& nees,
                       std::vector<int>& dof) {
    if (idx.empty()) return;
    const double v = nees_of(idx, err, p);
    if (!std::isfinite(v)) return;
    nees[ku] = v;
    dof[ku] = static_cast<int>(idx.size());
  };
  put(published_states(valid), run_.nees, run_.dof);
  for (std::size_t g = 0; g < kNeesGroups; ++g) {
    put(published_states(valid, g), run_.group_nees[g], run_.group_dof[g]);
  }
}

void ConsistencyRecorder::add_fix(std::size_t index, const nav::UpdateOutcome& pos,
                                  const nav::UpdateOutcome& vel) {
  if (index >= run_.nis_pos.size()) return;
  const auto gated = [](const nav::UpdateOutcome& o) {
    return o.status == nav::UpdateStatus::kAccepted || o.status == nav::UpdateStatus::kRejected;
  };
  if (gated(pos)) run_.nis_pos[index] = static_cast<double>(pos.nis);
  if (gated(vel)) run_.nis_vel[index] = static_cast<double>(vel.nis);
}

namespace {
/// z_p of the standard normal: the two tails the project uses, exact to 1e-15; others by
/// inverting erfc with Newton steps.
double normal_quantile(double p) {
  if (p == 0.975) return kZ975;
  if (p == 0.025) return -kZ975;
  double z = 0;
  for (int i = 0; i < 60; ++i) {
    const double cdf = 0.5 * std::erfc(-z / std::sqrt(2.0));
    const double pdf = std::exp(-0.5 * z * z) / std::sqrt(2.0 * M_PI);
    z -= (cdf - p) / pdf;
  }
  return z;
}
}  // namespace

double chi_square_quantile(double p, double dof) {
  // Exact for 1 and 2 degrees of freedom (a group published by one or two runs only), where
  // Wilson–Hilferty is far off (negative at 1, 48 % low at 2 for p = 0.025).
  if (dof == 1.0) {
    const double z = normal_quantile(0.5 + 0.5 * p);
    return z * z;
  }
  if (dof == 2.0) return -2.0 * std::log1p(-p);
  const double z = normal_quantile(p);
  const double a = 2.0 / (9.0 * dof);
  const double c = 1.0 - a + z * std::sqrt(a);
  return dof * c * c * c;
}

double binomial_upper_tail(std::size_t n, double p, std::size_t k) {
  double tail = 0;
  const double ln_p = std::log(p), ln_q = std::log1p(-p);
  const double nd = static_cast<double>(n);
  for (std::size_t i = k + 1; i <= n; ++i) {
    const double id = static_cast<double>(i);
    tail += std::exp(std::lgamma(nd + 1) - std::lgamma(id + 1) - std::lgamma(nd - id + 1) +
                     id * ln_p + (nd - id) * ln_q);
  }
  return std::min(tail, 1.0);
}

ConsistencyResult summarize_consistency(const std::vector<ConsistencyRun>& runs,
                                        const std::vector<double>& fix_t_s, double from_s) {
  ConsistencyResult r;
  r.runs = runs.size();
  if (runs.empty()) return r;
  const std::size_t epochs = runs.front().nees.size();
  const std::size_t fixes = runs.front().nis_pos.size();
  Sums nees{std::vector<double>(epochs, 0.0), std::vector<double>(epochs, 0.0)};
  std::array<Sums, kNeesGroups> groups;
  for (Sums& g : groups) g = nees;
  Sums pos{std::vector<double>(fixes, 0.0), std::vector<double>(fixes, 0.0)};
  Sums vel = pos;
  for (const ConsistencyRun& run : runs) {
    for (std::size_t i = 0; i < epochs && i < run.nees.size(); ++i) {
      nees.add(i, run.nees[i], run.dof[i]);
      for (std::size_t g = 0; g < kNeesGroups; ++g) {
        groups[g].add(i, run.group_nees[g][i], run.group_dof[g][i]);
      }
    }
    for (std::size_t i = 0; i < fixes && i < run.nis_pos.size(); ++i) {
      pos.add(i, run.nis_pos[i], 3);
      vel.add(i, run.nis_vel[i], 3);
    }
  }
  std::vector<double> t(epochs);
  std::vector<bool> counted(epochs);
  for (std::size_t i = 0; i < epochs; ++i) {
    t[i] = static_cast<double>(i + 1);
    counted[i] = t[i] >= from_s;
  }
  r.nees = finish(nees, t, counted);
  for (std::size_t g = 0; g < kNeesGroups; ++g) r.group_nees[g] = finish(groups[g], t, counted);
  std::vector<double> tf(fix_t_s);
  tf.resize(fixes, kNaN);
  std::vector<bool> fix_counted(fixes);
  for (std::size_t i = 0; i < fixes; ++i) fix_counted[i] = tf[i] >= from_s;
  r.nis_pos = finish(pos, tf, fix_counted);
  r.nis_vel = finish(vel, tf, fix_counted);
  return r;
}

HostResult<ConsistencyResult> run_consistency(const Scenario& base, std::size_t runs,
                                              std::uint64_t seed0, double from_s,
                                              const ProgressFn& progress, NavScalar scalar,
                                              std::size_t jobs, double stated_sigma_scale,
                                              const volatile std::sig_atomic_t* stop) {
  if (runs < 2) {
    return HostError{ErrorCode::kInvalidArgument, "consistency: at least two runs are needed"};
  }
  if (base.trajectory.kind == "calibration_poses") {
    return HostError{ErrorCode::kInvalidArgument,
                     "consistency: scenario " + base.name +
                         " is a calibration (calibration_poses): nothing navigates"};
  }
  // The scenario's [aiding] switched on, as `gfins-sim aided` runs it.
  Scenario aided = base;
  aided.aiding.enabled = true;
  GFINS_TRY(const std::vector<double> t_fix, fix_times(aided));
  std::vector<ConsistencyRun> done;
  done.reserve(runs);
  std::optional<HostError> failed;
  const auto stopped = [stop] { return stop != nullptr && *stop != 0; };
  ordered_parallel_for(
      runs, jobs,
      [&](std::size_t k) -> HostResult<ConsistencyRun> {
        if (stopped()) return HostError{ErrorCode::kFailedPrecondition, "consistency: stopped"};
        return one_run(aided, seed0, k, t_fix.size(), scalar, stated_sigma_scale, stop);
      },
      [&](std::size_t k, HostResult<ConsistencyRun>&& run) {
        if (stopped()) return false;
        if (!run.is_ok()) {
          failed = std::move(run).take_error();
          return false;
        }
        done.push_back(std::move(run).value());
        if (progress) progress(static_cast<double>(k + 1) / static_cast<double>(runs));
        return true;
      });
  if (failed) return *failed;
  if (done.size() < 2) {
    return HostError{ErrorCode::kFailedPrecondition,
                     "consistency: stopped after " + std::to_string(done.size()) +
                         " run(s): the statistics need at least two"};
  }
  return summarize_consistency(done, t_fix, from_s);
}

}  // namespace gfins::sim
