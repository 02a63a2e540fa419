#pragma once
// Command lines that a farm's job scripts and messages show for the user's shell to run.

#include <string>
#include <vector>

namespace treeanim {

// text => one POSIX shell word with the same bytes ('...', a ' as '\'').
std::string shell_word(const std::string& text);

// --set assignments => " --set 'A=B'" for each, in order ("" for none): what a task, the gather
// and a rerun pass on so that they see the scene that was submitted.
std::string set_arguments(const std::vector<std::string>& overrides);

}  // namespace treeanim
