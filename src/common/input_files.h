#pragma once
// The files this process reads its inputs from (scene, grammar and its includes, view, surfaces,
// wind series and volumes, leaf meshes), known by identity, device and inode: an output that
// names one of them, by any spelling or link, is refused before it could replace it
// (formats/outputs.h, OutputTargets).
#include <filesystem>
#include <string>

namespace treeanim {

// `path`, read or to be read => remembered when it is a regular file (a pipe or device cannot
// be replaced by an output). Thread-safe.
void note_input_file(const std::filesystem::path& path);

// A path => the input file it names (through links), as it was named when noted; "" when it
// names none (or nothing), or the input's name no longer leads to that file. Thread-safe.
std::string input_file_at(const std::filesystem::path& path);

// A status() that found no file, and its error => why, as a message says it: "no such file", or
// the system's reason where the path could not be looked up at all ("too many levels of
// symbolic links", "file name too long"), which "no such file" would hide.
std::string why_no_file(const std::filesystem::file_status& status, const std::error_code& error);

}  // namespace treeanim
