#pragma once
// Error types shared by every stage. The command line (cli/command_line.cpp) maps them to the
// exit codes of docs/design.md: InputError => 2, SimulationError => 3, OutputError => 4.
#include <stdexcept>
#include <string>

namespace treeanim {

// Bad scene, grammar, wind file or option. The message already names the place
// (file:line:column or file: /json/pointer) and what was expected.
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The simulation produced a non-finite value or otherwise could not go on.
struct SimulationError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// An output could not be written (path, permission, space). The message names the path.
struct OutputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Exit codes of the command-line tool.
enum ExitCode : int {
  kExitOk = 0,
  kExitUsage = 2,  // CLI11 usage errors share the bad-input code
  kExitInput = 2,
  kExitSimulation = 3,
  kExitOutput = 4,
  kExitSighup = 129,
  kExitSigint = 130,
  kExitSigterm = 143,
};

}  // namespace treeanim
