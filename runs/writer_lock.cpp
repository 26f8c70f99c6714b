#include "runs/writer_lock.h"

#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <fmt/format.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/input_error.h"

namespace needle {

std::filesystem::path WriterLock::lock_path(const std::filesystem::path& folder) {
  const std::filesystem::path absolute = std::filesystem::weakly_canonical(std::filesystem::absolute(folder));
  return absolute.parent_path() / ("." + absolute.filename().string() + ".lock");
}

WriterLock::WriterLock(const std::filesystem::path& folder, const std::string& shown) : path_(lock_path(folder)) {
  // The holder removes the file when it lets go; a writer that locked a file already removed (it opened it just
  // before) would hold a lock nobody else sees, so it checks that the path still names its file, and tries again.
  for (int attempt = 0; attempt < 100; ++attempt) {
    fd_ = ::open(path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    NEEDLE_REQUIRE(fd_ >= 0, fmt::format("cannot open the lock file '{}' for '{}': {}", path_.string(), shown, std::strerror(errno)));
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      char holder[32] = {0};
      const ssize_t n = ::pread(fd_, holder, sizeof holder - 1, 0);
      ::close(fd_);
      fd_ = -1;
      std::string pid = n > 0 ? std::string(holder, static_cast<size_t>(n)) : std::string();
      pid = pid.substr(0, pid.find_first_of("\n "));
      throw InputError(fmt::format("'{}' is being written by another needle (pid {}); wait for it to end, or choose another --out", shown,
                                   pid.empty() ? "unknown" : pid));
    }
    struct stat held {}, named {};
    if (::fstat(fd_, &held) == 0 && ::stat(path_.c_str(), &named) == 0 && held.st_ino == named.st_ino && held.st_dev == named.st_dev) {
      const std::string me = std::to_string(::getpid()) + "\n";
      if (::ftruncate(fd_, 0) == 0) (void)!::pwrite(fd_, me.data(), me.size(), 0);
      return;
    }
    ::close(fd_);
    fd_ = -1;
  }
  throw InputError(fmt::format("cannot lock '{}' for '{}': its lock file keeps changing", path_.string(), shown));
}

std::filesystem::path named_folder(const std::filesystem::path& path) { return path.has_filename() ? path : path.parent_path(); }

std::unique_ptr<WriterLock> lock_output_folder(const std::filesystem::path& folder) {
  const std::filesystem::path named = named_folder(folder);
  NEEDLE_REQUIRE(!named.empty(), "--out: give a folder");
  const std::filesystem::path parent = std::filesystem::absolute(named).parent_path();
  NEEDLE_REQUIRE(std::filesystem::is_directory(parent), fmt::format("--out {}: its parent folder does not exist", folder.string()));
  return std::make_unique<WriterLock>(named, named.string());
}

WriterLock::~WriterLock() {
  if (fd_ < 0) return;
  ::unlink(path_.c_str());  // still holding it: the next writer creates a fresh file
  ::close(fd_);             // closing drops the flock
}

}  // namespace needle
