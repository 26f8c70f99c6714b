// One writer at a time for a run folder (runs/writer_lock.h, RunFolder): a second writer is refused with the holder's
// pid and touches nothing; a writer that dies, however it dies, leaves a lock the next one takes over.
#include <catch2/catch.hpp>
#include <csignal>
#include <fcntl.h>
#include <fstream>
#include <sys/file.h>
#include <filesystem>
#include <sys/wait.h>
#include <unistd.h>

#include "core/input_error.h"
#include "runs/run_folder.h"
#include "runs/writer_lock.h"

namespace fs = std::filesystem;
using namespace needle;

namespace {
fs::path fresh(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("needle_lock_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}
}  // namespace

TEST_CASE("A second writer of a run folder is refused with the holder's pid and leaves the first's partial folder alone", "[runs][lock]") {
  const fs::path dir = fresh("second");
  const std::string out = (dir / "R").string();
  {
    RunFolder first(out, false);
    std::ofstream(first.path("history.csv")) << "t\n0\n";
    CHECK_THROWS_WITH(RunFolder(out, false), Catch::Contains("'" + out + "' is being written by another needle (pid " + std::to_string(::getpid()) + ")"));
    CHECK(fs::exists(first.path("history.csv")));  // the refused writer removed nothing
    first.commit();
  }
  CHECK(fs::exists(dir / "R" / "history.csv"));
  CHECK_FALSE(fs::exists(WriterLock::lock_path(dir / "R")));  // the writer that ended removed its lock file
  // The next writer (with --overwrite) takes the folder over.
  RunFolder next(out, true);
  next.commit();
}

TEST_CASE("A writer killed while it holds the lock leaves it to the next one", "[runs][lock]") {
  // The child holds the lock as a writer does (an exclusive flock on the lock file) with async-signal-safe calls only
  // (it is forked from a threaded process), and is killed with SIGKILL: no destructor runs.
  const fs::path dir = fresh("killed");
  const std::string lock = WriterLock::lock_path(dir / "R").string();
  int ready[2];
  REQUIRE(::pipe(ready) == 0);
  const pid_t child = ::fork();
  REQUIRE(child >= 0);
  if (child == 0) {
    ::close(ready[0]);
    const int fd = ::open(lock.c_str(), O_RDWR | O_CREAT, 0644);
    if (fd >= 0 && ::flock(fd, LOCK_EX) == 0) (void)!::write(ready[1], "x", 1);
    ::pause();  // until killed
    ::_exit(1);
  }
  ::close(ready[1]);
  char c = 0;
  REQUIRE(::read(ready[0], &c, 1) == 1);
  ::close(ready[0]);
  CHECK_THROWS_WITH(WriterLock(dir / "R", "R"), Catch::Contains("'R' is being written by another needle"));
  ::kill(child, SIGKILL);
  int status = 0;
  ::waitpid(child, &status, 0);
  CHECK(fs::exists(lock));  // the dead writer's file stays, unlocked
  CHECK_NOTHROW(WriterLock(dir / "R", "R"));
  CHECK_FALSE(fs::exists(lock));
}
