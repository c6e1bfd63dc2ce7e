// The per-sample navigation pipeline: front end → compensator → Chen mechanization → strapdown
// integrator, with static alignment at start. This is what the firmware's sample loop and the
// host simulation both run (DESIGN.md, data flow).
#pragma once

#include <array>
#include <cstdint>

#include "gfins/nav_core/alignment.hpp"
#include "gfins/nav_core/compensator.hpp"
#include "gfins/nav_core/front_end.hpp"
#include "gfins/nav_core/geometry.hpp"
#include "gfins/nav_core/gravity.hpp"
#include "gfins/nav_core/integrator.hpp"
#include "gfins/nav_core/misalignment.hpp"
#include "gfins/status/status.hpp"

namespace gfins::nav {

template <typename T>
struct PipelineConfig {
  ArrayGeometry<T, 6> nominal = table1_geometry<T>(T(0.1));
  FrontEndParams<T, 6> front_end{};
  Misalignment<T> misalignment{};
  CompensatorKind compensator = CompensatorKind::kNone;
  GravityModel<T> gravity = GravityModel<T>::constant(static_cast<T>(kStandardGravity));
  double max_condition = kDefaultMaxCondition;
  double sample_rate_hz = 1000.0;
  std::uint32_t alignment_samples = 1000;  // samples at rest averaged before navigating
  T heading_rad = T(0);                    // given: nothing on board senses heading
  Vec3<T> r0_n = Vec3<T>::Zero();          // given initial position, m, NED
};

enum class PipelinePhase : std::uint8_t { kAligning, kNavigating };

/// Counters a pipeline keeps; they only grow (the firmware publishes them).
struct PipelineCounters {
  std::uint32_t samples = 0;         // samples offered
  std::uint32_t gaps = 0;            // jumps of the sample counter
  std::uint32_t missed_samples = 0;  // samples lost in those jumps
  std::uint32_t saturated = 0;       // samples with a channel at ADC full scale
  std::uint32_t rejected = 0;        // samples not integrated (saturated or marked invalid)
};

template <typename T>
class NavPipeline {
 public:
  using Outputs = Vec6<T>;
  using Counts = std::array<std::int32_t, 6>;

  NavPipeline() = default;

  /// Builds every stage from `config`. On failure nothing changes: a pipeline that was running
  /// keeps its previous (last good) configuration.
  [[nodiscard]] Status configure(const PipelineConfig<T>& config) {
    const auto fe = FrontEnd<T, 6>::create(config.front_end);
    if (!fe.is_ok()) return fe.status();
    const auto comp =
        Compensator<T>::create(config.compensator, config.nominal, config.misalignment);
    if (!comp.is_ok()) return comp.status();
    const auto solver = ArraySolver<T, 6>::create(
        Compensator<T>::solver_geometry(config.compensator, config.nominal, config.misalignment),
        config.max_condition);
    if (!solver.is_ok()) return solver.status();
    if (!(config.sample_rate_hz > 0.0)) {
      return Status(ErrorCode::kInvalidArgument, "pipeline: sample rate must be positive");
    }
    config_ = config;
    front_end_ = fe.value();
    compensator_ = comp.value();
    compensator_.fold_into(solver.value());
    strapdown_ = Strapdown<T, 6>(solver.value(), config.gravity);
    aligner_.reset();
    period_s_ = static_cast<T>(1.0 / config.sample_rate_hz);
    phase_ = PipelinePhase::kAligning;
    configured_ = true;
    return Status::ok();
  }

  /// Skips alignment: navigation starts at `initial` with this sample (simulation with known
  /// truth, or a warm start).
  void start_at(const NavState<T>& initial, const Counts& counts) {
    Outputs s;
    front_end_.convert(counts, s);
    start_at_outputs(initial, s);
  }
  void start_at_outputs(const NavState<T>& initial, const Outputs& s_raw) {
    Outputs s;
    compensator_.apply(s_raw, initial.w_b, initial.wdot_b, s);
    strapdown_.initialize(initial, s);
    mark_compensated();
    last_seq_ = initial.seq;
    phase_ = PipelinePhase::kNavigating;
  }

  /// One ADC sample. Returns the phase after it; in kNavigating state() is valid at t_ns.
  PipelinePhase process(const Counts& counts, std::int64_t t_ns, std::uint32_t seq,
                        bool input_valid = true) {
    Outputs s;
    const std::uint32_t saturated = front_end_.convert(counts, s);
    if (saturated != 0) ++counters_.saturated;
    return process_outputs(s, t_ns, seq, input_valid && saturated == 0);
  }

  /// Same as process() for outputs already in m/s² (after the front end).
  PipelinePhase process_outputs(const Outputs& s_raw, std::int64_t t_ns, std::uint32_t seq,
                                bool input_valid = true) {
    ++counters_.samples;
    if (!input_valid) {
      // A rejected sample is skipped; the next good one integrates across the hole (seq jump).
      ++counters_.rejected;
      return phase_;
    }
    if (phase_ == PipelinePhase::kAligning) {
      align(s_raw, t_ns, seq);
      return phase_;
    }
    const std::uint32_t dseq = seq - last_seq_;  // wraps correctly at 2^32
    std::uint32_t status = nav_status::kAligned;
    if (dseq != 1) {
      ++counters_.gaps;
      counters_.missed_samples += dseq - 1;
      status |= nav_status::kSampleGap;
    }
    last_seq_ = seq;
    const NavState<T>& st = strapdown_.state();
    // u = M s with the compensator folded in (Compensator::fold_into): one product per sample.
    strapdown_.step_linear(
        compensator_.padded_linear_part(strapdown_.solver(), s_raw, st.w_b, st.wdot_b),
        period_s_ * static_cast<T>(dseq == 0 ? 1u : dseq), t_ns, seq);
    strapdown_.mutable_state().status = status;
    mark_compensated();
    return phase_;
  }

  PipelinePhase phase() const { return phase_; }
  bool configured() const { return configured_; }
  const NavState<T>& state() const { return strapdown_.state(); }
  const PipelineCounters& counters() const { return counters_; }
  const PipelineConfig<T>& config() const { return config_; }
  const ArraySolver<T, 6>& solver() const { return strapdown_.solver(); }
  const FrontEnd<T, 6>& front_end() const { return front_end_; }
  const AlignmentResult<T>& alignment() const { return alignment_; }

 private:
  void align(const Outputs& s_raw, std::int64_t t_ns, std::uint32_t seq) {
    Outputs s;
    compensator_.apply(s_raw, Vec3<T>::Zero(), Vec3<T>::Zero(), s);
    aligner_.add(strapdown_.solver(), s);
    if (aligner_.count() < config_.alignment_samples) return;
    const auto result = aligner_.finish(config_.alignment_samples);
    if (!result.is_ok()) {
      aligner_.reset();  // not a gravity vector: start over (board moving or not connected)
      return;
    }
    alignment_ = result.value();
    NavState<T> init =
        StaticAligner<T, 6>::initial_state(alignment_, config_.heading_rad, config_.r0_n, t_ns);
    init.seq = seq;
    start_at_outputs(init, s_raw);
  }

  void mark_compensated() {
    if (compensator_.kind() != CompensatorKind::kNone) {
      strapdown_.mutable_state().status |= nav_status::kCompensated;
    }
  }

  PipelineConfig<T> config_{};
  FrontEnd<T, 6> front_end_{};
  Compensator<T> compensator_{};
  Strapdown<T, 6> strapdown_{};
  StaticAligner<T, 6> aligner_{};
  AlignmentResult<T> alignment_{};
  PipelineCounters counters_{};
  T period_s_ = T(0.001);
  std::uint32_t last_seq_ = 0;
  PipelinePhase phase_ = PipelinePhase::kAligning;
  bool configured_ = false;
};

extern template class NavPipeline<float>;
extern template class NavPipeline<double>;

}  // namespace gfins::nav
