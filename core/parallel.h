#pragma once
// The one place that decides threading: every per-particle kernel runs through parallel_for.
// Kernels are written as gathers (each index writes only its own outputs), so results do not depend
// on the thread count or the schedule.
#include <algorithm>
#include <cstdint>
#include <functional>
#include <mutex>
#include <utility>
#include <vector>

namespace needle {

// Runs body(begin, end) over [0, n) in chunks on the worker threads.
void parallel_for(std::int64_t n, const std::function<void(std::int64_t begin, std::int64_t end)>& body);

// Runs body(begin, end, found) over chunks of [0, n) on the worker threads, each chunk appending what it finds
// to its own list, and returns the lists joined in index order: the same result for any thread count or schedule.
template <class T, class ChunkBody>
std::vector<T> parallel_collect_chunks(std::int64_t n, const ChunkBody& body) {
  std::mutex merge;
  std::vector<std::pair<std::int64_t, std::vector<T>>> chunks;
  parallel_for(n, [&](std::int64_t begin, std::int64_t end) {
    std::vector<T> found;
    body(begin, end, found);
    if (found.empty()) return;
    const std::lock_guard<std::mutex> lock(merge);
    chunks.emplace_back(begin, std::move(found));
  });
  std::sort(chunks.begin(), chunks.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<T> out;
  for (auto& chunk : chunks) out.insert(out.end(), chunk.second.begin(), chunk.second.end());
  return out;
}

// Runs body(k, found) for k in [0, n) on the worker threads, as parallel_collect_chunks: the finds in index order.
template <class T, class Body>
std::vector<T> parallel_collect(std::int64_t n, const Body& body) {
  return parallel_collect_chunks<T>(n, [&](std::int64_t begin, std::int64_t end, std::vector<T>& found) {
    for (std::int64_t k = begin; k < end; ++k) body(k, found);
  });
}

// Runs serial() on the calling thread while beside() runs on the other worker threads (its own parallel_for
// chunks may be helped by the caller once serial() is done), and returns when both are done. serial() keeps
// its thread: it does not pick up beside()'s work midway. Each keeps its own results' independence of the
// schedule, so the pair does too.
void run_beside(const std::function<void()>& serial, const std::function<void()>& beside);

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
// The worker threads parallel_for may use now: hardware_threads(), or fewer under a ThreadLimit.
int allowed_threads();

}  // namespace needle
