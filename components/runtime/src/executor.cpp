#include "skelgraph/runtime/executor.hpp"

#include <cstdio>

#include <future>

namespace skelgraph::runtime {

struct TimerHandle::State {
  std::recursive_mutex mutex;  // held while the callback runs; recursive so it may cancel itself
  bool cancelled = false;
  std::chrono::nanoseconds period{};
  std::chrono::steady_clock::time_point next;
  std::function<void()> fn;
  std::uint64_t overruns = 0;
};

TimerHandle& TimerHandle::operator=(TimerHandle&& other) noexcept {
  if (this != &other) {
    cancel();
    state_ = std::move(other.state_);
  }
  return *this;
}

void TimerHandle::cancel() {
  if (!state_) return;
  std::lock_guard<std::recursive_mutex> lock(state_->mutex);
  state_->cancelled = true;
}

std::uint64_t TimerHandle::overruns() const {
  if (!state_) return 0;
  std::lock_guard<std::recursive_mutex> lock(state_->mutex);
  return state_->overruns;
}

Executor::Executor(std::string name) : name_(std::move(name)) {}

Executor::~Executor() { stop(); }

void Executor::start() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (running_ || stopping_) return;
  running_ = true;
  thread_ = std::thread([this] { loop(); });
}

bool Executor::running() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return running_ && !stopping_;
}

void Executor::stop(std::function<void()> last) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!running_ || stopping_) {
      stopping_ = true;
      tasks_.clear();
      return;
    }
    if (last) tasks_.push_back(std::move(last));
    stopping_ = true;
  }
  cv_.notify_all();
  if (thread_.joinable() && thread_.get_id() != std::this_thread::get_id()) thread_.join();
}

void Executor::post(std::function<void()> task) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (stopping_) return;
    tasks_.push_back(std::move(task));
  }
  cv_.notify_all();
}

TimerHandle Executor::every(std::chrono::nanoseconds period, std::function<void()> fn, bool immediately) {
  auto state = std::make_shared<TimerHandle::State>();
  state->period = period;
  state->fn = std::move(fn);
  state->next = std::chrono::steady_clock::now() + (immediately ? std::chrono::nanoseconds(0) : period);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    timers_.push_back(state);
  }
  cv_.notify_all();
  return TimerHandle(state);
}

bool Executor::run_sync(std::function<void()> task, std::chrono::milliseconds timeout) {
  auto done = std::make_shared<std::promise<void>>();
  auto fut = done->get_future();
  post([task = std::move(task), done] {
    task();
    done->set_value();
  });
  return fut.wait_for(timeout) == std::future_status::ready;
}

void Executor::run_guarded(const std::function<void()>& fn) {
  std::string what;
  try {
    fn();
    return;
  } catch (const std::exception& e) {
    what = e.what();
  } catch (...) {
    what = "unknown exception";
  }
  if (on_error_) on_error_(what);
  else std::fprintf(stderr, "%s: unhandled error in a callback: %s\n", name_.c_str(), what.c_str());
}

void Executor::loop() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    if (!tasks_.empty()) {
      auto task = std::move(tasks_.front());
      tasks_.pop_front();
      lock.unlock();
      run_guarded(task);
      lock.lock();
      continue;
    }
    if (stopping_) break;
    // Due timers, earliest first; cancelled ones are forgotten.
    const auto now = std::chrono::steady_clock::now();
    auto earliest = std::chrono::steady_clock::time_point::max();
    std::shared_ptr<TimerHandle::State> due;
    for (auto it = timers_.begin(); it != timers_.end();) {
      auto& t = *it;
      if (t.use_count() == 1) {  // its handle is gone
        it = timers_.erase(it);
        continue;
      }
      if (t->next <= now && (!due || t->next < due->next)) due = t;
      earliest = std::min(earliest, t->next);
      ++it;
    }
    if (due) {
      lock.unlock();
      {
        std::lock_guard<std::recursive_mutex> tl(due->mutex);
        if (!due->cancelled) {
          run_guarded(due->fn);
          due->next += due->period;
          const auto after = std::chrono::steady_clock::now();
          if (due->next <= after) {
            const auto missed = (after - due->next) / due->period + 1;
            due->overruns += static_cast<std::uint64_t>(missed);
            due->next += missed * due->period;
          }
        } else {
          due->next = std::chrono::steady_clock::time_point::max();
        }
      }
      lock.lock();
      continue;
    }
    if (earliest == std::chrono::steady_clock::time_point::max()) {
      cv_.wait(lock);
    } else {
      cv_.wait_until(lock, earliest);
    }
  }
  running_ = false;
}

}  // namespace skelgraph::runtime
