#include "gfins/host_sim/replay.hpp"

#include <vector>

namespace gfins::sim {

template <typename T>
HostResult<NavReport> replay_recording(const std::string& path, nav::NavPipeline<T>& pipeline,
                                       typename NavLoop<T>::Sink sink,
                                       const volatile std::sig_atomic_t* stop) {
  auto reader = RecordingReader::open(path);
  if (!reader.is_ok()) return reader.error();
  NavLoop<T> loop(pipeline, std::move(sink));
  std::vector<RawSample> block;
  for (;;) {
    auto more = reader.value().next_block(block);
    if (!more.is_ok()) return more.error();
    if (!more.value()) break;
    for (const RawSample& x : block) {
      if (stop != nullptr && *stop != 0) break;
      loop.step(x);
    }
    if (stop != nullptr && *stop != 0) break;
  }
  NavReport r = loop.report();
  r.frames_not_applied = reader.value().frames_read();
  return r;
}

template HostResult<NavReport> replay_recording<float>(const std::string&, nav::NavPipeline<float>&,
                                                       NavLoop<float>::Sink,
                                                       const volatile std::sig_atomic_t*);
template HostResult<NavReport> replay_recording<double>(const std::string&,
                                                        nav::NavPipeline<double>&,
                                                        NavLoop<double>::Sink,
                                                        const volatile std::sig_atomic_t*);

}  // namespace gfins::sim
