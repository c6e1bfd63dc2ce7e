#include "gfins/host_sim/replay.hpp"

#include <vector>

namespace gfins::sim {

template <typename T>
HostResult<NavReport> replay_recording(const std::string& path, nav::NavPipeline<T>& pipeline,
                                       typename NavLoop<T>::Sink sink) {
  auto reader = RecordingReader::open(path);
  if (!reader.is_ok()) return reader.error();
  NavLoop<T> loop(pipeline, std::move(sink));
  std::vector<RawSample> block;
  for (;;) {
    auto more = reader.value().next_block(block);
    if (!more.is_ok()) return more.error();
    if (!more.value()) break;
    loop.run(block);
  }
  return loop.report();
}

template HostResult<NavReport> replay_recording<float>(const std::string&, nav::NavPipeline<float>&,
                                                       NavLoop<float>::Sink);
template HostResult<NavReport> replay_recording<double>(const std::string&,
                                                        nav::NavPipeline<double>&,
                                                        NavLoop<double>::Sink);

}  // namespace gfins::sim
