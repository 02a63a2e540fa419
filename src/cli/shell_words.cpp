#include "cli/shell_words.h"

namespace treeanim {

std::string shell_word(const std::string& text) {
  std::string word = "'";
  for (char c : text) word += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return word + "'";
}

std::string set_arguments(const std::vector<std::string>& overrides) {
  std::string arguments;
  for (const std::string& assignment : overrides) arguments += " --set " + shell_word(assignment);
  return arguments;
}

}  // namespace treeanim
