#include "files/staged_files.h"

#include <unistd.h>

#include <cstdio>
#include <system_error>

#include "common/errors.h"
#include "files/io_failure.h"

namespace treeanim {

namespace fs = std::filesystem;

fs::path temporary_path(const fs::path& target) {
  // Appended piece by piece: g++ 12 warns (-Wrestrict, a false positive) on "." + string.
  std::string name(1, '.');
  name += target.filename().string();
  name += ".tmp-";
  name += std::to_string(::getpid());
  return target.parent_path() / name;
}

namespace {

// What an lstat() found, as non_regular_kind describes it.
std::string kind_of(const fs::file_status& status) {
  switch (status.type()) {
    case fs::file_type::not_found:
    case fs::file_type::none:  // unreachable: the probe of the folder reports why
    case fs::file_type::regular: return "";
    case fs::file_type::directory: return "a directory";
    case fs::file_type::character: return "a character device";
    case fs::file_type::block: return "a block device";
    case fs::file_type::fifo: return "a FIFO";
    case fs::file_type::socket: return "a socket";
    case fs::file_type::symlink: return "a symbolic link";
    default: return "a file that is not a regular file";
  }
}

}  // namespace

OutputTarget resolve_output_target(const fs::path& target) {
  fs::path path = target;
  for (int links = 0;; ++links) {
    std::error_code error;
    const fs::file_status status = fs::symlink_status(path, error);
    if (!fs::is_symlink(status)) return {path, kind_of(status)};
    if (links == 40)  // Linux's own limit on a chain (ELOOP)
      throw InputError(target.string() + ": a loop of symbolic links, or a chain of more than 40");
    const fs::path next = fs::read_symlink(path, error);
    if (error) throw InputError(target.string() + ": cannot read the symbolic link " + path.string() + ": " + error.message());
    path = (next.is_absolute() ? next : path.parent_path() / next).lexically_normal();
  }
}

std::string non_regular_kind(const fs::path& path) {
  std::error_code error;
  return kind_of(fs::symlink_status(path, error));
}

void MadeFolders::make(const fs::path& folder, std::error_code& error) {
  // Missing: nothing there, not even a link (a dangling link is someone's, never ours to remove).
  std::vector<fs::path> missing;
  for (fs::path p = folder; !p.empty() && !fs::exists(fs::symlink_status(p, error)); p = p.parent_path())
    missing.push_back(p);
  fs::create_directories(folder, error);
  made_.insert(made_.begin(), missing.begin(), missing.end());  // later folders first: deeper or apart
}

void MadeFolders::undo() noexcept {
  // rmdir, not remove: what stands there now may be someone's file or link, not the folder made.
  for (const fs::path& p : made_) ::rmdir(p.c_str());  // fails, harmlessly, on a folder not empty
  made_.clear();
}

void check_writable_target(const fs::path& target, MadeFolders& made) {
  const fs::path folder = target.parent_path().empty() ? fs::path(".") : target.parent_path();
  std::error_code error;
  made.make(folder, error);
  if (error || !fs::is_directory(folder))
    throw OutputError(target.string() + ": cannot create the folder " + folder.string() +
                      (error ? ": " + error.message() : ": a file is in the way"));
  const fs::path probe = temporary_path(target);
  std::FILE* file = std::fopen(probe.c_str(), "wb");
  if (!file) throw OutputError(io_failure(target, "cannot create a file in " + folder.string()));
  std::fclose(file);
  fs::remove(probe, error);
}

fs::path StagedFiles::stage(const fs::path& target) {
  targets_.push_back(resolve_output_target(target).file);
  temporaries_.push_back(temporary_path(target));
  return temporaries_.back();
}

void StagedFiles::check() const {
  for (const fs::path& target : targets_) {
    const std::string kind = non_regular_kind(target);
    if (!kind.empty())
      throw OutputError(target.string() + ": " + kind + " appeared at the output path during the bake; it was " +
                        "left as it is and the finished file is not written");
  }
}

void StagedFiles::commit() {
  check();
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
