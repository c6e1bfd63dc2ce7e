#include "gfins/app/nav_accuracy.hpp"

#include <cmath>
#include <cstddef>

namespace gfins::app {

can::Validity epoch_validity(const nav::NavPipeline<float>& p,
                             const nav::NavState<float>& published) {
  if (p.phase() != nav::PipelinePhase::kNavigating) return can::Validity::none();
  can::Validity v;  // every group valid
  if (!p.aiding().started()) return v;
  // The attitude error φ is a rotation of the navigation frame, the same for the board and the
  // vehicle; only its Euler-angle σ depend on whose attitude they describe.
  const std::uint8_t bits = p.aiding().accuracy(published).valid;
  v.attitude = (bits & nav::filter_valid::kRollPitch) != 0;
  v.velocity = (bits & nav::filter_valid::kVelocity) != 0;
  v.position = (bits & nav::filter_valid::kPosition) != 0;
  return v;
}

can::Accuracy epoch_accuracy(const nav::NavPipeline<float>& p, std::int64_t now_ns,
                             const nav::NavState<float>& published) {
  can::Accuracy a;  // σ NaN: not available
  if (!p.aiding().started()) return a;
  const nav::NavAccuracy<float> n = p.aiding().accuracy(published);
  a.sigma_roll_rad = n.euler_sigma_rad.x();
  a.sigma_pitch_rad = n.euler_sigma_rad.y();
  a.sigma_heading_rad = n.euler_sigma_rad.z();
  a.sigma_vel_h_mps = std::hypot(n.vel_sigma_mps.x(), n.vel_sigma_mps.y());
  a.sigma_vel_v_mps = n.vel_sigma_mps.z();
  a.sigma_pos_h_m = std::hypot(n.pos_sigma_m.x(), n.pos_sigma_m.y());
  a.sigma_pos_v_m = n.pos_sigma_m.z();
  a.filter_mode = n.mode == 0 ? can::filter_mode::kUnaided : 0;
  if ((n.mode & nav::filter_mode::kStandstill) != 0) a.filter_mode |= can::filter_mode::kStandstill;
  if ((n.mode & nav::filter_mode::kGnss) != 0) a.filter_mode |= can::filter_mode::kGnss;
  if ((n.mode & nav::filter_mode::kHeading) != 0) a.filter_mode |= can::filter_mode::kHeading;
  const nav::ErrorStateFilter<float>& f = p.aiding().filter();
  const nav::FilterCounters& c = f.counters();
  static_assert(static_cast<std::size_t>(nav::kAidingKinds) == can::kAidKindCount,
                "one aiding kind per bus counter");
  for (std::size_t k = 0; k < can::kAidKindCount; ++k) {
    can::AidCounter& out = a.aiding[k];
    out.accepted = c.accepted[k];
    out.rejected = c.rejected[k] + c.invalid[k];
    const std::int64_t t = f.last_accepted_ns(static_cast<nav::AidingKind>(k));
    if (t != INT64_MIN && now_ns >= t) {
      out.since_accepted_s = static_cast<float>(static_cast<double>(now_ns - t) * 1e-9);
    }
  }
  return a;
}

}  // namespace gfins::app
