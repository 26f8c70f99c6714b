#include "sweeps/sweep_executor.h"

#include <chrono>
#include <cmath>
#include <cstring>
#include <optional>
#include <cstdlib>
#include <fcntl.h>
#include <fmt/format.h>
#include <map>
#include <signal.h>
#include <spawn.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

#include "core/input_error.h"
#include "core/interrupt.h"
#include "runs/json_file.h"

extern char** environ;

namespace needle {
namespace fs = std::filesystem;

namespace {

double now_s() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

std::string duration_words(double s) {
  if (!std::isfinite(s)) return "?";
  if (s < 90) return fmt::format("{:.0f} s", s);
  if (s < 5400) return fmt::format("{:.0f} min", s / 60);
  return fmt::format("{:.1f} h", s / 3600);
}

// The environment variable that tells a worker which sweep process started it.
constexpr const char* kParentVariable = "NEEDLE_SWEEP_PARENT_PID";

// Starts `needle sweep FILE --out DIR --task-index I --threads T --quiet` with its output in the case's worker.log.
pid_t start_worker(const SweepCase& c, const fs::path& dir, const SweepWorkers& w) {
  const fs::path folder = case_folder(dir, c.name);
  fs::create_directories(folder);
  const std::string log = (folder / "worker.log").string();
  std::vector<std::string> args = {"/proc/self/exe", "sweep", w.sweep_file, "--out", dir.string(), "--task-index", std::to_string(c.index),
                                   "--threads", std::to_string(w.threads_per_case), "--quiet"};
  if (w.allow_other_code) args.push_back("--allow-other-code");
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  // The worker's environment: this one's, and this process's pid for die_with_sweep_parent.
  std::vector<std::string> env = {std::string(kParentVariable) + "=" + std::to_string(getpid())};
  for (char** e = environ; *e; ++e)
    if (std::strncmp(*e, kParentVariable, std::strlen(kParentVariable)) != 0 || (*e)[std::strlen(kParentVariable)] != '=') env.emplace_back(*e);
  std::vector<char*> envp;
  for (std::string& e : env) envp.push_back(e.data());
  envp.push_back(nullptr);
  pid_t pid = 0;
  const int error = posix_spawn(&pid, "/proc/self/exe", &actions, nullptr, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&actions);
  if (error != 0) throw std::runtime_error(fmt::format("cannot start a sweep worker: {}", std::strerror(error)));
  return pid;
}

std::string exit_words(int status) {
  if (WIFSIGNALED(status)) return fmt::format("the worker process ended by {}", signal_name(WTERMSIG(status)));
  return fmt::format("the worker process exited with code {} and no case record", WEXITSTATUS(status));
}

}  // namespace

SweepProgress::SweepProgress(int total_cases, int done_before, int workers, bool quiet)
    : total_(total_cases), done_(done_before), workers_(std::max(1, workers)), start_s_(now_s()), quiet_(quiet) {
  if (!quiet_ && done_before > 0) fmt::print(stderr, "sweep: {} of {} cases done before; running the other {}\n", done_before, total_, total_ - done_before);
}

void SweepProgress::case_started(const std::string& name, const std::string& values) {
  ++started_here_;
  if (!quiet_) fmt::print(stderr, "sweep: {} started ({})\n", name, values);
}

void SweepProgress::case_done(const CaseResult& r, double wall_s) {
  ++done_;
  ++done_here_;
  if (!r.done()) ++failed_;
  case_seconds_ += wall_s;
  if (quiet_) return;
  const int left = total_ - done_;
  const double eta_s = left * (case_seconds_ / done_here_) / workers_;
  const std::string outcome = r.status == "finished" ? finished_case_words(r)
                                                     : r.reason;
  fmt::print(stderr, "sweep: {} {} in {:.0f} s ({}): {} | {} of {} done, {} failed, ETA {}\n", r.name, r.status, wall_s, describe_case(r.label, r.values),
             outcome, done_, total_, failed_, left == 0 ? "0 s" : duration_words(eta_s));
}

std::vector<SweepCase> cases_to_run(const SweepPlan& plan, const fs::path& dir) {
  std::vector<SweepCase> todo;
  for (const SweepCase& c : plan.cases)
    if (!read_done_case(dir, c.name, c.values)) todo.push_back(c);
  return todo;
}

void run_sweep_with_workers(const SweepPlan& plan, const fs::path& dir, const SweepWorkers& w) {
  const std::vector<SweepCase> todo = cases_to_run(plan, dir);
  SweepProgress progress(static_cast<int>(plan.cases.size()), static_cast<int>(plan.cases.size() - todo.size()), w.jobs, w.quiet);
  InterruptWatch watch;
  struct Running {
    SweepCase c;
    double start_s;
    bool over_time = false;  // stopped at the time limit
  };
  std::map<pid_t, Running> running;
  size_t next = 0;
  int forwarded = 0;
  while (!running.empty() || (next < todo.size() && !watch.signal())) {
    while (!watch.signal() && running.size() < static_cast<size_t>(w.jobs) && next < todo.size()) {
      const SweepCase& c = todo[next++];
      running[start_worker(c, dir, w)] = {c, now_s()};
      progress.case_started(c.name, describe_case(c.label, c.values));
    }
    if (watch.signal() && forwarded != watch.signal()) {  // a signal to this process alone (kill, a batch system) reaches the workers too
      forwarded = watch.signal();
      for (const auto& [pid, r] : running) kill(pid, forwarded);
    }
    if (w.case_time_limit_s > 0)  // a case that hangs (or crawls) is stopped: asked first, then killed
      for (auto& [pid, r] : running) {
        const double over_s = now_s() - r.start_s - w.case_time_limit_s;
        if (over_s > 0 && !r.over_time) kill(pid, SIGTERM);
        if (over_s > 10) kill(pid, SIGKILL);
        r.over_time = r.over_time || over_s > 0;
      }
    int status = 0;
    const pid_t pid = waitpid(-1, &status, WNOHANG);
    if (pid <= 0) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
      continue;
    }
    const auto it = running.find(pid);
    if (it == running.end()) continue;
    const Running r = it->second;
    running.erase(it);
    std::optional<CaseResult> result = read_done_case(dir, r.c.name, r.c.values);
    if (!result && r.over_time) {
      result = case_record(r.c.index, r.c.name, r.c.label, r.c.values, "timed_out",
                           fmt::format("ran longer than the time limit for a case ({:g} s) and was stopped", w.case_time_limit_s));
      result->runtime_s = now_s() - r.start_s;
      write_case_record(dir, *result);
    }
    if (!result) {
      const fs::path record = case_folder(dir, r.c.name) / "case.json";
      if (fs::exists(record)) result = case_result_from_json(read_json_file(record.string(), "case record"), record.string());
    }
    if (!result && watch.signal()) continue;  // stopped by the interrupt: it runs again next time
    if (!result) {
      result = case_record(r.c.index, r.c.name, r.c.label, r.c.values, "failed",
                           fmt::format("{} (see {})", exit_words(status), (fs::path("cases") / r.c.name / "worker.log").string()));
      write_case_record(dir, *result);
    }
    progress.case_done(*result, now_s() - r.start_s);
  }
  if (watch.signal())
    throw Interrupted(watch.signal(), fmt::format("the sweep was interrupted ({}): finished cases stay in {}; the same command goes on from there",
                                                  signal_name(watch.signal()), dir.string()));
}

void die_with_sweep_parent() {
  const char* parent = std::getenv(kParentVariable);
  if (!parent) return;
  const pid_t expected = static_cast<pid_t>(std::atol(parent));
  prctl(PR_SET_PDEATHSIG, SIGTERM);
  // The parent may have died before the line above: then this process was handed to another and must not run.
  if (getppid() != expected) throw Interrupted(SIGTERM, fmt::format("the sweep that started this worker (pid {}) is gone; the case runs again next time", expected));
}

int batch_array_task_index() {
  const char* id = std::getenv("SLURM_ARRAY_TASK_ID");
  if (id == nullptr || *id == '\0') return -1;
  char* end = nullptr;
  const long index = std::strtol(id, &end, 10);
  NEEDLE_REQUIRE(*end == '\0' && index >= 0, fmt::format("SLURM_ARRAY_TASK_ID '{}' is not a case index", id));
  return static_cast<int>(index);
}

}  // namespace needle
