#include "gfins/host_sim/nav_loop.hpp"

namespace gfins::sim {
namespace {
template <typename T, typename Vec>
void hash_vector(Fnv1a64& h, const Vec& v) {
  for (Eigen::Index i = 0; i < v.size(); ++i) h.add_value<T>(v(i));
}
}  // namespace

template <typename T>
void hash_nav_state(Fnv1a64& h, const nav::NavState<T>& s) {
  h.add_value(s.t_ns);
  h.add_value(s.seq);
  h.add_value(s.status);
  hash_vector<T>(h, s.q_nb.coeffs());
  hash_vector<T>(h, s.w_b);
  hash_vector<T>(h, s.wdot_b);
  hash_vector<T>(h, s.f_b);
  hash_vector<T>(h, s.a_n);
  hash_vector<T>(h, s.v_n);
  hash_vector<T>(h, s.r_n);
}

template <typename T>
bool NavLoop<T>::step(const RawSample& s) {
  const std::uint64_t index = report_.samples;
  if ((s.flags & sample_flags::kCrcError) != 0) ++report_.invalid;
  if ((s.flags & sample_flags::kSaturated) != 0) ++report_.flagged_saturated;
  const nav::PipelineCounters before = pipeline_.counters();
  // A frame with a CRC error or flagged saturated is not a measurement: the pipeline rejects it
  // (is_measurement, raw_sample.hpp: counted in counters().rejected, state untouched, the gap
  // count of its seq kept, the next good frame integrates across the hole), as the board's loop
  // does. docs/replay.md: flagged frames are rejected.
  const nav::PipelinePhase phase = pipeline_.process(s);
  return finish(index, s.seq, before, phase);
}

template <typename T>
bool NavLoop<T>::step_specific_force(const nav::Vec6<T>& s_mps2, std::int64_t t_ns,
                                     std::uint32_t seq) {
  const std::uint64_t index = report_.samples;
  const nav::PipelineCounters before = pipeline_.counters();
  const nav::PipelinePhase phase = pipeline_.process_specific_force(s_mps2, t_ns, seq);
  return finish(index, seq, before, phase);
}

template <typename T>
bool NavLoop<T>::finish(std::uint64_t index, std::uint32_t seq, const nav::PipelineCounters& before,
                        nav::PipelinePhase phase) {
  ++report_.samples;
  const nav::PipelineCounters& after = pipeline_.counters();
  if (after.gaps != before.gaps) {
    // The pipeline counted one jump of the counter at this sample; it is reported, not recounted.
    NavGap g;
    g.index = index;
    g.seq = seq;
    g.missing = after.missed_samples - before.missed_samples;
    g.expected_seq = seq - g.missing;  // wraps like the counter
    report_.missed_samples += g.missing;
    report_.gaps.push_back(g);
  }
  report_.out_of_order += after.out_of_order - before.out_of_order;
  const bool rejected = after.rejected != before.rejected;
  if (rejected) ++report_.rejected;
  // A rejected sample leaves the state unchanged: it produced no output, so it is neither hashed
  // nor handed to the sink.
  if (phase != nav::PipelinePhase::kNavigating || rejected) return false;
  ++report_.navigating;
  hash_nav_state(hash_, pipeline_.state());
  report_.output_hash = hash_.value();
  if (sink_) sink_(index, pipeline_.state());
  return true;
}

template <typename T>
const NavReport& NavLoop<T>::run(std::span<const RawSample> samples) {
  for (const auto& s : samples) step(s);
  return report_;
}

template class NavLoop<float>;
template class NavLoop<double>;
template void hash_nav_state<float>(Fnv1a64&, const nav::NavState<float>&);
template void hash_nav_state<double>(Fnv1a64&, const nav::NavState<double>&);

}  // namespace gfins::sim
