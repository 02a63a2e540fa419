#pragma once
// A small text file (a manifest, a job script) written whole or not at all: to a temporary
// beside it, renamed into place when complete (docs/outputs.md "Never half-written").
#include <filesystem>
#include <string>

namespace treeanim {

// Writes `text` to `path` (its folder created when missing), replacing the file there.
// `executable`: mode 0755 instead of 0644. Throws OutputError naming the path, also when the path
// is (or links to) a folder, another file that is not a regular one or an input, which stays untouched.
void write_text_output(const std::filesystem::path& path, const std::string& text, bool executable = false);
// A path a command was given to write => InputError when it is (or links to) a folder or another
// file that is not a regular one, or one of the inputs noted so far (common/input_files.h):
// checked before any work, as bad input.
void check_text_output_target(const std::filesystem::path& path);

}  // namespace treeanim
