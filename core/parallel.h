#pragma once
// The one place that decides threading: every per-particle kernel runs through parallel_for.
// Kernels are written as gathers (each index writes only its own outputs), so results do not depend
// on the thread count or the schedule.
#include <cstdint>
#include <functional>

namespace needle {

// Runs body(begin, end) over [0, n) in chunks on the worker threads.
void parallel_for(std::int64_t n, const std::function<void(std::int64_t begin, std::int64_t end)>& body);

// Limits the worker threads for the lifetime of the object (0 = all cores).
class ThreadLimit {
 public:
  explicit ThreadLimit(int threads);
  ~ThreadLimit();
  ThreadLimit(const ThreadLimit&) = delete;
  ThreadLimit& operator=(const ThreadLimit&) = delete;

 private:
  struct Impl;
  Impl* impl_;
};

int hardware_threads();

}  // namespace needle
