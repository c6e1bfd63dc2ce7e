// One aided-filter operation at a time, for the filter's cost figures (docs/performance.md):
// the error-state filter of a board at rest at the alignment point (identity attitude, table 1
// geometry, ρ = 0.1 m), started, then one operation repeated. The cost of the filter's dense
// 18-state algebra does not depend on the values; at rest every update is accepted (zero
// innovation), so each call does the whole update: gain, Joseph-form covariance, feedback.
//
// The same rig runs under callgrind and Google Benchmark on the host (tests/bench/filter_ir.cpp,
// filter_bench.cpp) and in the QEMU build of the bare-metal probe (main.cpp), whose trace
// scripts/m4f_step_cycles.sh costs in Cortex-M4F cycles: nav_core headers only, no heap.
#pragma once

#include <cstdint>

#include "gfins/nav_core/filter/error_state_filter.hpp"
#include "gfins/nav_core/geometry.hpp"
#include "gfins/nav_core/gravity.hpp"
#include "gfins/nav_core/integrator.hpp"

namespace gfins::bench {

enum class FilterOp { kPropagate, kZupt, kZaru, kGnssPosition, kGnssVelocity, kHeading };

inline const char* to_string(FilterOp op) {
  switch (op) {
    case FilterOp::kPropagate:
      return "propagate";
    case FilterOp::kZupt:
      return "zupt";
    case FilterOp::kZaru:
      return "zaru";
    case FilterOp::kGnssPosition:
      return "gnss-position";
    case FilterOp::kGnssVelocity:
      return "gnss-velocity";
    case FilterOp::kHeading:
      return "heading";
  }
  return "?";
}

inline constexpr FilterOp kFilterOps[] = {FilterOp::kPropagate,    FilterOp::kZupt,
                                          FilterOp::kZaru,         FilterOp::kGnssPosition,
                                          FilterOp::kGnssVelocity, FilterOp::kHeading};

template <typename T>
class FilterRig {
 public:
  /// Propagation interval: the board propagates every 10th sample at 1 kHz.
  static constexpr T kDt = T(0.01);

  FilterRig()
      : solver_(nav::ArraySolver<T>::create(nav::table1_geometry<T>(T(0.1))).value()),
        gravity_(nav::GravityModel<T>::constant(T(9.80665))),
        nav_(solver_, gravity_) {
    // At rest, level: every accelerometer reads the projection of f_b = (0, 0, −g) on its axis
    // (the lever-arm terms vanish without rotation).
    nav::Vec6<T> s0;
    const nav::Vec3<T> f_b(T(0), T(0), -T(9.80665));
    for (int j = 0; j < 6; ++j) {
      s0(j) = solver_.geometry().theta_b[static_cast<std::size_t>(j)].dot(f_b);
    }
    nav_.initialize(nav::NavState<T>{}, s0);
    nav::FilterConfig<T> config;
    config.heading_known = true;  // GNSS fixes are updates, not the resets of heading alignment
    ok_ = filter().configure(config).is_ok();
    if (ok_) filter().start(nav_);
  }

  bool ok() const { return ok_; }

  /// One `op`; true when the filter accepted it.
  bool run(FilterOp op) {
    nav::ErrorStateFilter<T>& f = filter();
    switch (op) {
      case FilterOp::kPropagate:
        return f.propagate(nav_, kDt).is_ok();
      case FilterOp::kZupt:
        return f.update_zupt(nav_).status == nav::UpdateStatus::kAccepted;
      case FilterOp::kZaru:
        return f.update_zaru(nav_).status == nav::UpdateStatus::kAccepted;
      case FilterOp::kGnssPosition:
      case FilterOp::kGnssVelocity: {
        nav::GnssFix<T> fix;
        fix.t_valid_ns = nav_.state().t_ns;
        fix.value_n = op == FilterOp::kGnssPosition ? nav_.state().r_n : nav_.state().v_n;
        fix.sigma = nav::Vec3<T>::Constant(op == FilterOp::kGnssPosition ? T(1.5) : T(0.1));
        const auto out = op == FilterOp::kGnssPosition ? f.update_gnss_position(nav_, fix)
                                                       : f.update_gnss_velocity(nav_, fix);
        return out.status == nav::UpdateStatus::kAccepted;
      }
      case FilterOp::kHeading:
        return f.update_heading(nav_, nav::HeadingFix<T>{nav_.state().t_ns, T(0), T(0.01)})
                   .status == nav::UpdateStatus::kAccepted;
    }
    return false;
  }

  /// A number that depends on the whole covariance, so the work cannot be optimised away.
  double checksum() const { return static_cast<double>(filter().covariance().trace()); }

 private:
  // Static: 18×18 matrices and the history stay off the stack (as on the board).
  static nav::ErrorStateFilter<T>& filter() {
    static nav::ErrorStateFilter<T> f;
    return f;
  }
  nav::ArraySolver<T> solver_;
  nav::GravityModel<T> gravity_;
  nav::Strapdown<T> nav_;
  bool ok_ = false;
};

}  // namespace gfins::bench
