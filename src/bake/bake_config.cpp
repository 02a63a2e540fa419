#include "bake/bake_config.h"

#include <cinttypes>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "bake/scene_hash.h"
#include "treeanim_version.h"

namespace treeanim {

std::string treeanim_generator() { return std::string("treeanim ") + TREEANIM_VERSION; }

namespace {

// What a file past this many bytes is known by instead of its bytes: its size and time (a
// volume of one file for all time may hold gigabytes, read again for each tree of a forest).
constexpr uintmax_t kHashedBytes = uintmax_t(64) << 20;

// A file's size and time, or "absent" where no regular file stands.
std::string file_stamp(const std::filesystem::path& path) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) return "absent";
  const uintmax_t size = std::filesystem::file_size(path, error);
  const auto time = std::filesystem::last_write_time(path, error).time_since_epoch().count();
  return "bytes " + std::to_string(size) + " time " + std::to_string(time);
}

// A file => the FNV-1a of its bytes as 16 hex digits; past kHashedBytes, its file_stamp;
// "absent" where no regular file stands (a volume's frame pattern). Read each time: a forest's
// trees re-read kilobytes, and no cached digest can miss an edit that kept the file's size and time.
std::string file_digest(const std::filesystem::path& path) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) return "absent";
  if (const uintmax_t size = std::filesystem::file_size(path, error); !error && size > kHashedBytes)
    return file_stamp(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) return "unreadable";
  uint64_t hash = kFnv1aStart;
  std::vector<char> chunk(1 << 16);
  while (in.read(chunk.data(), std::streamsize(chunk.size())) || in.gcount() > 0)
    hash = fnv1a64(hash, chunk.data(), size_t(in.gcount()));
  char digest[24];
  std::snprintf(digest, sizeof digest, "%016" PRIx64, hash);
  return digest;
}

}  // namespace

std::string bake_key(const Scene& scene, const std::string& generator) {
  // The resolved scene holds the paths of the files it names, not what they hold: each file's
  // name and the hash of its bytes go after it, so that a grammar or a wind series edited
  // between a kill and --resume is a new bake, not frames of the old one continued.
  std::string text = scene.resolved.dump(2);
  for (const std::filesystem::path& path : scene.input_paths) text += "\n" + path.string() + " " + file_digest(path);
  for (const std::filesystem::path& path : scene.volume_frames) text += "\n" + path.string() + " " + file_stamp(path);
  return scene_hash(text, generator);
}

std::filesystem::path checkpoint_folder(const std::filesystem::path& out_dir, const std::filesystem::path& given) {
  return given.empty() ? out_dir / "checkpoints" : given;
}

BakeConfig tree_bake_config(const BakeConfig& forest, const std::string& id) {
  BakeConfig tree = forest;
  tree.checkpoints.dir = forest.checkpoints.dir / id;
  return tree;
}

}  // namespace treeanim
