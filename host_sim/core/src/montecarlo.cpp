// Monte-Carlo statistics over seeds (montecarlo.hpp).
#include "gfins/host_sim/montecarlo.hpp"

#include <cmath>
#include <cstdio>
#include <limits>

namespace gfins::sim {

HostResult<MonteCarloResult> run_montecarlo(const Scenario& base, std::size_t runs,
                                            std::uint64_t seed0, const ProgressFn& progress,
                                            NavScalar scalar) {
  if (runs < 2) {
    return HostError{ErrorCode::kInvalidArgument, "montecarlo: at least two runs are needed"};
  }
  MonteCarloResult r;
  r.runs = runs;
  // Running sums per [quantity][axis][sample] (Welford would be overkill: errors are small and
  // the sums are in double).
  std::array<std::array<std::vector<double>, 3>, kMcQuantities> sum;
  std::array<std::array<std::vector<double>, 3>, kMcQuantities> sum2;
  std::array<std::vector<double>, kMcQuantities> norm2;
  double cal2 = 0;
  for (std::size_t k = 0; k < runs; ++k) {
    Scenario s = base;
    s.seed = seed0 + k;
    s.calibration.seed = seed0 + 100003 * k;
    GFINS_TRY(const ScenarioOutcome o, run_scenario(s, {}, /*with_uncompensated=*/false, scalar));
    cal2 += o.calibration.rms_angle_error_rad * o.calibration.rms_angle_error_rad;
    const auto& smp = o.compensated.samples;
    const std::size_t n = smp.size();
    if (k == 0) {
      r.t_s.resize(n);
      for (std::size_t i = 0; i < n; ++i) r.t_s[i] = smp[i].t_s;
      for (std::size_t q = 0; q < kMcQuantities; ++q) {
        for (std::size_t a = 0; a < 3; ++a) {
          sum[q][a].assign(n, 0.0);
          sum2[q][a].assign(n, 0.0);
        }
        norm2[q].assign(n, 0.0);
      }
    }
    for (std::size_t i = 0; i < n; ++i) {
      const std::array<Vec3d, kMcQuantities> e = {smp[i].w_err_b(), smp[i].att_err_b(),
                                                  smp[i].v_err_n(), smp[i].r_err_n()};
      for (std::size_t q = 0; q < kMcQuantities; ++q) {
        for (std::size_t a = 0; a < 3; ++a) {
          const double v = e[q](static_cast<Eigen::Index>(a));
          sum[q][a][i] += v;
          sum2[q][a][i] += v * v;
        }
        norm2[q][i] += e[q].squaredNorm();
      }
    }
    if (progress) progress(static_cast<double>(k + 1) / static_cast<double>(runs));
  }
  const auto nr = static_cast<double>(runs);
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
