#include "runs/run_folder.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fmt/format.h>
#include <sys/resource.h>
#include <unistd.h>

#include "core/input_error.h"

namespace needle {
namespace {

double now_s() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

std::string clock_text(double seconds) {
  const long s = static_cast<long>(seconds + 0.5);
  return s >= 3600 ? fmt::format("{}:{:02}:{:02}", s / 3600, s / 60 % 60, s % 60) : fmt::format("{}:{:02}", s / 60, s % 60);
}

constexpr const char* kMarker = ".needle-run";  // in every run folder: the toolkit wrote it, --overwrite may replace it

// Whether folder is a run folder the toolkit wrote: its marker, or (folders from before the marker) its
// summary.json and scene.json.
bool holds_run(const std::filesystem::path& folder) {
  namespace fs = std::filesystem;
  return fs::is_directory(folder) && (fs::exists(folder / kMarker) || (fs::exists(folder / "summary.json") && fs::exists(folder / "scene.json")));
}

// DIR as an absolute path and the folder that will hold it, after the checks of RunFolder::check_target.
struct CheckedTarget {
  std::filesystem::path target, parent;
};

CheckedTarget checked_target(const std::string& dir, bool overwrite) {
  namespace fs = std::filesystem;
  NEEDLE_REQUIRE(!dir.empty(), "--out needs a folder");
  const fs::path folder(dir);
  fs::path target = fs::weakly_canonical(fs::absolute(folder));
  // "runs/SB/" names the folder runs/SB, as a shell's completion writes it.
  while (!target.has_filename() && target.has_parent_path() && target != target.root_path()) target = target.parent_path();
  // "." and ".." name the folder itself: its parent is the one above.
  const fs::path parent = target.has_parent_path() && target != target.root_path() ? target.parent_path() : target;
  NEEDLE_REQUIRE(fs::is_directory(parent), fmt::format("the folder '{}' that should hold '{}' does not exist", parent.string(), dir));
  if (fs::exists(folder)) {
    NEEDLE_REQUIRE(overwrite, fmt::format("'{}' already exists; choose another --out or pass --overwrite", dir));
    // --overwrite replaces a run the toolkit wrote, and nothing else: never the current folder or one above it.
    const fs::path cwd = fs::weakly_canonical(fs::current_path());
    const auto [end, unused] = std::mismatch(target.begin(), target.end(), cwd.begin(), cwd.end());
    NEEDLE_REQUIRE(end != target.end() && target != target.root_path(),
                   fmt::format("--overwrite would replace '{}', which holds the current folder; choose another --out", dir));
    NEEDLE_REQUIRE(holds_run(folder), fmt::format("--overwrite replaces only a run folder this toolkit wrote (with its {} marker, or its "
                                                  "summary.json and scene.json); '{}' is not one, and is left as it is",
                                                  kMarker, dir));
  }
  return {target, parent};
}

}  // namespace

void RunFolder::check_target(const std::string& dir, bool overwrite) { checked_target(dir, overwrite); }

RunFolder::RunFolder(const std::string& dir, bool overwrite) : final_(dir), overwrite_(overwrite) {
  namespace fs = std::filesystem;
  const CheckedTarget checked = checked_target(dir, overwrite);
  final_ = fs::path(dir).has_filename() ? fs::path(dir) : checked.target;  // "runs/SB/": the folder runs/SB
  lock_ = std::make_unique<WriterLock>(checked.target, dir);  // a second writer stops here, before it removes the first's partial
  partial_ = checked.parent / ("." + checked.target.filename().string() + ".partial");
  fs::remove_all(partial_);
  fs::create_directories(partial_);
  std::ofstream(partial_ / kMarker) << "A run folder written by needle (docs/scenes.md); --overwrite may replace it.\n";
}

RunFolder::~RunFolder() {
  if (!committed_) {
    std::error_code ignored;
    std::filesystem::remove_all(partial_, ignored);
  }
}

void RunFolder::commit() {
  if (overwrite_ && std::filesystem::exists(final_)) std::filesystem::remove_all(final_);
  std::filesystem::rename(partial_, final_);
  committed_ = true;
}

RunLog::RunLog(const std::filesystem::path& path) : out_(path), start_s_(now_s()) {
  NEEDLE_REQUIRE(out_.good(), fmt::format("cannot write the log '{}'", path.string()));
}

void RunLog::line(const std::string& text) {
  out_ << fmt::format("[{:9.3f} s] {}\n", now_s() - start_s_, text);
  out_.flush();
}

ProgressBar::ProgressBar(double end_value, bool quiet) : end_(end_value), start_s_(now_s()), quiet_(quiet), tty_(isatty(2)) {}

void ProgressBar::update(double value, long step, const std::string& unit) {
  if (quiet_ || end_ <= 0) return;
  const double fraction = std::clamp(value / end_, 0.0, 1.0), elapsed = now_s() - start_s_;
  const std::string eta = fraction > 1e-6 ? clock_text(elapsed * (1 - fraction) / fraction) : "?";
  if (tty_) {
    if (now_s() - last_draw_s_ < 0.2 && fraction < 1) return;
    last_draw_s_ = now_s();
    const int width = 30, filled = static_cast<int>(fraction * width);
    fmt::print(stderr, "\r{:3.0f}% [{}{}] step {}  t {:.4g}/{:.4g} {}  elapsed {}  ETA {}   ", 100 * fraction,
               std::string(static_cast<size_t>(filled), '#'), std::string(static_cast<size_t>(width - filled), '.'), step, value,
               end_, unit, clock_text(elapsed), eta);
    std::fflush(stderr);
    return;
  }
  const int decile = static_cast<int>(fraction * 10);
  if (decile == last_decile_) return;
  last_decile_ = decile;
  fmt::print(stderr, "{:3.0f}%  step {}  t {:.4g}/{:.4g} {}  elapsed {}  ETA {}\n", 100 * fraction, step, value, end_, unit,
             clock_text(elapsed), eta);
}

void ProgressBar::finish() {
  if (!quiet_ && tty_) fmt::print(stderr, "\n");
}

void write_pvd(const std::filesystem::path& path, const std::vector<std::pair<double, std::string>>& frames) {
  std::ofstream out(path);
  out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n  <Collection>\n";
  for (const auto& [time, file] : frames) out << fmt::format("    <DataSet timestep=\"{:.9g}\" file=\"{}\"/>\n", time, file);
  out << "  </Collection>\n</VTKFile>\n";
}

double peak_memory_MiB() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;
}

}  // namespace needle
