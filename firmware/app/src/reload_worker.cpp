#include "gfins/app/reload_worker.hpp"

namespace gfins::app {
namespace {
constexpr int kIdle = 0, kRequested = 1, kRunning = 2, kReady = 3, kFailed = 4;
}

ReloadWorker::ReloadWorker(LoadFn load) : load_(std::move(load)), thread_([this] { run(); }) {}

ReloadWorker::~ReloadWorker() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

bool ReloadWorker::request(const nav::PipelineConfig<float>& current) {
  // try_lock: the worker holds the mutex only while copying, never during the load itself.
  if (state_.load() != kIdle || !mutex_.try_lock()) return false;
  request_config_ = current;
  state_.store(kRequested);
  mutex_.unlock();
  wake_.notify_one();
  return true;
}

ReloadWorker::Poll ReloadWorker::poll(CalibrationSet& out) {
  const int s = state_.load();
  if (s == kFailed) {
    state_.store(kIdle);
    return Poll::kFailed;
  }
  if (s != kReady || !mutex_.try_lock()) return Poll::kNothing;
  out = result_;
  state_.store(kIdle);
  mutex_.unlock();
  return Poll::kReady;
}

void ReloadWorker::run() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    wake_.wait(lock, [this] { return stop_ || state_.load() == kRequested; });
    if (stop_) return;
    state_.store(kRunning);
    const nav::PipelineConfig<float> base = request_config_;
    lock.unlock();
    std::optional<CalibrationSet> loaded = load_(base);
    lock.lock();
    if (loaded) {
      result_ = *loaded;
      state_.store(kReady);
    } else {
      state_.store(kFailed);
    }
  }
}

}  // namespace gfins::app
