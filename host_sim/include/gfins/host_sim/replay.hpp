// Replay of recorded (or any) streams of RawSample values through the one navigation loop
// (nav_loop.hpp): the same report, hash and sink as every other host run.
#pragma once

#include <span>
#include <string>

#include "gfins/host_sim/error.hpp"
#include "gfins/host_sim/nav_loop.hpp"
#include "gfins/host_sim/recording.hpp"
#include "gfins/nav_core/pipeline.hpp"
#include "gfins/sample/raw_sample.hpp"

namespace gfins::sim {

/// A fresh replay of `samples` through `pipeline` (NavLoop); returns the report.
template <typename T>
NavReport replay(nav::NavPipeline<T>& pipeline, std::span<const RawSample> samples,
                 typename NavLoop<T>::Sink sink = {}) {
  return run_samples(pipeline, samples, std::move(sink));
}

/// Streams the recording at `path` block by block (memory: one block) through `pipeline`. On a
/// truncated or corrupt file the error names its byte offset; the pipeline has then consumed
/// every sample before the broken block (the checks of a block come before any of its samples
/// is offered).
template <typename T>
HostResult<NavReport> replay_recording(const std::string& path, nav::NavPipeline<T>& pipeline,
                                       typename NavLoop<T>::Sink sink = {});

extern template HostResult<NavReport> replay_recording<float>(const std::string&,
                                                              nav::NavPipeline<float>&,
                                                              NavLoop<float>::Sink);
extern template HostResult<NavReport> replay_recording<double>(const std::string&,
                                                               nav::NavPipeline<double>&,
                                                               NavLoop<double>::Sink);

}  // namespace gfins::sim
