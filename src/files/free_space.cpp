#include "files/free_space.h"

#include <sys/stat.h>
#include <sys/statvfs.h>

#include <cstdio>

#include "common/errors.h"
#include "files/io_failure.h"

namespace treeanim {

namespace fs = std::filesystem;

FreeSpace filesystem_free_space(const fs::path& folder) {
  struct stat info {};
  struct statvfs space {};
  if (::stat(folder.c_str(), &info) != 0 || ::statvfs(folder.c_str(), &space) != 0)
    throw OutputError(io_failure(folder, "cannot measure the free space"));
  return {static_cast<uint64_t>(info.st_dev), double(space.f_bavail) * double(space.f_frsize)};
}

namespace {

// The folder a file goes into, or the nearest of its ancestors that exists.
fs::path existing_folder(const fs::path& file) {
  fs::path folder = file.parent_path().empty() ? fs::path(".") : file.parent_path();
  std::error_code error;
  while (!fs::is_directory(folder, error) && folder.has_relative_path()) folder = folder.parent_path();
  return folder.empty() ? fs::path(".") : folder;
}

}  // namespace

void check_free_space(const std::vector<SpaceNeed>& needs, const FreeSpaceProbe& probe) {
  struct Filesystem {
    FreeSpace space;
    fs::path first;  // the first path written there, which the message names
    double needed = 0;
  };
  std::vector<Filesystem> filesystems;  // in the order of the needs: the message is deterministic
  for (const SpaceNeed& need : needs) {
    const FreeSpace space = probe(existing_folder(need.path));
    auto it = filesystems.begin();
    while (it != filesystems.end() && it->space.device != space.device) ++it;
    if (it == filesystems.end()) it = filesystems.insert(it, {space, need.path, 0});
    it->needed += need.bytes;
  }
  for (const Filesystem& filesystem : filesystems)
    if (filesystem.needed > filesystem.space.bytes)
      throw OutputError(filesystem.first.string() + ": not enough free space: the bake needs " +
                        bytes_text(filesystem.needed) + " on its filesystem, " + bytes_text(filesystem.space.bytes) +
                        " free; make room, write elsewhere (-o), or skip this estimate with --no-space-check");
}

std::string bytes_text(double bytes) {
  const char* units[] = {"B", "KB", "MB", "GB", "TB", "PB"};
  int unit = 0;
  while (bytes >= 1000 && unit < 5) bytes /= 1000, ++unit;
  char text[32];
  std::snprintf(text, sizeof text, "%.3g %s", bytes, units[unit]);
  return text;
}

}  // namespace treeanim
