// The per-sample navigation pipeline: front end → compensator → Chen mechanization → strapdown
// integrator, with static alignment at start. This is what the firmware's sample loop and the
// host simulation both run (docs/architecture.md, data flow).
#pragma once

#include <array>
#include <cmath>
#include <cstdint>

#include "gfins/nav_core/alignment.hpp"
#include "gfins/nav_core/compensator.hpp"
#include "gfins/nav_core/front_end.hpp"
#include "gfins/nav_core/geometry.hpp"
#include "gfins/nav_core/gravity.hpp"
#include "gfins/nav_core/integrator.hpp"
#include "gfins/nav_core/misalignment.hpp"
#include "gfins/sample/raw_sample.hpp"
#include "gfins/status/status.hpp"

namespace gfins::nav {

template <typename T>
struct PipelineConfig {
  ArrayGeometry<T, 6> nominal = table1_geometry<T>(T(0.1));
  FrontEndParams<T, 6> front_end{};
  Misalignment<T> misalignment{};
  CompensatorKind compensator = CompensatorKind::kNone;
  GravityModel<T> gravity = GravityModel<T>::constant(static_cast<T>(kStandardGravity));
  // In T like everything else: on the Cortex-M4F any double here would need the soft-float
  // routines at configure() (docs/performance.md, "no soft-float double anywhere").
  T max_condition = T(kDefaultMaxCondition);
  T sample_rate_hz = T(1000);
  std::uint32_t alignment_samples = 1000;  // samples at rest averaged before navigating
  T heading_rad = T(0);                    // given: nothing on board senses heading
  Vec3<T> r0_n = Vec3<T>::Zero();          // given initial position, m, NED
};

enum class PipelinePhase : std::uint8_t { kAligning, kNavigating };

/// Counters a pipeline keeps; they only grow (the firmware publishes them).
struct PipelineCounters {
  std::uint32_t samples = 0;         // samples offered
  std::uint32_t gaps = 0;            // jumps of the sample counter (counted here only)
  std::uint32_t missed_samples = 0;  // samples lost in those jumps
  std::uint32_t saturated = 0;       // samples with a channel at ADC full scale
  std::uint32_t rejected = 0;        // samples not integrated (saturated or kCrcError)
};

template <typename T>
class NavPipeline {
 public:
  using Outputs = Vec6<T>;

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
    if (!(config.sample_rate_hz > T(0)) || !std::isfinite(config.sample_rate_hz)) {
      return Status(ErrorCode::kInvalidArgument,
                    "pipeline: sample rate must be positive and finite");
    }
    config_ = config;
    front_end_ = fe.value();
    compensator_ = comp.value();
    compensator_.fold_into(solver.value());
    strapdown_ = Strapdown<T, 6>(solver.value(), config.gravity);
    aligner_.reset();
    have_seen_ = false;
    period_s_ = T(1) / config.sample_rate_hz;
    phase_ = PipelinePhase::kAligning;
    configured_ = true;
    return Status::ok();
  }

  /// Skips alignment: navigation starts at `initial` with this sample (simulation with known
  /// truth, or a warm start). Only the counts of `first` are used: initial.seq and initial.t_ns
  /// say which sample it is, and the next process() counts its gap against initial.seq. The
  /// counts must be a measurement (the caller has the truth, so it starts on a good sample).
  void start_at(const NavState<T>& initial, const RawSample& first) {
    Outputs s;
    front_end_.convert(first.counts, s);
    start_at_specific_force(initial, s);
  }

  /// One ADC frame: the pipeline's one input (docs/architecture.md, "one path for a sample").
  /// Returns the phase after it; in kNavigating, state() is valid at s.t_ns.
  ///
  /// Per frame, in this order:
  ///   - counters().samples grows;
  ///   - a jump of the sample counter against the previous frame offered (whatever became of
  ///     it) is a gap: counters().gaps and counters().missed_samples grow. This is the only place
  ///     in the project that counts sequence gaps (replay and the firmware read the counters);
  ///   - a frame with sample_flags::kCrcError carries counts that are not a measurement, and a
  ///     frame with a channel at either rail of the 24-bit code (FrontEnd::convert) is saturated:
  ///     both are rejected (counters().rejected; saturated also counts in counters().saturated)
  ///     and leave the state untouched. The next good frame integrates across the hole, over
  ///     the sample periods since the last integrated frame, with nav_status::kSampleGap.
  PipelinePhase process(const RawSample& s) {
    ++counters_.samples;
    count_gap(s.seq);
    Outputs f;
    const std::uint32_t saturated = front_end_.convert(s.counts, f);
    if (saturated != 0) ++counters_.saturated;
    if ((s.flags & sample_flags::kCrcError) != 0 || saturated != 0) {
      ++counters_.rejected;
      return phase_;
    }
    return integrate(f, s.t_ns, s.seq);
  }

  // ---- m/s² entry: the paper's §6.3 experiment only ------------------------------------------
  // The paper's §6.3 simulation feeds the mechanization with sensor outputs in m/s² (no converter,
  // noise σ stated in m/s²), so reproducing its Figs. 7-10 needs an entry after the front end.
  // Nothing else uses it: the board, replay, every other scenario, the tests and benchmarks enter
  // through process(const RawSample&) with counts (host_sim's scenario runner selects this entry
  // only for scenarios with `adc = false`, which only the paper-6.3 files set).

  /// start_at() for outputs already in m/s² (§6.3 only, see above).
  void start_at_specific_force(const NavState<T>& initial, const Outputs& s_raw) {
    Outputs s;
    compensator_.apply(s_raw, initial.w_b, initial.wdot_b, s);
    strapdown_.initialize(initial, s);
    mark_compensated();
    last_seq_ = initial.seq;
    last_seen_seq_ = initial.seq;
    have_seen_ = true;
    phase_ = PipelinePhase::kNavigating;
  }

  /// process() for outputs already in m/s² (§6.3 only, see above): same counters, no flags.
  PipelinePhase process_specific_force(const Outputs& s_raw, std::int64_t t_ns, std::uint32_t seq) {
    ++counters_.samples;
    count_gap(seq);
    return integrate(s_raw, t_ns, seq);
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
  /// Counts a jump of the sample counter against the previous frame offered (wraps at 2^32).
  void count_gap(std::uint32_t seq) {
    const std::uint32_t dseq = seq - last_seen_seq_;
    if (have_seen_ && dseq != 1) {
      ++counters_.gaps;
      counters_.missed_samples += dseq - 1;
    }
    last_seen_seq_ = seq;
    have_seen_ = true;
  }

  /// A good sample after the front end (m/s²): alignment, or one integration step over the
  /// sample periods since the last integrated sample.
  PipelinePhase integrate(const Outputs& s_raw, std::int64_t t_ns, std::uint32_t seq) {
    if (phase_ == PipelinePhase::kAligning) {
      align(s_raw, t_ns, seq);
      return phase_;
    }
    const std::uint32_t dseq = seq - last_seq_;  // wraps correctly at 2^32
    std::uint32_t status = nav_status::kAligned;
    if (dseq != 1) status |= nav_status::kSampleGap;  // lost or rejected samples in between
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
    start_at_specific_force(init, s_raw);
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
  std::uint32_t last_seq_ = 0;       // last integrated sample (integration step)
  std::uint32_t last_seen_seq_ = 0;  // last sample offered (gap counting)
  bool have_seen_ = false;
  PipelinePhase phase_ = PipelinePhase::kAligning;
  bool configured_ = false;
};

extern template class NavPipeline<float>;
extern template class NavPipeline<double>;

}  // namespace gfins::nav
