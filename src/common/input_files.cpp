#include "common/input_files.h"

#include <sys/stat.h>

#include <cctype>
#include <cstdint>
#include <mutex>
#include <unordered_map>

namespace treeanim {

namespace {

struct InputFiles {
  std::mutex mutex;
  std::unordered_map<uint64_t, std::unordered_map<uint64_t, std::string>> named;  // device => inode => name
};

InputFiles& input_files() {
  static InputFiles files;
  return files;
}

}  // namespace

void note_input_file(const std::filesystem::path& path) {
  struct stat status;
  if (::stat(path.c_str(), &status) != 0 || !S_ISREG(status.st_mode)) return;
  InputFiles& files = input_files();
  const std::lock_guard<std::mutex> lock(files.mutex);
  // The newest name: an inode freed since may be a new file's.
  files.named[status.st_dev].insert_or_assign(status.st_ino, path.string());
}

std::string input_file_at(const std::filesystem::path& path) {
  struct stat status;
  if (::stat(path.c_str(), &status) != 0 || !S_ISREG(status.st_mode)) return "";
  InputFiles& files = input_files();
  const std::lock_guard<std::mutex> lock(files.mutex);
  const auto device = files.named.find(status.st_dev);
  if (device == files.named.end()) return "";
  const auto file = device->second.find(status.st_ino);
  if (file == device->second.end()) return "";
  // Only while its name still leads to it: an input removed since gave its inode to a new file.
  struct stat noted;
  if (::stat(file->second.c_str(), &noted) != 0 || noted.st_dev != status.st_dev || noted.st_ino != status.st_ino)
    return "";
  return file->second;
}

std::string why_no_file(const std::filesystem::file_status& status, const std::error_code& error) {
  if (std::filesystem::status_known(status) || !error) return "no such file";
  std::string why = error.message();
  if (!why.empty()) why[0] = static_cast<char>(std::tolower(static_cast<unsigned char>(why[0])));
  return why;
}

}  // namespace treeanim
