#pragma once
// A simulation's output folder. Everything is written into a hidden sibling "DIR.partial" first; the
// folder appears under its own name when the run ends (finished, or stopped by the solver with what
// it wrote so far), and is removed if the run fails on bad input. An existing DIR is refused unless
// overwriting is asked for, and then replaced only when the new run has ended. One writer at a time: a second
// run on the same DIR while the first writes is refused with the first's pid (writer_lock.h), and touches nothing.
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "runs/writer_lock.h"

namespace needle {

class RunFolder {
 public:
  // InputError if DIR exists (and !overwrite) or its parent folder does not.
  RunFolder(const std::string& dir, bool overwrite);
  // The same checks, writing nothing: a run calls it before it builds its model, so that a bad --out is
  // refused at once, not after the setup.
  static void check_target(const std::string& dir, bool overwrite);
  ~RunFolder();  // removes the partial folder unless commit() ran
  RunFolder(const RunFolder&) = delete;
  RunFolder& operator=(const RunFolder&) = delete;

  std::filesystem::path path(const std::string& name) const { return partial_ / name; }
  // Moves the partial folder to DIR.
  void commit();
  const std::filesystem::path& final_path() const { return final_; }

 private:
  std::unique_ptr<WriterLock> lock_;  // taken before the partial folder is touched, held until this is destroyed
  std::filesystem::path final_, partial_;
  bool overwrite_ = false, committed_ = false;
};

// A line-by-line log file, each line stamped with the seconds since the run began.
class RunLog {
 public:
  explicit RunLog(const std::filesystem::path& path);
  void line(const std::string& text);

 private:
  std::ofstream out_;
  double start_s_;
};

// A progress bar on stderr: redrawn in place on a terminal (at most 5 times a second), one line per
// 10 % otherwise; silent when quiet.
class ProgressBar {
 public:
  ProgressBar(double end_value, bool quiet);
  void update(double value, long step, const std::string& unit);
  void finish();

 private:
  double end_, start_s_, last_draw_s_ = -1;
  int last_decile_ = -1;
  bool quiet_, tty_;
};

// A ParaView collection (.pvd) of (time, file) frames.
void write_pvd(const std::filesystem::path& path, const std::vector<std::pair<double, std::string>>& frames);

// The process's peak resident memory (MiB).
double peak_memory_MiB();

}  // namespace needle
