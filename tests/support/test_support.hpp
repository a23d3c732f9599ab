#pragma once
// Helpers for DDS tests: a DdsConfig for the test's own domain, and a
// thread-safe collector that tests wait on (with a timeout, never a bare sleep).

#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <functional>
#include <mutex>
#include <vector>

#include <string>
#include <thread>

#include "skelgraph/runtime/context.hpp"
#include "skelgraph/runtime/dds_config.hpp"

namespace skelgraph::test {

// Loopback profile, domain from SKELGRAPH_DOMAIN (ctest gives each test its own).
inline runtime::DdsConfig test_config() {
  auto c = runtime::DdsConfig::from_env();
  c.profile = "loopback";
  return c;
}

// Waits until the component of `ctx` has taken (an input) or written (an
// output) `n` samples of `topic`, by its endpoint counter: a test paces a
// stream by what the component has read, so a component slower than the test
// on a busy machine loses nothing to its reader's keep-last history.
enum class Endpoint { Input, Output };
inline bool wait_endpoint_count(const runtime::Context& ctx, Endpoint which, const std::string& topic, std::uint64_t n,
                                std::chrono::milliseconds timeout = std::chrono::seconds(10)) {
  std::shared_ptr<runtime::EndpointCounter> counter;
  for (const auto& c : ctx.counters()) {
    if (c->is_output == (which == Endpoint::Output) && c->topic == topic) counter = c;
  }
  if (!counter) return false;
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (counter->count.load() < n) {
    if (std::chrono::steady_clock::now() > until) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));  // polling the condition
  }
  return true;
}
// Until the component's reader of `topic` has matched n writers on its own
// side. A writer that sees the reader (wait_for_matched) may still be unknown
// to it, and a best-effort sample from an unknown writer is dropped for good.
inline bool wait_input_matched(const runtime::Context& ctx, const std::string& topic, std::size_t n = 1,
                               std::chrono::milliseconds timeout = std::chrono::seconds(10)) {
  for (const auto& c : ctx.counters()) {
    if (!c->is_output && c->topic == topic) return c->wait_matched(n, timeout);
  }
  return false;
}
inline bool wait_input_count(const runtime::Context& ctx, const std::string& topic, std::uint64_t n,
                             std::chrono::milliseconds timeout = std::chrono::seconds(10)) {
  return wait_endpoint_count(ctx, Endpoint::Input, topic, n, timeout);
}

template <class T>
class Collector {
 public:
  void add(const T& v) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      items_.push_back(v);
    }
    cv_.notify_all();
  }
  std::function<void(const T&)> sink() {
    return [this](const T& v) { add(v); };
  }
  // Waits until `pred(items)` holds.
  bool wait(const std::function<bool(const std::vector<T>&)>& pred,
            std::chrono::milliseconds timeout = std::chrono::seconds(10)) {
    std::unique_lock<std::mutex> lock(mutex_);
    return cv_.wait_for(lock, timeout, [&] { return pred(items_); });
  }
  bool wait_count(std::size_t n, std::chrono::milliseconds timeout = std::chrono::seconds(10)) {
    return wait([n](const std::vector<T>& v) { return v.size() >= n; }, timeout);
  }
  std::vector<T> items() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return items_;
  }

 private:
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  std::vector<T> items_;
};

}  // namespace skelgraph::test
