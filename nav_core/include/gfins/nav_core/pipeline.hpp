// The per-sample navigation pipeline: front end → compensator → Chen mechanization → strapdown
// integrator, with static alignment at start. This is what the firmware's sample loop and the
// host simulation both run (docs/architecture.md, data flow).
#pragma once

#include <array>
#include <cmath>
#include <cstdint>

#include "gfins/nav_core/alignment.hpp"
#include "gfins/nav_core/compensator.hpp"
#include "gfins/nav_core/filter/aiding.hpp"
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
  AidingConfig<T> aiding{};                // error-state filter and standstill updates (off)
  // With aiding on, the static alignment refuses a window that moved (and starts over):
  // RMS deviation of f from its mean, RMS of ω̇, and | |f̄| − g | beyond these. Defaults: 5 mg,
  // 0.5 rad/s² and 10 mg, several times the QA-1100 array's noise (docs/math.md).
  T align_max_f_noise_mps2 = T(0.05);
  T align_max_wdot_rms_rps2 = T(0.5);
  T align_gravity_tolerance_mps2 = T(0.1);
  // With aiding on, a GNSS velocity fix faster than aiding.gnss_moving_speed_mps refuses the
  // window in progress (kGnssMotion: a smooth acceleration reads like a tilt to accelerometers).
  // For a vehicle (aiding.filter.track_heading_sigma_rad > 0), a fix at least as fast as the
  // track's threshold (aiding.filter.track_min_speed_mps) starts navigation in motion at the next
  // sample: attitude, rate and heading unknown, every σ not available, until the fixes that
  // follow re-level the tilt and set the heading from the track (docs/math.md, "In-motion
  // alignment"). false: the board waits for a standstill.
  bool align_in_motion = true;
};

/// Why the last alignment window was refused (PipelineCounters::alignment_restarts counts them).
enum class AlignmentRefusal : std::uint8_t {
  kNone,
  kNotGravity,        // |f̄| < 1 m/s²: not a gravity vector (board not at rest, wrong units)
  kSpecificForce,     // f scattered beyond align_max_f_noise_mps2: the board moved
  kAngularAccel,      // ω̇ beyond align_max_wdot_rms_rps2: the board turned
  kGravityMagnitude,  // |f̄| differs from the gravity model: accelerating, or a wrong calibration
  kGnssMotion,        // a GNSS velocity fix said the board moves (align_in_motion)
};

enum class PipelinePhase : std::uint8_t { kAligning, kNavigating };

/// Counters a pipeline keeps; they only grow (the firmware publishes them).
struct PipelineCounters {
  std::uint32_t samples = 0;               // samples offered
  std::uint32_t gaps = 0;                  // jumps of the sample counter (counted here only)
  std::uint32_t missed_samples = 0;        // samples lost in those jumps
  std::uint32_t saturated = 0;             // samples with a channel at ADC full scale
  std::uint32_t rejected = 0;              // samples not integrated (saturated, kCrcError, or
                                           // out of order while navigating)
  std::uint32_t alignment_restarts = 0;    // alignment windows refused (last_refusal says why)
  std::uint32_t out_of_order = 0;          // samples whose counter repeated or went back: not
                                           // integrated (is_behind)
  std::uint32_t in_motion_alignments = 0;  // navigation started in motion (align_in_motion)
  AlignmentRefusal last_refusal = AlignmentRefusal::kNone;
};

template <typename T>
class NavPipeline {
 public:
  using Outputs = Vec6<T>;

  NavPipeline() = default;

  /// Builds every stage from `config`. On failure nothing changes: a pipeline that was running
  /// keeps its previous (last good) configuration.
  [[nodiscard]] Status configure(const PipelineConfig<T>& config);

  /// Whether configure() would accept `config`, with its message if not: the same checks, run
  /// on a scratch pipeline, so that a caller can refuse a calibration before it replaces the one
  /// in use. Needs sizeof(NavPipeline) of stack (about 7 kB for float): host and Linux only.
  [[nodiscard]] static Status check(const PipelineConfig<T>& config);

  /// Skips alignment: navigation starts at `initial` with this sample (simulation with known
  /// truth, or a warm start). Only the counts of `first` are used: initial.seq and initial.t_ns
  /// say which sample it is, and the next process() counts its gap against initial.seq. The
  /// counts must be a measurement (the caller has the truth, so it starts on a good sample).
  void start_at(const NavState<T>& initial, const RawSample& first);

  /// One ADC frame: the pipeline's one input (docs/architecture.md, "one path for a sample").
  /// Returns the phase after it; in kNavigating, state() is valid at s.t_ns.
  ///
  /// Per frame, in this order:
  ///   - counters().samples grows;
  ///   - a jump of the sample counter against the previous frame offered (whatever became of
  ///     it) is a gap: counters().gaps and counters().missed_samples grow. This is the only place
  ///     in the project that counts sequence gaps (replay and the firmware read the counters);
  ///     a counter that repeats or goes back is no gap: counters().out_of_order grows and the
  ///     frame is not integrated (no negative or 2^32-sample step); later frames count from it;
  ///   - a frame with sample_flags::kCrcError carries counts that are not a measurement, and a
  ///     frame with a channel at either rail of the 24-bit code (FrontEnd::convert) is saturated:
  ///     both are rejected (counters().rejected; saturated also counts in counters().saturated)
  ///     and leave the state untouched. The next good frame integrates across the hole, over
  ///     the sample periods since the last integrated frame, with nav_status::kSampleGap.
  PipelinePhase process(const RawSample& s);

  // ---- m/s² entry: the paper's §6.3 experiment only ------------------------------------------
  // The paper's §6.3 simulation feeds the mechanization with sensor outputs in m/s² (no converter,
  // noise σ stated in m/s²), so reproducing its Figs. 7-10 needs an entry after the front end.
  // Nothing else uses it: the board, replay, every other scenario, the tests and benchmarks enter
  // through process(const RawSample&) with counts (host_sim's scenario runner selects this entry
  // only for scenarios with `adc = false`, which only the paper-6.3 files set).

  /// start_at() for outputs already in m/s² (§6.3 only, see above).
  void start_at_specific_force(const NavState<T>& initial, const Outputs& s_raw);

  /// process() for outputs already in m/s² (§6.3 only, see above): same counters, no flags.
  PipelinePhase process_specific_force(const Outputs& s_raw, std::int64_t t_ns, std::uint32_t seq);

  // ---- Aiding (PipelineConfig::aiding) -------------------------------------------------------
  // External measurements with their own time of validity (GnssFix / HeadingFix::t_valid_ns, on
  // the samples' clock); each goes through the filter's χ² gate. Not aligned or aiding off:
  // kInvalid.

  UpdateOutcome offer_gnss_position(const GnssFix<T>& fix);
  /// While aligning (aiding on), a fix is not applied (kInvalid) but read for motion
  /// (PipelineConfig::align_in_motion).
  UpdateOutcome offer_gnss_velocity(const GnssFix<T>& fix);
  UpdateOutcome offer_heading(const HeadingFix<T>& fix);
  /// The filter, the detector and the accuracy of state(); aiding().started() says whether the
  /// σ mean anything (aiding on and aligned).
  const Aiding<T>& aiding() const { return aiding_; }
  NavAccuracy<T> accuracy() const;

  PipelinePhase phase() const { return phase_; }
  bool configured() const { return configured_; }
  const NavState<T>& state() const { return strapdown_.state(); }
  const PipelineCounters& counters() const { return counters_; }
  const PipelineConfig<T>& config() const { return config_; }
  const ArraySolver<T, 6>& solver() const { return strapdown_.solver(); }
  const FrontEnd<T, 6>& front_end() const { return front_end_; }
  const AlignmentResult<T>& alignment() const { return alignment_; }

  /// True when `seq` does not come after `prev`: the same counter again, or one that went back
  /// (a step of 2^31 or more modulo 2^32: at 1 kHz a forward jump that long is 25 days).
  static bool is_behind(std::uint32_t seq, std::uint32_t prev) {
    const std::uint32_t d = seq - prev;
    return d == 0 || d >= 0x80000000u;
  }

 private:
  /// Counts a jump of the sample counter against the previous frame offered (wraps at 2^32). A
  /// counter that repeats or goes back is not a gap (nothing was lost): counted as out of order.
  void count_gap(std::uint32_t seq) {
    const std::uint32_t dseq = seq - last_seen_seq_;
    if (have_seen_ && is_behind(seq, last_seen_seq_)) {
      ++counters_.out_of_order;
    } else if (have_seen_ && dseq != 1) {
      ++counters_.gaps;
      counters_.missed_samples += dseq - 1;
    }
    last_seen_seq_ = seq;
    have_seen_ = true;
  }

  /// A good sample after the front end (m/s²): alignment, or one integration step over the
  /// sample periods since the last integrated sample.
  PipelinePhase integrate(const Outputs& s_raw, std::int64_t t_ns, std::uint32_t seq);

  void align(const Outputs& s_raw, std::int64_t t_ns, std::uint32_t seq);

  /// The motion checks of an aided alignment (PipelineConfig); unaided, only the gravity-vector
  /// check of StaticAligner::finish applies.
  AlignmentRefusal refusal(const AlignmentResult<T>& a) const;

  /// A GNSS velocity fix while aligning: refuses a window that moved, arms the in-motion start
  /// (align() makes it at the next sample).
  void note_motion(const GnssFix<T>& fix);

  void mark_compensated() {
    if (compensator_.kind() != CompensatorKind::kNone) {
      strapdown_.mutable_state().status |= nav_status::kCompensated;
    }
  }

  PipelineConfig<T> config_{};
  FrontEnd<T, 6> front_end_{};
  Compensator<T> compensator_{};
  Strapdown<T, 6> strapdown_{};
  Aiding<T> aiding_{};
  StaticAligner<T, 6> aligner_{};
  AlignmentResult<T> alignment_{};
  PipelineCounters counters_{};
  T period_s_ = T(0.001);
  std::uint32_t last_seq_ = 0;       // last integrated sample (integration step)
  std::uint32_t last_seen_seq_ = 0;  // last sample offered (gap counting)
  bool have_seen_ = false;
  PipelinePhase phase_ = PipelinePhase::kAligning;
  bool configured_ = false;
  bool in_motion_pending_ = false;           // note_motion: start in motion at the next sample
  Vec3<T> in_motion_v_n_ = Vec3<T>::Zero();  // the fix that armed it: velocity, m/s NED
};

// ---- NavPipeline: member functions defined outside the class, so not inline: a translation unit
// that uses the extern instantiation below calls them instead of instantiating them again
// to inline them (nav_core/src instantiates each once per scalar type).

template <typename T>
Status NavPipeline<T>::configure(const PipelineConfig<T>& config) {
  const auto fe = FrontEnd<T, 6>::create(config.front_end);
  if (!fe.is_ok()) return fe.status();
  const auto comp = Compensator<T>::create(config.compensator, config.nominal, config.misalignment);
  if (!comp.is_ok()) return comp.status();
  const auto solver = ArraySolver<T, 6>::create(
      Compensator<T>::solver_geometry(config.compensator, config.nominal, config.misalignment),
      config.max_condition);
  if (!solver.is_ok()) return solver.status();
  if (!(config.sample_rate_hz > T(0)) || !std::isfinite(config.sample_rate_hz)) {
    return Status(ErrorCode::kInvalidArgument, "pipeline: sample rate must be positive and finite");
  }
  Aiding<T> aiding;
  const Status as = aiding.configure(solver.value(), config.aiding);
  if (!as.is_ok()) return as;
  config_ = config;
  front_end_ = fe.value();
  compensator_ = comp.value();
  compensator_.fold_into(solver.value());
  strapdown_ = Strapdown<T, 6>(solver.value(), config.gravity);
  aiding_ = aiding;
  aligner_.reset();
  in_motion_pending_ = false;
  have_seen_ = false;
  period_s_ = T(1) / config.sample_rate_hz;
  phase_ = PipelinePhase::kAligning;
  configured_ = true;
  return Status::ok();
}

template <typename T>
Status NavPipeline<T>::check(const PipelineConfig<T>& config) {
  NavPipeline<T> scratch;
  return scratch.configure(config);
}

template <typename T>
void NavPipeline<T>::start_at(const NavState<T>& initial, const RawSample& first) {
  Outputs s;
  front_end_.convert(first.counts, s);
  start_at_specific_force(initial, s);
}

// process() and integrate() stay inline: the per-sample path, inlined with the strapdown step
// where the sample loop calls it (docs/performance.md, instructions per sample); the filter behind
// it (Aiding::after_step, once per sample) stays a call into the instantiation.
template <typename T>
inline PipelinePhase NavPipeline<T>::process(const RawSample& s) {
  ++counters_.samples;
  count_gap(s.seq);
  Outputs f;
  // is_measurement() (raw_sample.hpp), with the rails found by the conversion itself.
  const std::uint32_t saturated = front_end_.convert(s.counts, f);
  if (saturated != 0 || (s.flags & sample_flags::kSaturated) != 0) ++counters_.saturated;
  if ((s.flags & sample_flags::kNotMeasured) != 0 || saturated != 0) {
    ++counters_.rejected;
    return phase_;
  }
  return integrate(f, s.t_ns, s.seq);
}

template <typename T>
void NavPipeline<T>::start_at_specific_force(const NavState<T>& initial, const Outputs& s_raw) {
  Outputs s;
  compensator_.apply(s_raw, initial.w_b, initial.wdot_b, s);
  strapdown_.initialize(initial, s);
  aiding_.start(strapdown_);
  mark_compensated();
  last_seq_ = initial.seq;
  last_seen_seq_ = initial.seq;
  have_seen_ = true;
  phase_ = PipelinePhase::kNavigating;
}

template <typename T>
PipelinePhase NavPipeline<T>::process_specific_force(const Outputs& s_raw, std::int64_t t_ns,
                                                     std::uint32_t seq) {
  ++counters_.samples;
  count_gap(seq);
  return integrate(s_raw, t_ns, seq);
}

template <typename T>
UpdateOutcome NavPipeline<T>::offer_gnss_position(const GnssFix<T>& fix) {
  return aiding_.offer_gnss_position(strapdown_, fix);
}

template <typename T>
UpdateOutcome NavPipeline<T>::offer_gnss_velocity(const GnssFix<T>& fix) {
  if (phase_ == PipelinePhase::kAligning && aiding_.enabled()) note_motion(fix);
  return aiding_.offer_gnss_velocity(strapdown_, fix);
}

template <typename T>
void NavPipeline<T>::note_motion(const GnssFix<T>& fix) {
  if (!fix.value_n.allFinite()) return;
  const T speed = fix.value_n.template head<2>().norm();
  if (!(speed > config_.aiding.gnss_moving_speed_mps)) return;
  if (aligner_.count() > 0) {
    aligner_.reset();
    ++counters_.alignment_restarts;
    counters_.last_refusal = AlignmentRefusal::kGnssMotion;
  }
  const FilterConfig<T>& f = config_.aiding.filter;
  if (config_.align_in_motion && f.track_heading_sigma_rad > T(0) &&
      speed >= f.track_min_speed_mps) {
    in_motion_pending_ = true;
    in_motion_v_n_ = fix.value_n;
  }
}

template <typename T>
UpdateOutcome NavPipeline<T>::offer_heading(const HeadingFix<T>& fix) {
  return aiding_.offer_heading(strapdown_, fix);
}

template <typename T>
NavAccuracy<T> NavPipeline<T>::accuracy() const {
  return aiding_.accuracy(strapdown_.state());
}

template <typename T>
inline PipelinePhase NavPipeline<T>::integrate(const Outputs& s_raw, std::int64_t t_ns,
                                               std::uint32_t seq) {
  if (phase_ == PipelinePhase::kAligning) {
    align(s_raw, t_ns, seq);
    return phase_;
  }
  if (is_behind(seq, last_seq_)) {
    // The same sample again, or a counter that went back (a recording spliced or rewound, an ADC
    // reset): no time to integrate. Later samples count from this one; the state is flagged.
    last_seq_ = seq;
    ++counters_.rejected;
    strapdown_.mutable_state().status |= nav_status::kSampleGap;
    return phase_;
  }
  const std::uint32_t dseq = seq - last_seq_;  // wraps correctly at 2^32
  std::uint32_t status = nav_status::kAligned;
  if (dseq != 1) status |= nav_status::kSampleGap;  // lost or rejected samples in between
  last_seq_ = seq;
  const NavState<T>& st = strapdown_.state();
  const T dt_s = period_s_ * static_cast<T>(dseq);
  // u = M s with the compensator folded in (Compensator::fold_into): one product per sample.
  strapdown_.step_linear(
      compensator_.padded_linear_part(strapdown_.solver(), s_raw, st.w_b, st.wdot_b), dt_s, t_ns,
      seq);
  if (aiding_.started()) aiding_.after_step(strapdown_, dt_s);
  strapdown_.mutable_state().status = status;
  mark_compensated();
  return phase_;
}

template <typename T>
void NavPipeline<T>::align(const Outputs& s_raw, std::int64_t t_ns, std::uint32_t seq) {
  Outputs s;
  compensator_.apply(s_raw, Vec3<T>::Zero(), Vec3<T>::Zero(), s);
  // In motion (note_motion armed it): this sample alone gives a first guess of the tilt, as if at
  // rest (level when it is no gravity vector), the fix's track the heading; the filter starts
  // with the attitude lost and the fixes that follow align it.
  const bool in_motion = in_motion_pending_;
  if (in_motion) aligner_.reset();
  aligner_.add(strapdown_.solver(), s);
  if (!in_motion && aligner_.count() < config_.alignment_samples) return;
  const auto result = aligner_.finish(in_motion ? 1 : config_.alignment_samples);
  AlignmentRefusal why = result.is_ok() ? refusal(result.value()) : AlignmentRefusal::kNotGravity;
  if (in_motion) why = AlignmentRefusal::kNone;
  if (why != AlignmentRefusal::kNone) {
    aligner_.reset();  // start over (board moving, not connected, or the wrong calibration)
    ++counters_.alignment_restarts;
    counters_.last_refusal = why;
    return;
  }
  alignment_ = result.is_ok() ? result.value() : AlignmentResult<T>{};
  const T heading =
      in_motion ? std::atan2(in_motion_v_n_.y(), in_motion_v_n_.x()) : config_.heading_rad;
  NavState<T> init = StaticAligner<T, 6>::initial_state(alignment_, heading, config_.r0_n, t_ns);
  init.seq = seq;
  if (!in_motion) {
    start_at_specific_force(init, s_raw);
    return;
  }
  init.v_n = in_motion_v_n_;
  alignment_ = AlignmentResult<T>{};  // no static alignment: nothing to check gravity against
  aligner_.reset();
  in_motion_pending_ = false;
  ++counters_.in_motion_alignments;
  start_at_specific_force(init, s_raw);
  aiding_.lose_attitude(strapdown_);
}

template <typename T>
AlignmentRefusal NavPipeline<T>::refusal(const AlignmentResult<T>& a) const {
  if (!config_.aiding.enabled) return AlignmentRefusal::kNone;
  if (!(a.f_noise_mps2 <= config_.align_max_f_noise_mps2)) return AlignmentRefusal::kSpecificForce;
  if (!(a.wdot_rms_rps2 <= config_.align_max_wdot_rms_rps2)) return AlignmentRefusal::kAngularAccel;
  const T g = config_.gravity.magnitude_at_origin();
  if (!(std::abs(a.gravity_mps2 - g) <= config_.align_gravity_tolerance_mps2)) {
    return AlignmentRefusal::kGravityMagnitude;
  }
  return AlignmentRefusal::kNone;
}

extern template class NavPipeline<float>;
extern template class NavPipeline<double>;

}  // namespace gfins::nav
