#pragma once
// Another program run to its end (a farm engine's client: sbatch, scancel), its output kept.
#include <filesystem>
#include <string>
#include <vector>

namespace treeanim {

// name => the first executable file of that name in a folder of $PATH; empty when none.
std::filesystem::path find_on_path(const std::string& name);

struct ProgramResult {
  int status = 0;   // exit code; 128 + N when killed by signal N; 127 when it could not start
  std::string out;  // its standard output
  std::string err;  // its standard error
};

// Runs `program` with `args` (argv[1..]), waits for it. Throws OutputError when no temporary file
// for its output can be made.
ProgramResult run_program(const std::filesystem::path& program, const std::vector<std::string>& args);

}  // namespace treeanim
