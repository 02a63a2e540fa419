#pragma once
// Did-you-mean suggestions for unknown names (scene keys, choices, grammar symbols).
#include <cstddef>
#include <string>
#include <vector>

namespace treeanim {

// Edit distance: insertions, deletions, substitutions and swaps of neighbouring letters.
size_t edit_distance(const std::string& a, const std::string& b);
// The closest candidate to `word` (ignoring case first), else the one candidate that `word` (3
// letters or more) abbreviates ("dir": "direction"), or "" when none is close enough to suggest.
std::string closest_match(const std::string& word, const std::vector<std::string>& candidates);

}  // namespace treeanim
