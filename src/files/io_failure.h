#pragma once
// The message of a failed system call on a file, for OutputError.
#include <filesystem>
#include <string>

namespace treeanim {

// "<path>: <what>: <strerror(errno)>".
std::string io_failure(const std::filesystem::path& path, const std::string& what);

}  // namespace treeanim
