#include "gfins/host_sim/replay.hpp"

#include <array>
#include <cstring>

namespace gfins::sim {

void Fnv1a64::add(std::span<const std::uint8_t> bytes) {
  for (const std::uint8_t b : bytes) {
    h_ ^= b;
    h_ *= 0x100000001b3ull;
  }
}

template <typename V>
void Fnv1a64::add_value(const V& v) {
  std::array<std::uint8_t, sizeof(V)> b{};
  std::memcpy(b.data(), &v, sizeof(V));
  add(b);
}

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
void Replayer<T>::step(const RawSample& s) {
  const std::uint64_t index = report_.samples;
  if (have_last_ && s.seq != last_seq_ + 1u) {
    ReplayGap g;
    g.index = index;
    g.expected_seq = last_seq_ + 1u;
    g.seq = s.seq;
    g.missing = s.seq - g.expected_seq;  // wraps at 2^32 like the counter
    report_.missed_samples += g.missing;
    report_.gaps.push_back(g);
  }
  last_seq_ = s.seq;
  have_last_ = true;
  const bool valid = (s.flags & sample_flags::kCrcError) == 0;
  if (!valid) ++report_.invalid;
  if ((s.flags & sample_flags::kSaturated) != 0) ++report_.flagged_saturated;
  ++report_.samples;
  // A sample the pipeline rejects (invalid or saturated) leaves its state unchanged: it produced
  // no output, so it is neither hashed nor handed to the sink.
  const std::uint32_t rejected_before = pipeline_.counters().rejected;
  const nav::PipelinePhase phase = pipeline_.process(s.counts, s.t_ns, s.seq, valid);
  if (phase == nav::PipelinePhase::kNavigating &&
      pipeline_.counters().rejected == rejected_before) {
    ++report_.navigating;
    hash_nav_state(hash_, pipeline_.state());
    if (sink_) sink_(index, pipeline_.state());
  }
  report_.output_hash = hash_.value();
}

template <typename T>
const ReplayReport& Replayer<T>::run(std::span<const RawSample> samples) {
  for (const auto& s : samples) step(s);
  return report_;
}

template <typename T>
RecordingResult<ReplayReport> replay_recording(const std::string& path,
                                               nav::NavPipeline<T>& pipeline,
                                               typename Replayer<T>::Sink sink) {
  auto reader = RecordingReader::open(path);
  if (!reader.is_ok()) return reader.error();
  Replayer<T> replayer(pipeline, std::move(sink));
  std::vector<RawSample> block;
  for (;;) {
    auto more = reader.value().next_block(block);
    if (!more.is_ok()) return more.error();
    if (!more.value()) break;
    replayer.run(block);
  }
  return replayer.report();
}

template class Replayer<float>;
template class Replayer<double>;
template void hash_nav_state<float>(Fnv1a64&, const nav::NavState<float>&);
template void hash_nav_state<double>(Fnv1a64&, const nav::NavState<double>&);
template RecordingResult<ReplayReport> replay_recording<float>(const std::string&,
                                                               nav::NavPipeline<float>&,
                                                               Replayer<float>::Sink);
template RecordingResult<ReplayReport> replay_recording<double>(const std::string&,
                                                                nav::NavPipeline<double>&,
                                                                Replayer<double>::Sink);

}  // namespace gfins::sim
