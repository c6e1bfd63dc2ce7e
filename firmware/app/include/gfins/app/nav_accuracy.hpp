// What the bus says about how far a navigation value can be trusted (docs/can-interface.md,
// "Validity and accuracy"): per group valid or not available, and the filter's 1σ, mode and
// aiding counters, from the navigation core's pipeline.
#pragma once

#include <cstdint>

#include "gfins/can/epoch.hpp"
#include "gfins/nav_core/pipeline.hpp"

namespace gfins::app {

/// Aligning: nothing valid (never an identity quaternion or a made-up zero). Navigating unaided:
/// every group valid, as the paper's navigation has no σ to judge it by. Aided: attitude while
/// the roll/pitch 1σ is within the filter's horizon, velocity and position while theirs are;
/// rates and accelerations (measured every sample) while navigating. `published` is the state as
/// the epoch carries it (in the vehicle frame when the board is mounted rotated): the Euler
/// angles' σ are those of its attitude.
can::Validity epoch_validity(const nav::NavPipeline<float>& p,
                             const nav::NavState<float>& published);

/// The filter's 1σ (roll, pitch, heading of `published`, horizontal/vertical velocity and
/// position), its mode and the aiding counters at `now_ns`; every σ not available (NaN) when no
/// filter runs.
can::Accuracy epoch_accuracy(const nav::NavPipeline<float>& p, std::int64_t now_ns,
                             const nav::NavState<float>& published);

}  // namespace gfins::app
