#pragma once
// One writer per output: a bake holds a lock file beside each output's first file, reached
// through any links (a sequence: its first file, whatever spelling of the pattern named it),
// from before the simulation to its end, so a second bake of the same output is refused at
// once rather than both renaming over each other. The lock is a POSIX
// record lock (fcntl F_SETLK), which the kernel drops when the process dies, SIGKILL included:
// a resumed bake is never blocked by its own dead run, and a lock file left by one is reused.
#include <filesystem>
#include <vector>

namespace treeanim {

// output => "<folder>/.<name>.lock", hidden beside it like the temporaries.
std::filesystem::path lock_path(const std::filesystem::path& output);

class OutputLocks {
 public:
  OutputLocks() = default;
  OutputLocks(const OutputLocks&) = delete;
  OutputLocks& operator=(const OutputLocks&) = delete;
  ~OutputLocks() { release(); }

  // Locks `output` (its folder exists). Throws OutputError naming the output and the pid of the
  // process that holds it.
  void lock(const std::filesystem::path& output);
  // Removes every lock file and drops its lock. Never throws.
  void release() noexcept;

 private:
  struct Held {
    std::filesystem::path path;
    int fd = -1;
  };
  std::vector<Held> held_;
};

}  // namespace treeanim
