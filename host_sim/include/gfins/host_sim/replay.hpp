// Replay of recorded (or any) streams of RawSample values through the one navigation loop
// (nav_loop.hpp): the same report, hash and sink as every other host run.
#pragma once

#include <csignal>
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
/// is offered). `stop` (may be null) is polled before each sample: once non-zero (a SIGINT/SIGTERM
/// handler sets it) the replay ends there, between two samples, and returns the report so far
/// (the caller reads *stop to tell).
template <typename T>
HostResult<NavReport> replay_recording(const std::string& path, nav::NavPipeline<T>& pipeline,
                                       typename NavLoop<T>::Sink sink = {},
                                       const volatile std::sig_atomic_t* stop = nullptr);

extern template HostResult<NavReport> replay_recording<float>(const std::string&,
                                                              nav::NavPipeline<float>&,
                                                              NavLoop<float>::Sink,
                                                              const volatile std::sig_atomic_t*);
extern template HostResult<NavReport> replay_recording<double>(const std::string&,
                                                               nav::NavPipeline<double>&,
                                                               NavLoop<double>::Sink,
                                                               const volatile std::sig_atomic_t*);

}  // namespace gfins::sim
