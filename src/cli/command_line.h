#pragma once
// The treeanim command line: what main() hands over to.

namespace treeanim {

// argv => the subcommand run, its exit code (docs/design.md): 0, 2 bad input or usage, 3 simulation
// failed, 4 output failed, 130/143/129 interrupted.
int run_command_line(int argc, char** argv);

}  // namespace treeanim
