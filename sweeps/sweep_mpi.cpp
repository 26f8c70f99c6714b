#include "sweeps/sweep_mpi.h"

#include <algorithm>

#include <chrono>
#include <cstdlib>
#include <fmt/format.h>
#include <string>
#include <thread>

#include "core/input_error.h"
#include "core/interrupt.h"

#ifdef NEEDLE_HAVE_MPI
#include <mpi.h>
#endif

namespace needle {
namespace fs = std::filesystem;
using json = nlohmann::json;

bool launched_by_mpi() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE"})
    if (std::getenv(name) != nullptr) return true;
  return false;
}

#ifndef NEEDLE_HAVE_MPI

bool mpi_available() { return false; }
MpiSession::MpiSession() { throw InputError("this needle was built without MPI (install libopenmpi-dev and build again)"); }
MpiSession::~MpiSession() = default;
void run_sweep_on_mpi(const MpiSession&, const SweepPlan&, const fs::path&, int, bool) {}

#else

namespace {
constexpr int kTagResult = 1;  // worker -> rank 0: a case's record as JSON text, or an empty message (ready)
constexpr int kTagWork = 2;    // rank 0 -> worker: the case index, or -1 (no more work)

double now_s() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

CaseResult run_case_here(const SweepPlan& plan, const SweepCase& c, const fs::path& dir, int threads) {
  try {
    return run_design_case(plan.base, c.index, c.name, c.values, dir, threads, true, c.label);
  } catch (const Interrupted&) {
    throw;
  } catch (const std::exception& e) {  // the environment (a full disk, memory): recorded, the sweep goes on
    const CaseResult failed = case_record(c.index, c.name, c.label, c.values, "failed", e.what());
    write_case_record(dir, failed);
    return failed;
  }
}

void dispatch(const MpiSession& mpi, const SweepPlan& plan, const fs::path& dir, int threads, bool quiet) {
  const std::vector<SweepCase> todo = cases_to_run(plan, dir);
  SweepProgress progress(static_cast<int>(plan.cases.size()), static_cast<int>(plan.cases.size() - todo.size()), std::max(1, mpi.size() - 1),
                         quiet);  // one rank alone runs the cases itself
  InterruptWatch watch;
  if (mpi.size() == 1) {  // no worker rank: run them here
    for (const SweepCase& c : todo) {
      progress.case_started(c.name, describe_case(c.label, c.values));
      const double start = now_s();
      const CaseResult result = run_case_here(plan, c, dir, threads);  // before the clock is read again
      progress.case_done(result, now_s() - start);
    }
    return;
  }
  std::vector<int> running(mpi.size(), -1);
  std::vector<double> started(mpi.size(), 0);
  size_t next = 0;
  int active = mpi.size() - 1;
  while (active > 0) {
    if (watch.signal()) {
      fmt::print(stderr, "needle: the sweep was interrupted ({}): finished cases stay in {}; the same command goes on from there\n",
                 signal_name(watch.signal()), dir.string());
      MPI_Abort(MPI_COMM_WORLD, 128 + watch.signal());
    }
    int ready = 0;
    MPI_Status status;
    MPI_Iprobe(MPI_ANY_SOURCE, kTagResult, MPI_COMM_WORLD, &ready, &status);
    if (!ready) {  // sleep rather than spin: rank 0 should not take a core from the workers
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      continue;
    }
    int length = 0;
    MPI_Get_count(&status, MPI_CHAR, &length);
    std::string text(static_cast<size_t>(length), '\0');
    MPI_Recv(text.data(), length, MPI_CHAR, status.MPI_SOURCE, kTagResult, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    const int worker = status.MPI_SOURCE;
    if (!text.empty()) {
      const CaseResult r = case_result_from_json(json::parse(text), fmt::format("rank {}", worker));
      write_case_record(dir, r);  // where the table is built (the same file where the ranks share DIR)
      progress.case_done(r, now_s() - started[worker]);
    }
    int index = -1;
    if (next < todo.size()) {
      index = todo[next].index;
      running[worker] = index;
      started[worker] = now_s();
      progress.case_started(fmt::format("{} on rank {}", todo[next].name, worker), describe_case(todo[next].label, todo[next].values));
      ++next;
    } else {
      --active;
    }
    MPI_Send(&index, 1, MPI_INT, worker, kTagWork, MPI_COMM_WORLD);
  }
}

void work(const SweepPlan& plan, const fs::path& dir, int threads) {
  std::string message;  // empty: ready for the first case
  for (;;) {
    MPI_Send(message.data(), static_cast<int>(message.size()), MPI_CHAR, 0, kTagResult, MPI_COMM_WORLD);
    int index = -1;
    MPI_Recv(&index, 1, MPI_INT, 0, kTagWork, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    if (index < 0) return;
    message = case_result_to_json(run_case_here(plan, plan.cases.at(static_cast<size_t>(index)), dir, threads)).dump();
  }
}

}  // namespace

bool mpi_available() { return true; }

MpiSession::MpiSession() {
  MPI_Init(nullptr, nullptr);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
}

MpiSession::~MpiSession() { MPI_Finalize(); }

void run_sweep_on_mpi(const MpiSession& mpi, const SweepPlan& plan, const fs::path& dir, int threads, bool quiet) {
  if (mpi.rank() == 0)
    dispatch(mpi, plan, dir, threads, quiet);
  else
    work(plan, dir, threads);
}

#endif

}  // namespace needle
