// Monte-Carlo statistics over seeds (montecarlo.hpp).
#include "gfins/host_sim/montecarlo.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>

#include "gfins/host_sim/parallel.hpp"

namespace gfins::sim {

namespace {

/// What one run contributes to the statistics: per sample, the twelve error components and the
/// four squared norms, in the order the sums take them.
struct RunErrors {
  double calibration_angle_error_rad = 0;
  std::vector<double> t_s;
  std::vector<std::array<double, kMcQuantities * 4>> e;  // [q * 4 + a] axis a, [q * 4 + 3] |.|²
};

/// Run k of the Monte-Carlo: its seeds come from (seed0, k) only, so the run is the same on any
/// thread and in any order (parallel.hpp).
HostResult<RunErrors> one_run(const Scenario& base, std::uint64_t seed0, std::size_t k,
                              NavScalar scalar) {
  Scenario s = base;
  s.seed = seed0 + k;
  s.calibration.seed = seed0 + 100003 * k;
  GFINS_TRY(const ScenarioOutcome o, run_scenario(s, {}, /*with_uncompensated=*/false, scalar));
  RunErrors r;
  r.calibration_angle_error_rad = o.calibration.rms_angle_error_rad;
  const auto& smp = o.compensated.samples;
  r.t_s.reserve(smp.size());
  r.e.reserve(smp.size());
  for (const auto& x : smp) {
    r.t_s.push_back(x.t_s);
    const std::array<Vec3d, kMcQuantities> e = {x.w_err_b(), x.att_err_b(), x.v_err_n(),
                                                x.r_err_n()};
    auto& row = r.e.emplace_back();
    for (std::size_t q = 0; q < kMcQuantities; ++q) {
      for (std::size_t a = 0; a < 3; ++a) row[q * 4 + a] = e[q](static_cast<Eigen::Index>(a));
      row[q * 4 + 3] = e[q].squaredNorm();
    }
  }
  return r;
}

/// Bytes per sample of one RunErrors (t_s and the error row).
constexpr std::uint64_t kRunErrorsBytesPerSample =
    sizeof(double) + sizeof(std::array<double, kMcQuantities * 4>);
/// Bytes per sample of the running sums (sum, sum2: 3 axes; norm2) and of the result (t_s, mean,
/// std: 3 axes; rms_norm).
constexpr std::uint64_t kSumsBytesPerSample = (2 * 3 + 1) * kMcQuantities * sizeof(double);
constexpr std::uint64_t kResultBytesPerSample =
    sizeof(double) + (2 * 3 + 1) * kMcQuantities * sizeof(double);

std::size_t effective_jobs(std::size_t runs, std::size_t jobs) {
  return std::max<std::size_t>(1, std::min(jobs == 0 ? default_jobs() : jobs, runs));
}

}  // namespace

std::uint64_t montecarlo_memory_bytes(const Scenario& s, std::size_t runs, std::size_t jobs) {
  const auto samples = static_cast<double>(sample_count(s));
  const auto j = static_cast<double>(effective_jobs(runs, jobs));
  // A run in flight: run_scenario's own peak, then its error rows while its outcome is alive.
  const double in_run = static_cast<double>(run_memory_bytes(s, false)) / samples +
                        static_cast<double>(kRunErrorsBytesPerSample);
  // Finished runs waiting for their turn: a thread claims run k only while k < consumed + 2 ×
  // jobs (parallel.hpp), so runs in flight and waiting are at most min(2 × jobs, runs) together;
  // with one thread none waits.
  const double alive = std::min(2.0 * j, static_cast<double>(runs));
  const double waiting = j > 1 ? (alive - j) * static_cast<double>(kRunErrorsBytesPerSample) : 0.0;
  const double during = j * in_run + waiting + static_cast<double>(kSumsBytesPerSample);
  const double at_end = static_cast<double>(kSumsBytesPerSample + kResultBytesPerSample);
  const double bytes = samples * std::max(during, at_end) + static_cast<double>(kProcessBaseBytes);
  return bytes >= 1.8e19 ? UINT64_MAX : static_cast<std::uint64_t>(bytes);
}

HostStatus check_montecarlo_size(const Scenario& s, std::size_t runs, std::size_t jobs) {
  GFINS_TRY_STATUS(check_run_size(s, false, /*in_memory=*/false));
  const std::uint64_t bytes = montecarlo_memory_bytes(s, runs, jobs);
  const std::uint64_t limit = max_run_memory_bytes();
  if (bytes <= limit) return Done{};
  const std::size_t j = effective_jobs(runs, jobs);
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "scenario %s: %llu samples per run (duration_s %g x rate_hz %g), %zu run%s at "
                "a time (-j %zu): about %.3g GiB of memory, above the limit of %.3g GiB: use "
                "fewer threads (-j 1 needs about %.3g GiB), a shorter run or a lower rate",
                s.name.c_str(), static_cast<unsigned long long>(sample_count(s)), s.duration_s,
                s.rate_hz, j, j == 1 ? "" : "s", j, static_cast<double>(bytes) / double(1u << 30),
                static_cast<double>(limit) / double(1u << 30),
                static_cast<double>(montecarlo_memory_bytes(s, runs, 1)) / double(1u << 30));
  return HostError{ErrorCode::kOutOfRange, buf};
}

double montecarlo_seconds_estimate(const Scenario& s, std::size_t runs, std::size_t jobs) {
  const auto j = static_cast<double>(effective_jobs(runs, jobs));
  return static_cast<double>(sample_count(s)) * static_cast<double>(runs) * kMcSecondsPerSampleRun /
         j;
}

HostResult<MonteCarloResult> run_montecarlo(const Scenario& base, std::size_t runs,
                                            std::uint64_t seed0, const ProgressFn& progress,
                                            NavScalar scalar, std::size_t jobs,
                                            const volatile std::sig_atomic_t* stop) {
  if (runs < 2) {
    return HostError{ErrorCode::kInvalidArgument, "montecarlo: at least two runs are needed"};
  }
  MonteCarloResult r;
  r.runs = runs;
  // Running sums per [quantity][axis][sample] (Welford would be overkill: errors are small and
  // the sums are in double), added in run order 0, 1, 2, ... whatever the thread count.
  std::array<std::array<std::vector<double>, 3>, kMcQuantities> sum;
  std::array<std::array<std::vector<double>, 3>, kMcQuantities> sum2;
  std::array<std::vector<double>, kMcQuantities> norm2;
  double cal2 = 0;
  std::optional<HostError> failed;
  std::size_t folded = 0;
  const auto stopped = [stop] { return stop != nullptr && *stop != 0; };
  const auto fold = [&](std::size_t k, HostResult<RunErrors>&& run) {
    if (stopped()) return false;  // the runs folded so far stay; nothing further is taken
    if (!run.is_ok()) {
      failed = std::move(run).take_error();
      return false;
    }
    const RunErrors& o = run.value();
    cal2 += o.calibration_angle_error_rad * o.calibration_angle_error_rad;
    const std::size_t n = o.t_s.size();
    if (k == 0) {
      r.t_s = o.t_s;
      for (std::size_t q = 0; q < kMcQuantities; ++q) {
        for (std::size_t a = 0; a < 3; ++a) {
          sum[q][a].assign(n, 0.0);
          sum2[q][a].assign(n, 0.0);
        }
        norm2[q].assign(n, 0.0);
      }
    } else if (n != r.t_s.size()) {
      failed = HostError{ErrorCode::kFailedPrecondition,
                         "montecarlo: run " + std::to_string(k) + " has " + std::to_string(n) +
                             " samples, run 0 has " + std::to_string(r.t_s.size())};
      return false;
    }
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t q = 0; q < kMcQuantities; ++q) {
        for (std::size_t a = 0; a < 3; ++a) {
          const double v = o.e[i][q * 4 + a];
          sum[q][a][i] += v;
          sum2[q][a][i] += v * v;
        }
        norm2[q][i] += o.e[i][q * 4 + 3];
      }
    }
    folded = k + 1;
    if (progress) progress(static_cast<double>(k + 1) / static_cast<double>(runs));
    return true;
  };
  ordered_parallel_for(
      runs, jobs,
      [&](std::size_t k) -> HostResult<RunErrors> {
        // A run not started before the stop is skipped (fold drops it).
        if (stopped()) return HostError{ErrorCode::kFailedPrecondition, "montecarlo: stopped"};
        return one_run(base, seed0, k, scalar);
      },
      fold);
  if (failed) return *failed;
  if (folded < 2) {
    return HostError{ErrorCode::kFailedPrecondition, "montecarlo: stopped after " +
                                                         std::to_string(folded) +
                                                         " run(s): statistics need at least two"};
  }
  r.runs = folded;
  const auto nr = static_cast<double>(folded);
  const std::size_t n = r.t_s.size();
  for (std::size_t q = 0; q < kMcQuantities; ++q) {
    for (std::size_t a = 0; a < 3; ++a) {
      r.mean[q][a].resize(n);
      r.std[q][a].resize(n);
      for (std::size_t i = 0; i < n; ++i) {
        const double m = sum[q][a][i] / nr;
        r.mean[q][a][i] = m;
        r.std[q][a][i] = std::sqrt(std::max(0.0, (sum2[q][a][i] - nr * m * m) / (nr - 1.0)));
      }
    }
    r.rms_norm[q].resize(n);
    for (std::size_t i = 0; i < n; ++i) r.rms_norm[q][i] = std::sqrt(norm2[q][i] / nr);
  }
  r.rms_calibration_angle_error_rad = std::sqrt(cal2 / nr);
  return r;
}

double loglog_slope(const std::vector<double>& t, const std::vector<double>& y, double t_lo,
                    double t_hi) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  std::size_t m = 0;
  for (std::size_t i = 0; i < t.size() && i < y.size(); ++i) {
    if (t[i] < t_lo || t[i] > t_hi || !(t[i] > 0) || !(y[i] > 0)) continue;
    const double x = std::log(t[i]);
    const double v = std::log(y[i]);
    sx += x;
    sy += v;
    sxx += x * x;
    sxy += x * v;
    ++m;
  }
  if (m < 2) return std::numeric_limits<double>::quiet_NaN();
  const auto mm = static_cast<double>(m);
  return (mm * sxy - sx * sy) / (mm * sxx - sx * sx);
}

HostStatus write_montecarlo_csv(const MonteCarloResult& r, const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) return HostError{ErrorCode::kIoError, "cannot write " + path};
  std::fprintf(f, "t_s");
  const char* axes = "xyz";
  for (std::size_t q = 0; q < kMcQuantities; ++q) {
    for (std::size_t a = 0; a < 3; ++a) {
      std::fprintf(f, ",%s_%c_mean,%s_%c_std", kMcQuantityNames[q], axes[a], kMcQuantityNames[q],
                   axes[a]);
    }
    std::fprintf(f, ",%s_norm_rms", kMcQuantityNames[q]);
  }
  std::fprintf(f, "\n");
  for (std::size_t i = 0; i < r.t_s.size(); ++i) {
    std::fprintf(f, "%.6f", r.t_s[i]);
    for (std::size_t q = 0; q < kMcQuantities; ++q) {
      for (std::size_t a = 0; a < 3; ++a) {
        std::fprintf(f, ",%.9g,%.9g", r.mean[q][a][i], r.std[q][a][i]);
      }
      std::fprintf(f, ",%.9g", r.rms_norm[q][i]);
    }
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

}  // namespace gfins::sim
