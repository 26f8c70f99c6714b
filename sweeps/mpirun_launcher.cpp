#include "sweeps/mpirun_launcher.h"

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <fmt/format.h>
#include <sstream>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

#include "core/input_error.h"
#include "core/interrupt.h"
#include "core/parallel.h"

namespace needle {
namespace fs = std::filesystem;

namespace {

std::string find_on_path(const std::string& program) {
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "");
  for (std::string dir; std::getline(dirs, dir, ':');) {
    if (dir.empty()) continue;
    const fs::path candidate = fs::path(dir) / program;
    if (access(candidate.c_str(), X_OK) == 0) return candidate.string();
  }
  return "";
}

}  // namespace

int run_sweep_under_mpirun(const std::vector<std::string>& sweep_args, int ranks, const fs::path& out_dir) {
  NEEDLE_REQUIRE(ranks >= 1 && ranks <= 1024, fmt::format("--mpi must be from 1 to 1024 ranks (got {})", ranks));
  const std::string mpirun = find_on_path("mpirun");
  NEEDLE_REQUIRE(!mpirun.empty(), "--mpi: no mpirun on the PATH (Debian: openmpi-bin)");
  std::vector<std::string> args = {mpirun, "-n", std::to_string(ranks), "--bind-to", "none", "--stdin", "none"};
  if (ranks > hardware_threads()) args.emplace_back("--oversubscribe");
  if (geteuid() == 0) args.emplace_back("--allow-run-as-root");
  args.push_back(fs::read_symlink("/proc/self/exe").string());
  args.insert(args.end(), sweep_args.begin(), sweep_args.end());
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);

  InterruptWatch watch;  // before the fork: a signal from now on is seen
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error(fmt::format("cannot start mpirun: {}", std::strerror(errno)));
  if (pid == 0) {
    // The child: a process group of its own (the terminal's Ctrl-C goes to needle's group only), ended with needle.
    setpgid(0, 0);
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != parent) _exit(128 + SIGTERM);
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);
    execv(argv[0], argv.data());
    _exit(127);
  }
  setpgid(pid, pid);  // also here, so that the group exists before a kill below
  int status = 0;
  bool stopping = false;
  for (;;) {
    const pid_t r = waitpid(pid, &status, WNOHANG);
    if (r == pid) break;
    if (r < 0 && errno != EINTR) throw std::runtime_error(fmt::format("waiting for mpirun: {}", std::strerror(errno)));
    if (watch.signal() && !stopping) {
      kill(pid, SIGTERM);  // mpirun aborts its ranks; each rank's run stops between two steps
      stopping = true;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  if (watch.signal())
    throw Interrupted(watch.signal(), fmt::format("the sweep was interrupted ({}): finished cases stay in {}; the same command goes on from there",
                                                  signal_name(watch.signal()), out_dir.string()));
  if (WIFEXITED(status)) {
    NEEDLE_REQUIRE(WEXITSTATUS(status) != 127, fmt::format("--mpi: {} could not be started", mpirun));
    return WEXITSTATUS(status);
  }
  return 128 + WTERMSIG(status);
}

}  // namespace needle
