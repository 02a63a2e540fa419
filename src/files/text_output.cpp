#include "files/text_output.h"

#include <sys/stat.h>

#include <system_error>

#include "common/errors.h"
#include "common/input_files.h"
#include "files/io_failure.h"
#include "files/output_file.h"
#include "files/staged_files.h"

namespace treeanim {

namespace fs = std::filesystem;

namespace {

// path => "" when a file can be written there, else what stands in the way: something other
// than a regular file, or a file this process reads its inputs from.
std::string text_target_problem(const fs::path& path) {
  const OutputTarget target = resolve_output_target(path);
  if (!target.kind.empty())
    return path.string() + (target.file == path ? " is " : " links to " + target.file.string() + ", ") + target.kind +
           ", left untouched; expected a regular file or a new one";
  if (const std::string input = input_file_at(target.file); !input.empty())
    return path.string() + " is " + (input == path.string() ? "" : input + ", ") +
           "an input of this command, left untouched; expected a file it does not read";
  return "";
}

}  // namespace

void check_text_output_target(const fs::path& path) {
  if (const std::string problem = text_target_problem(path); !problem.empty()) throw InputError(problem);
}

void write_text_output(const fs::path& path, const std::string& text, bool executable) {
  if (const std::string problem = text_target_problem(path); !problem.empty()) throw OutputError(problem);
  std::error_code error;
  if (!path.parent_path().empty()) fs::create_directories(path.parent_path(), error);
  if (error) throw OutputError(path.parent_path().string() + ": cannot create the folder: " + error.message());
  StagedFiles staged;
  const fs::path temporary = staged.stage(path);
  try {
    OutputFile file(temporary, path);
    file.write(text);
    file.close();
    if (executable && ::chmod(temporary.c_str(), 0755) != 0) throw OutputError(io_failure(path, "chmod"));
    staged.commit();
  } catch (...) {
    staged.discard();
    throw;
  }
}

}  // namespace treeanim
