#include "files/io_failure.h"

#include <cerrno>
#include <cstring>

namespace treeanim {

std::string io_failure(const std::filesystem::path& path, const std::string& what) {
  return path.string() + ": " + what + ": " + std::strerror(errno);
}

}  // namespace treeanim
