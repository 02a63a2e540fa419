#pragma once
// What a bake tells as it goes. The command line prints; a bake only calls these, and each says
// nothing unless it is set.
#include <cstddef>
#include <cstdio>
#include <functional>
#include <string>

namespace treeanim {

struct PreparedTree;
struct TreeBakeResult;

// `what` ("checking outputs") has passed `done` of a forest's `total` trees.
using TreesPassed = std::function<void(const char* what, size_t done, size_t total)>;

struct BakeLog {
  std::FILE* notes = nullptr;  // resumes, removed checkpoints, warm-up periods; null: quiet
  // Derivation step `step` of `steps` made `modules` modules (a grammar may derive for minutes).
  std::function<void(int step, int steps, size_t modules)> grown_step;
  // A pass over a forest's trees before the first is baked (a million trees take a minute).
  TreesPassed trees_passed = [](const char*, size_t, size_t) {};
  std::function<void(const PreparedTree&)> prepared = [](const PreparedTree&) {};  // grown and built
  std::function<void(long long total)> frames_begin = [](long long) {};  // the frame loop will simulate `total`
  std::function<void(long long done)> frame_done = [](long long) {};     // `done` frames of the loop are complete
  std::function<void()> frames_end = [] {};                              // the loop ended or was interrupted
  // The solver's team took a thread fewer or more (bake/thread_governor.h): the line to tell.
  std::function<void(const std::string& line)> team_resized = [](const std::string&) {};
  // Outputs already removed; frame -1: between two trees of a forest, whose baked trees stay.
  std::function<void(int signal, long long frame)> interrupted = [](int, long long) {};
  std::function<void(const TreeBakeResult&)> baked = [](const TreeBakeResult&) {};      // a tree's outputs are final
  // A forest: tree `tree`, the `i`th (from 0) of the `count` this process bakes, is next;
  // `complete`: its part says it is baked already, and it is skipped.
  std::function<void(size_t i, size_t count, size_t tree, bool complete)> forest_tree =
      [](size_t, size_t, size_t, bool) {};
};

}  // namespace treeanim
