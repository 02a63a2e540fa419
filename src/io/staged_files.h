#pragma once
// Temporaries beside their targets: every sink writes ".name.tmp-<pid>" next to "name" and
// renames all of its files only when the whole output is complete, so a file with a final
// name is always whole and an aborted bake leaves nothing behind.
#include <filesystem>
#include <string>
#include <vector>

namespace treeanim {

// target => "<dir>/.<name>.tmp-<pid>" (hidden, same folder so rename() is atomic).
std::filesystem::path temporary_path(const std::filesystem::path& target);

// Checks, before anything is simulated, that `target` can be written: its folder exists or is
// created, no directory stands at the target, and a file can be created there (a probe
// temporary is created and removed). Throws OutputError naming the path.
void check_writable_target(const std::filesystem::path& target);

class StagedFiles {
 public:
  // Registers `target`; returns the temporary to write instead.
  std::filesystem::path stage(const std::filesystem::path& target);
  // Renames every temporary to its target, in staging order. Throws OutputError naming the path.
  void commit();
  // Removes every temporary still present. Never throws.
  void discard() noexcept;
  bool empty() const { return targets_.empty(); }

 private:
  std::vector<std::filesystem::path> targets_;      // final names
  std::vector<std::filesystem::path> temporaries_;  // same order as targets_
};

// "<path>: <what>: <strerror(errno)>" for OutputError messages.
std::string io_failure(const std::filesystem::path& path, const std::string& what);

}  // namespace treeanim
