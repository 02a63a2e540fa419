#include "files/text_output.h"

#include <sys/stat.h>

#include <system_error>

#include "common/errors.h"
#include "files/io_failure.h"
#include "files/output_file.h"
#include "files/staged_files.h"

namespace treeanim {

namespace fs = std::filesystem;

void write_text_output(const fs::path& path, const std::string& text, bool executable) {
  // A folder or device named as the file is the caller's slip, refused before anything is made.
  if (const OutputTarget target = resolve_output_target(path); !target.kind.empty())
    throw InputError(path.string() + (target.file == path ? " is " : " links to " + target.file.string() + ", ") +
                     target.kind + ", left untouched; expected a regular file or a new one");
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
