// An aiding input, decoded from its frames (aiding_input.hpp), offered to the navigation
// pipeline: the one conversion from the bus's fix to the filter's, used by the firmware loop and
// by the hardware-in-the-loop host's reference run, so both apply a fix the same way.
#pragma once

#include <cmath>
#include <cstdint>

#include "gfins/can/aiding_input.hpp"
#include "gfins/nav_core/filter/error_state_filter.hpp"
#include "gfins/nav_core/filter/euler_error.hpp"
#include "gfins/nav_core/filter/gnss_update.hpp"

namespace gfins::can {

/// Time of validity of an aiding input on the loop's clock: its reception less the age the
/// sender stated (docs/can-interface.md, "Time of validity"; the bus transit, under a
/// millisecond at 500 kbit/s, is not in it).
inline std::int64_t valid_at(std::int64_t received_ns, double age_s) {
  return received_ns - static_cast<std::int64_t>(std::llround(age_s * 1e9));
}

/// Offers a complete GNSS fix (its position and velocity parts, as present) or a heading to
/// `pipeline` (a nav::NavPipeline<float>), received at `received_ns`. Returns kRejected or
/// kInvalid when any part was refused (the filter counts each), else kAccepted.
template <class Pipeline>
nav::UpdateStatus offer_input(Pipeline& pipeline, const InputEvent& e, std::int64_t received_ns) {
  nav::UpdateStatus worst = nav::UpdateStatus::kAccepted;
  const auto note = [&worst](const nav::UpdateOutcome& o) {
    if (o.status == nav::UpdateStatus::kRejected || o.status == nav::UpdateStatus::kInvalid)
      worst = o.status;
  };
  if (e.kind == InputEventKind::kGnssFix) {
    const GnssFix& g = e.gnss;
    nav::GnssFix<float> fix;
    fix.t_valid_ns = valid_at(received_ns, g.age_s);
    if (g.has_position) {
      fix.value_n = nav::Vec3<double>(g.r_n_m[0], g.r_n_m[1], g.r_n_m[2]).cast<float>();
      fix.sigma =
          nav::Vec3<double>(g.sigma_pos_h_m, g.sigma_pos_h_m, g.sigma_pos_v_m).cast<float>();
      note(pipeline.offer_gnss_position(fix));
    }
    if (g.has_velocity) {
      fix.value_n = nav::Vec3<double>(g.v_n_mps[0], g.v_n_mps[1], g.v_n_mps[2]).cast<float>();
      fix.sigma.setConstant(static_cast<float>(g.sigma_vel_mps));
      note(pipeline.offer_gnss_velocity(fix));
    }
  } else if (e.kind == InputEventKind::kHeadingFix) {
    nav::HeadingFix<float> fix;
    fix.t_valid_ns = valid_at(received_ns, e.heading.age_s);
    fix.yaw_rad = static_cast<float>(e.heading.heading_rad);
    fix.sigma_rad = static_cast<float>(e.heading.sigma_rad);
    note(pipeline.offer_heading(fix));
  }
  return worst;
}

}  // namespace gfins::can
