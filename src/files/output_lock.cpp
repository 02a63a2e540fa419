#include "files/output_lock.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <string>

#include "common/errors.h"
#include "files/io_failure.h"

namespace treeanim {

namespace fs = std::filesystem;

fs::path lock_path(const fs::path& output) {
  std::string name(1, '.');
  name += output.filename().string();
  name += ".lock";
  return output.parent_path() / name;
}

namespace {

// A write lock on the whole file.
struct flock whole_file() {
  struct flock region {};
  region.l_type = F_WRLCK;
  region.l_whence = SEEK_SET;
  return region;
}

// The file at `path` is still the one open as `fd`: a bake that released its lock may have
// removed the file between our open() and our lock, and a lock on a removed file guards nothing.
bool still_linked(int fd, const fs::path& path) {
  struct stat open_file {}, named {};
  return ::fstat(fd, &open_file) == 0 && ::stat(path.c_str(), &named) == 0 && open_file.st_dev == named.st_dev &&
         open_file.st_ino == named.st_ino;
}

}  // namespace

void OutputLocks::lock(const fs::path& output) {
  const fs::path path = lock_path(output);
  for (;;) {
    const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0) throw OutputError(io_failure(path, "cannot create the lock file of " + output.string()));
    struct flock region = whole_file();
    if (::fcntl(fd, F_SETLK, &region) == 0) {
      if (still_linked(fd, path)) {
        held_.push_back({path, fd});
        return;
      }
      ::close(fd);
      continue;
    }
    if (errno != EACCES && errno != EAGAIN) {
      const std::string failure = io_failure(path, "cannot lock");
      ::close(fd);
      throw OutputError(failure);
    }
    struct flock holder = whole_file();
    const int asked = ::fcntl(fd, F_GETLK, &holder);
    ::close(fd);
    if (asked == 0 && holder.l_type == F_UNLCK) continue;  // released in between: try again
    throw OutputError(output.string() + ": another bake is writing this output (process " +
                      std::to_string(asked == 0 ? holder.l_pid : -1) + ", lock " + path.string() +
                      "); nothing was written: wait for it to end, or write elsewhere (-o)");
  }
}

void OutputLocks::release() noexcept {
  // Removed before closed: whoever opens the name afterwards gets a new file and a free lock.
  // Only while the name is still this lock: a file that took its place is another's.
  for (const Held& held : held_) {
    if (still_linked(held.fd, held.path)) ::unlink(held.path.c_str());
    ::close(held.fd);
  }
  held_.clear();
}

}  // namespace treeanim
