#include "gfins/app/reload_worker.hpp"

namespace gfins::app {
namespace {
constexpr int kIdle = 0, kRequested = 1, kRunning = 2, kReady = 3, kFailed = 4, kOtherDevice = 5;
}

ReloadWorker::ReloadWorker(LoadFn load) : load_(std::move(load)), thread_([this] { run(); }) {}

// The condition variables are notified with the mutex held: the state change and the wake-up
// are then one step for every observer (valgrind's helgrind flags a notify without the mutex,
// and a waiter cannot miss it either way since the state changes under the mutex).
ReloadWorker::~ReloadWorker() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
    wake_.notify_all();
  }
  thread_.join();
}

bool ReloadWorker::request(const ReloadRequest& r) {
  // try_lock: the worker holds the mutex only while copying, never during the load itself.
  if (state_.load() != kIdle || !mutex_.try_lock()) return false;
  request_ = r;
  state_.store(kRequested);
  wake_.notify_one();
  mutex_.unlock();
  return true;
}

ReloadWorker::Poll ReloadWorker::poll(CalibrationSet& out) {
  // The state is the hand-over: the worker writes result_ before it stores kReady (release,
  // seq_cst here) and writes it again only after a new request, which only this side makes
  // after it has stored kIdle. So reading result_ after loading kReady needs no lock.
  const int s = state_.load();
  if (s == kFailed || s == kOtherDevice) {
    state_.store(kIdle);
    return s == kFailed ? Poll::kFailed : Poll::kOtherDevice;
  }
  if (s != kReady) return Poll::kNothing;
  out = result_;
  state_.store(kIdle);
  return Poll::kReady;
}

void ReloadWorker::wait_settled() {
  std::unique_lock<std::mutex> lock(mutex_);
  settled_.wait(lock, [this] {
    const int s = state_.load();
    return s != kRequested && s != kRunning;
  });
}

void ReloadWorker::run() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    wake_.wait(lock, [this] { return stop_ || state_.load() == kRequested; });
    if (stop_) return;
    state_.store(kRunning);
    const ReloadRequest request = request_;
    lock.unlock();
    const ReloadOutcome loaded = load_(request);
    lock.lock();
    if (loaded.set) {
      result_ = *loaded.set;
      state_.store(kReady);
    } else {
      state_.store(loaded.other_device ? kOtherDevice : kFailed);
    }
    settled_.notify_all();
  }
}

}  // namespace gfins::app
