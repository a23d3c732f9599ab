#pragma once
// Helpers for DDS tests: a DdsConfig for the test's own domain, and a
// thread-safe collector that tests wait on (with a timeout, never a bare sleep).

#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <functional>
#include <mutex>
#include <vector>

#include "skelgraph/runtime/dds_config.hpp"

namespace skelgraph::test {

// Loopback profile, domain from SKELGRAPH_DOMAIN (ctest gives each test its own).
inline runtime::DdsConfig test_config() {
  auto c = runtime::DdsConfig::from_env();
  c.profile = "loopback";
  return c;
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
