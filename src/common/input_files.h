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

}  // namespace treeanim
