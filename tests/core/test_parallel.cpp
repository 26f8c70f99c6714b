// run_beside: both functions run to their end, the serial one on the calling thread, for any thread count; an
// exception from the serial one reaches the caller only once the other has finished.
#include <catch2/catch.hpp>
#include <chrono>
#include <numeric>
#include <stdexcept>
#include <thread>
#include <vector>

#include "core/parallel.h"

using namespace needle;

namespace {

// beside(): fills each entry with its index squared through parallel_for (chunks anywhere), after a pause.
void filled_beside(std::vector<long>& out) {
  out.assign(100000, -1);
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  parallel_for(static_cast<std::int64_t>(out.size()), [&](std::int64_t begin, std::int64_t end) {
    for (std::int64_t i = begin; i < end; ++i) out[static_cast<size_t>(i)] = static_cast<long>(i) * i;
  });
}

}  // namespace

TEST_CASE("run_beside runs both to their end, the serial one on the caller's thread, for 1 and 2 threads", "[core][parallel]") {
  for (int threads : {1, 2}) {
    const ThreadLimit limit(threads);
    std::vector<long> out;
    std::thread::id serial_thread;
    long serial_sum = 0;
    run_beside(
        [&] {
          serial_thread = std::this_thread::get_id();
          for (long k = 1; k <= 1000; ++k) serial_sum += k;
        },
        [&] { filled_beside(out); });
    INFO(threads << " threads");
    CHECK(serial_thread == std::this_thread::get_id());
    CHECK(serial_sum == 500500);
    REQUIRE(out.size() == 100000);
    long wrong = 0;
    for (size_t i = 0; i < out.size(); ++i) wrong += out[i] != static_cast<long>(i) * static_cast<long>(i);
    CHECK(wrong == 0);
  }
}

TEST_CASE("run_beside passes the serial function's exception on once the other has finished", "[core][parallel]") {
  std::vector<long> out;
  CHECK_THROWS_WITH(run_beside([] { throw std::runtime_error("the needle stopped"); }, [&] { filled_beside(out); }), "the needle stopped");
  REQUIRE(out.size() == 100000);
  CHECK(out.back() == 99999L * 99999L);  // written after the pause: the caller waited for it
}
