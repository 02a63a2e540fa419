#include "common/did_you_mean.h"

#include <algorithm>
#include <cctype>
#include <limits>
#include <utility>

namespace treeanim {

size_t edit_distance(const std::string& a, const std::string& b) {
  // Optimal string alignment: insertions, deletions, substitutions and swaps of neighbours
  // ("fromat", "axoim") each one edit. Rows i - 2, i - 1 and i.
  std::vector<size_t> before(b.size() + 1), last(b.size() + 1), row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) last[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      row[j] = std::min({last[j] + 1, row[j - 1] + 1, last[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) row[j] = std::min(row[j], before[j - 2] + 1);
    }
    std::swap(before, last);
    std::swap(last, row);
  }
  return last[b.size()];
}

std::string closest_match(const std::string& word, const std::vector<std::string>& candidates) {
  auto lower = [](std::string text) {
    for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return text;
  };
  // Nearest ignoring case ("GLB" means "glb", "Z" means "z", not "y"), then nearest as written.
  const std::string folded = lower(word);
  std::string best;
  std::pair<size_t, size_t> best_distance{std::numeric_limits<size_t>::max(), 0};
  for (const std::string& c : candidates) {
    const std::pair<size_t, size_t> d{edit_distance(folded, lower(c)), edit_distance(word, c)};
    if (d < best_distance) {
      best_distance = d;
      best = c;
    }
  }
  // A suggestion must be closer than a rewrite: at most a third of the word, at least 2 edits
  // (one for a word of three letters or fewer, where two would turn "fbx" into "obj").
  const size_t allowed = word.size() <= 3 ? 1 : std::max<size_t>(2, word.size() / 3);
  if (best_distance.first <= allowed) return best;
  // Else the one candidate it abbreviates, as "dir" does "direction".
  std::string abbreviated;
  for (const std::string& c : candidates)
    if (folded.size() >= 3 && lower(c).starts_with(folded)) {
      if (!abbreviated.empty()) return "";
      abbreviated = c;
    }
  return abbreviated;
}

}  // namespace treeanim
