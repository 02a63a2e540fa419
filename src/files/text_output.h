#pragma once
// A small text file (a manifest, a job script) written whole or not at all: to a temporary
// beside it, renamed into place when complete (docs/outputs.md "Never half-written").
#include <filesystem>
#include <string>

namespace treeanim {

// Writes `text` to `path` (its folder created when missing), replacing the file there.
// `executable`: mode 0755 instead of 0644. Throws InputError when `path` is (or links to) a
// folder or another file that is not a regular one, else OutputError naming the path.
void write_text_output(const std::filesystem::path& path, const std::string& text, bool executable = false);

}  // namespace treeanim
