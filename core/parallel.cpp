#include "core/parallel.h"

#include <algorithm>
#include <memory>
#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <tbb/task_group.h>

namespace needle {

void parallel_for(std::int64_t n, const std::function<void(std::int64_t, std::int64_t)>& body) {
  if (n <= 0) return;
  constexpr std::int64_t kGrain = 512;
  if (n <= kGrain) {
    body(0, n);
    return;
  }
  tbb::parallel_for(tbb::blocked_range<std::int64_t>(0, n, kGrain),
                    [&](const tbb::blocked_range<std::int64_t>& r) { body(r.begin(), r.end()); });
}

void run_beside(const std::function<void()>& serial, const std::function<void()>& beside) {
  tbb::task_group group;
  group.run([&beside] { beside(); });
  try {
    tbb::this_task_arena::isolate([&serial] { serial(); });
  } catch (...) {
    group.wait();  // beside() works on what the caller owns: it finishes before the caller unwinds
    throw;
  }
  group.wait();
}

struct ThreadLimit::Impl {
  std::unique_ptr<tbb::global_control> control;
};

ThreadLimit::ThreadLimit(int threads) : impl_(new Impl) {
  if (threads > 0)
    impl_->control = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                           static_cast<size_t>(threads));
}

ThreadLimit::~ThreadLimit() { delete impl_; }

int hardware_threads() { return tbb::info::default_concurrency(); }

int allowed_threads() {
  return static_cast<int>(std::min<size_t>(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism),
                                           static_cast<size_t>(hardware_threads())));
}

}  // namespace needle
