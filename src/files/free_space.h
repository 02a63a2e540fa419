#pragma once
// Room on disk before a long bake: the bytes a bake will write, summed by filesystem, against
// what statvfs says an unprivileged writer may still use there, so a bake that cannot fit fails
// in seconds rather than at the frame where the disk fills (docs/outputs.md "Room on disk").
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace treeanim {

// A filesystem as a folder on it sees it.
struct FreeSpace {
  uint64_t device = 0;  // st_dev: folders with the same one share their free space
  double bytes = 0;     // f_bavail * f_frsize: what a writer that is not root may still use
};

// An existing folder => its filesystem and free bytes (stat, statvfs). Throws OutputError naming it.
FreeSpace filesystem_free_space(const std::filesystem::path& folder);

using FreeSpaceProbe = std::function<FreeSpace(const std::filesystem::path& folder)>;

// A file a bake will write (or the first of several in one folder) and the bytes it will take.
struct SpaceNeed {
  std::filesystem::path path;
  double bytes = 0;
};

// Needs => nothing when every filesystem has room for what is written to it; else OutputError
// naming the first path on the first filesystem that lacks room, what it needs and what is free.
// Each need's folder is probed where it exists (a folder still to be made: its nearest ancestor).
void check_free_space(const std::vector<SpaceNeed>& needs, const FreeSpaceProbe& probe = filesystem_free_space);

// Bytes => "104 GB", "4.5 MB": decimal units, 3 significant digits.
std::string bytes_text(double bytes);

}  // namespace treeanim
