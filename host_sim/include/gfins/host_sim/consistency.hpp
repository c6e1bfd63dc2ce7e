// Filter consistency by Monte-Carlo over a whole scenario (`gfins-sim consistency`,
// docs/navigation-accuracy.md, "Filter consistency").
//
// Each run is the scenario's aided navigation (the board's pipeline and filter, float32 unless
// asked otherwise) with its own sensor noise (seed), GNSS noise (gnss.seed), an unknown
// per-sensor bias drawn from the filter's own prior ([aiding] bias_sigma_ug), which the sensors
// have and the compensator is not told, and a start off the truth drawn from the filter's P0
// (FilterConfig's initial σ): what the filter claims at its start and claims to estimate.
//
// NEES. Once per epoch (every second of scenario time) a run contributes x̂ᵀ P⁻¹ x̂ over the
// states whose σ the board publishes at that moment (NavAccuracy::valid): the tilt φ_N, φ_E
// (roll/pitch valid), φ_D (heading valid), δv (velocity valid), δr (position valid), x = the
// estimate minus the truth in the filter's own convention (error_model.hpp). For a consistent
// filter each is χ²(d), d the states used, and the sum over the runs is χ²(Σd). The statistic per
// epoch is that sum divided by Σd (1 expected), and its two-sided 95 % bounds are
// χ²_0.025(Σd)/Σd and χ²_0.975(Σd)/Σd (Wilson–Hilferty).
//
// NIS. Per GNSS fix (the same schedule in every run), the innovation νᵀ S⁻¹ ν of the position
// and of the velocity update (3-D each) of the runs that gated it (accepted or rejected; a fix
// that reset the quantity or came before the filter started has none), summed and divided by 3
// times the runs: the same bounds with Σd = 3·runs.
//
// Verdict. A consistent filter leaves each epoch (fix) outside its bounds with probability 5 %;
// ≥ 90 % inside is asked. With M independent epochs the number outside is Binomial(M, 0.05), and
// P(more than 10 % of M outside) is the false-failure probability stated with each verdict
// (consecutive epochs are correlated, which widens the true spread: the figure is a floor).
#pragma once

#include <Eigen/Core>
#include <array>
#include <csignal>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "gfins/host_sim/scenario.hpp"
#include "gfins/nav_core/filter/error_state_filter.hpp"

namespace gfins::sim {

/// The groups of published states whose NEES is also kept alone (each with its own marginal
/// covariance), to see which part of P is off: tilt (φ_N, φ_E), heading (φ_D), velocity,
/// position.
inline constexpr std::size_t kNeesGroups = 4;
inline constexpr std::array<const char*, kNeesGroups> kNeesGroupNames = {"tilt", "heading",
                                                                         "velocity", "position"};

/// What one run contributes: per epoch the NEES and its states (0: nothing published), the same
/// per group, per GNSS fix the NIS of its position and velocity updates (NaN: not gated).
struct ConsistencyRun {
  std::vector<double> nees;
  std::vector<int> dof;
  std::array<std::vector<double>, kNeesGroups> group_nees;
  std::array<std::vector<int>, kNeesGroups> group_dof;
  std::vector<double> nis_pos;
  std::vector<double> nis_vel;
};

/// Collects one run's ConsistencyRun from inside run_scenario_streamed (StreamTargets).
class ConsistencyRecorder {
 public:
  /// `epochs`: the scenario's whole seconds after t = 0 (1 .. floor(duration)).
  ConsistencyRecorder(std::size_t epochs, std::size_t fixes);

  /// The epoch a sample at t_s completes, or -1 when it completes none (the first sample at or
  /// after each whole second completes it).
  long due(double t_s) const;
  /// Epoch `k`: err = [φ; δr; δv] (the filter's first nine states, est − truth), p their
  /// covariance, `valid` the NavAccuracy::valid bits of the moment.
  void add_epoch(long k, const Eigen::Matrix<double, 9, 1>& err,
                 const Eigen::Matrix<double, 9, 9>& p, std::uint8_t valid);
  /// Fix `index` (sending order): its position and velocity updates' outcomes.
  void add_fix(std::size_t index, const nav::UpdateOutcome& pos, const nav::UpdateOutcome& vel);

  const ConsistencyRun& run() const { return run_; }

 private:
  ConsistencyRun run_;
  long next_ = 0;
};

/// One statistic (NEES per epoch or NIS per fix) over the runs.
struct ConsistencySeries {
  std::vector<double> t_s;     // epoch time, or the fix's time of validity
  std::vector<double> value;   // Σ statistic / Σ d (1 expected); NaN where no run had one
  std::vector<double> lo, hi;  // two-sided 95 % bounds of that ratio
  std::vector<double> dof;     // Σ d
  std::vector<bool> judged;    // at or after the window's start
  std::size_t offered = 0;     // epochs (fixes) with a value
  std::size_t inside = 0;      // ... within [lo, hi]
  std::size_t above = 0;       // ... above hi (optimistic)
  double false_failure = 0;    // P(Binomial(offered, 0.05) > 10 % of offered)
  bool pass() const { return offered > 0 && inside * 10 >= offered * 9; }
};

struct ConsistencyResult {
  std::size_t runs = 0;
  ConsistencySeries nees;
  std::array<ConsistencySeries, kNeesGroups> group_nees;
  ConsistencySeries nis_pos;
  ConsistencySeries nis_vel;
};

/// The χ² quantile at probability p with `dof` degrees of freedom, Wilson–Hilferty:
/// dof·(1 − 2/(9 dof) + z_p √(2/(9 dof)))³ (relative error below 1e-3 from 30 degrees of freedom).
double chi_square_quantile(double p, double dof);
/// P(X > k) for X ~ Binomial(n, p).
double binomial_upper_tail(std::size_t n, double p, std::size_t k);

/// Folds the runs (in order) into the three series; epochs before `from_s` are left out.
ConsistencyResult summarize_consistency(const std::vector<ConsistencyRun>& runs,
                                        const std::vector<double>& fix_t_s, double from_s);

/// Runs the scenario aided `runs` times (run k: seeds seed0 + k, the unknown bias from the
/// same) on `jobs` threads and summarizes from `from_s`; bit-identical for any `jobs`. `stop` as
/// run_montecarlo's. The scenario's [aiding] is switched on (as `gfins-sim aided` does); without
/// [gnss] the NIS series are empty.
/// `stated_sigma_scale`: StreamTargets::gnss_stated_sigma_scale (1: the receiver states its
/// accuracy truthfully).
HostResult<ConsistencyResult> run_consistency(const Scenario& base, std::size_t runs,
                                              std::uint64_t seed0, double from_s,
                                              const ProgressFn& progress, NavScalar scalar,
                                              std::size_t jobs, double stated_sigma_scale = 1.0,
                                              const volatile std::sig_atomic_t* stop = nullptr);

}  // namespace gfins::sim
