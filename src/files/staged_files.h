#pragma once
// Temporaries beside their targets: every sink writes ".name.tmp-<pid>" next to "name" and
// renames all of its files only when the whole output is complete, so a file with a final
// name is always whole and an aborted bake leaves nothing behind.
#include <filesystem>
#include <string>
#include <vector>

namespace treeanim {

// target => "<dir>/.<name>.tmp-<pid>" (hidden, same folder so rename() is atomic).
std::filesystem::path temporary_path(const std::filesystem::path& target);

// The file that writing a target replaces, and what stands there now.
struct OutputTarget {
  std::filesystem::path file;  // the target, or where its chain of symbolic links ends
  std::string kind;            // as non_regular_kind: "" when absent or a regular file
};

// Follows `target`'s symbolic links as cp and editors do, so the link stays and the file it
// names is replaced (a dangling link: that file is created); one lstat() per link, never an
// open(). Throws InputError on a loop or a chain over 40 links.
OutputTarget resolve_output_target(const std::filesystem::path& target);

// What stands at `path` when it is neither absent nor a regular file: "a directory", "a character
// device", "a block device", "a FIFO", "a socket"; "" otherwise. Looks with lstat(), so it never
// opens the path (opening a FIFO blocks) and never follows a link.
std::string non_regular_kind(const std::filesystem::path& path);

// Folders made for a bake or a submission, removed again (when still empty) if it fails, so
// that a failure leaves what stood before and nothing else.
class MadeFolders {
 public:
  // create_directories(folder), remembering the folders that did not exist.
  void make(const std::filesystem::path& folder, std::error_code& error);
  // Removes the remembered folders that are empty, deepest first. Never throws.
  void undo() noexcept;

 private:
  std::vector<std::filesystem::path> made_;  // deepest first within each make()
};

// Checks, before anything is simulated, that a file can be created in `target`'s folder: the
// folder exists or is created (into `made`), and a probe temporary is created and removed.
// Throws OutputError naming the path.
void check_writable_target(const std::filesystem::path& target, MadeFolders& made);

class StagedFiles {
 public:
  // Registers `target` (resolve_output_target: a link's file is what gets replaced); returns the
  // temporary to write instead, beside that file.
  std::filesystem::path stage(const std::filesystem::path& target);
  // Throws OutputError naming a target that is no longer absent or a regular file (something
  // appeared there during the bake), which the commit would leave as it is.
  void check() const;
  // check(), then renames every temporary to its target, in staging order. Throws OutputError
  // naming the path.
  void commit();
  // Removes every temporary still present. Never throws.
  void discard() noexcept;
  bool empty() const { return targets_.empty(); }

 private:
  std::vector<std::filesystem::path> targets_;      // final names
  std::vector<std::filesystem::path> temporaries_;  // same order as targets_
};

}  // namespace treeanim
