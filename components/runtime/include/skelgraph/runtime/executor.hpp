#pragma once
// One thread per component runs all of its callbacks (data, timers) in order,
// so component code never needs locks of its own. DDS listener threads only
// post work here.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace skelgraph::runtime {

class Executor;

// Cancels its timer when destroyed. Safe to destroy from inside the timer's callback.
class TimerHandle {
 public:
  TimerHandle() = default;
  TimerHandle(TimerHandle&&) noexcept = default;
  TimerHandle& operator=(TimerHandle&& other) noexcept;
  TimerHandle(const TimerHandle&) = delete;
  TimerHandle& operator=(const TimerHandle&) = delete;
  ~TimerHandle() { cancel(); }
  void cancel();
  std::uint64_t overruns() const;  // periods skipped because a callback ran late

  struct State;

 private:
  friend class Executor;
  explicit TimerHandle(std::shared_ptr<State> s) : state_(std::move(s)) {}
  std::shared_ptr<State> state_;
};

class Executor {
 public:
  explicit Executor(std::string name);
  ~Executor();
  Executor(const Executor&) = delete;
  Executor& operator=(const Executor&) = delete;

  void start();
  // Runs `last` (if given) on the executor thread after the queued work, then
  // joins. Work posted afterwards is dropped. Idempotent.
  void stop(std::function<void()> last = {});
  bool running() const;

  void post(std::function<void()> task);
  // Calls `fn` every `period`, first at now + period (or now, if `immediately`).
  // Late calls are not bunched: missed periods are skipped and counted.
  TimerHandle every(std::chrono::nanoseconds period, std::function<void()> fn, bool immediately = false);

  // An exception escaping a task or timer is handed to `handler` (the
  // component's context marks it ERROR) instead of ending the process; the
  // executor goes on with the next task. Set before start().
  void on_error(std::function<void(const std::string& what)> handler) { on_error_ = std::move(handler); }

  // Runs `task` on the executor thread and waits for it (returns false on timeout or if stopped).
  bool run_sync(std::function<void()> task, std::chrono::milliseconds timeout);

 private:
  void loop();
  void run_guarded(const std::function<void()>& fn);

  std::string name_;
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<std::function<void()>> tasks_;
  std::vector<std::shared_ptr<TimerHandle::State>> timers_;
  bool running_ = false;
  bool stopping_ = false;
  std::function<void(const std::string&)> on_error_;
  std::thread thread_;
};

}  // namespace skelgraph::runtime
