#include "io/staged_files.h"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <system_error>

#include "common/errors.h"

namespace treeanim {

namespace fs = std::filesystem;

std::string io_failure(const fs::path& path, const std::string& what) {
  return path.string() + ": " + what + ": " + std::strerror(errno);
}

fs::path temporary_path(const fs::path& target) {
  // Appended piece by piece: g++ 12 warns (-Wrestrict, a false positive) on "." + string.
  std::string name(1, '.');
  name += target.filename().string();
  name += ".tmp-";
  name += std::to_string(::getpid());
  return target.parent_path() / name;
}

void check_writable_target(const fs::path& target) {
  const fs::path folder = target.parent_path().empty() ? fs::path(".") : target.parent_path();
  std::error_code error;
  fs::create_directories(folder, error);
  if (error || !fs::is_directory(folder))
    throw OutputError(target.string() + ": cannot create the folder " + folder.string() +
                      (error ? ": " + error.message() : ": a file is in the way"));
  if (fs::is_directory(target))
    throw OutputError(target.string() + ": a directory is in the way of the output file");
  const fs::path probe = temporary_path(target);
  std::FILE* file = std::fopen(probe.c_str(), "wb");
  if (!file) throw OutputError(io_failure(target, "cannot create a file in " + folder.string()));
  std::fclose(file);
  fs::remove(probe, error);
}

fs::path StagedFiles::stage(const fs::path& target) {
  targets_.push_back(target);
  temporaries_.push_back(temporary_path(target));
  return temporaries_.back();
}

void StagedFiles::commit() {
  for (size_t i = 0; i < targets_.size(); ++i) {
    std::error_code error;
    fs::rename(temporaries_[i], targets_[i], error);
    if (error)
      throw OutputError(targets_[i].string() + ": cannot rename the finished temporary " +
                        temporaries_[i].string() + " into place: " + error.message());
  }
  targets_.clear();
  temporaries_.clear();
}

void StagedFiles::discard() noexcept {
  for (const fs::path& temporary : temporaries_) {
    std::error_code ignored;
    fs::remove(temporary, ignored);
  }
  targets_.clear();
  temporaries_.clear();
}

}  // namespace treeanim
