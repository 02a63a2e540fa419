// treeanim: the command line (cli/command_line.h) does the work.
#include "cli/command_line.h"

int main(int argc, char** argv) { return treeanim::run_command_line(argc, argv); }
