#pragma once
// One writer at a time for an output folder: an exclusive flock(2) on a hidden lock file beside it
// ("DIR" -> ".DIR.lock" in DIR's parent), held for the writer's lifetime. A second writer is refused at once
// with one line naming the holder's pid; the kernel drops the lock of a process that dies, however it dies, so a
// lock left by a dead writer is taken over by the next one (its file, holding the dead pid, stays until then). A
// writer that ends removes the file while it still holds it; a writer that locked a file just removed notices
// (the path no longer names it) and tries again, so two writers never hold two files of one name.
#include <filesystem>
#include <memory>
#include <string>

namespace needle {

class WriterLock {
 public:
  // InputError "'<shown>' is being written by another needle (pid N) ..." if another process (or another
  // WriterLock in this one) holds the lock of folder.
  WriterLock(const std::filesystem::path& folder, const std::string& shown);
  ~WriterLock();
  WriterLock(const WriterLock&) = delete;
  WriterLock& operator=(const WriterLock&) = delete;

  // The lock file of folder (in its parent).
  static std::filesystem::path lock_path(const std::filesystem::path& folder);

 private:
  std::filesystem::path path_;
  int fd_ = -1;
};

// The folder a path names: "out/" (a shell's completion) names out.
std::filesystem::path named_folder(const std::filesystem::path& path);

// What a command that writes a folder (a sweep, a search, a report, a calibration, the stress suite) takes before
// anything is written: the folder's lock, so that a second command on the same --out is refused at once with one line
// naming the first's pid. InputError "--out DIR: its parent folder does not exist" first where it does not.
std::unique_ptr<WriterLock> lock_output_folder(const std::filesystem::path& folder);

}  // namespace needle
