// Throughput of the L-system stage: derivation of a non-parametric and a parametric
// grammar, and turtle interpretation, in modules per second (modules of every string produced,
// or read). A plain timing program: best of `repeats` runs, printed as one table.
//
// Usage: bench_lsystem [repeats]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>

#include "lsystem/derive.h"
#include "lsystem/grammar.h"
#include "lsystem/turtle.h"

namespace {

using treeanim::DerivationSettings;
using treeanim::Grammar;
using treeanim::ModuleString;

// ABOP Fig. 1.24a: F --> F[+F]F[-F]F (no parameters).
const char* kNonParametric = "axiom: F\nF --> F[+F]F[-F]F\n";

// ABOP Fig. 2.7a: sympodial tree, every successor parameter an expression.
const char* kParametric =
    "#define r1 0.9\n#define r2 0.7\n#define a1 5\n#define a2 65\n#define wr 0.707\n"
    "axiom: A(1,10)\n"
    "A(l,w) --> !(w)F(l)[&(a1)B(l*r1,w*wr)]/(180)[&(a2)B(l*r2,w*wr)]\n"
    "B(l,w) --> !(w)F(l)[+(a1)$B(l*r1,w*wr)][-(a2)$B(l*r2,w*wr)]\n";

// fn => the best wall time of `repeats` calls (seconds).
double best_seconds(int repeats, const std::function<void()>& fn) {
  double best = 1e300;
  for (int r = 0; r < repeats; ++r) {
    const auto start = std::chrono::steady_clock::now();
    fn();
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  return best;
}

// Modules written by a derivation of `iterations` steps: the sum of every step's string.
size_t modules_written(const Grammar& grammar, int iterations) {
  size_t total = 0;
  for (int n = 1; n <= iterations; ++n) total += treeanim::derive(grammar, {n, 1, 1u << 29}).size();
  return total;
}

void bench_derivation(const char* name, const char* text, int iterations, int repeats) {
  const Grammar grammar = treeanim::parse_grammar({{name, text, false}}, {});
  const size_t modules = modules_written(grammar, iterations);
  size_t final_size = 0;
  const double seconds = best_seconds(repeats, [&] {
    final_size = treeanim::derive(grammar, DerivationSettings{iterations, 1, 1u << 29}).size();
  });
  std::printf("%-28s %3d steps %11zu modules (final %10zu) %8.3f s %8.1f M modules/s\n", name, iterations,
              modules, final_size, seconds, static_cast<double>(modules) / seconds * 1e-6);
}

void bench_turtle(const char* name, const char* text, int iterations, int repeats) {
  const Grammar grammar = treeanim::parse_grammar({{name, text, false}}, {});
  const ModuleString word = treeanim::derive(grammar, DerivationSettings{iterations, 1, 1u << 29});
  treeanim::TurtleSettings settings;
  settings.angle_degrees = 25.7;
  size_t segments = 0;
  const double seconds = best_seconds(repeats, [&] { segments = treeanim::interpret(word, settings).segment_count(); });
  std::printf("%-28s %3d steps %11zu modules (%zu segments) %8.3f s %8.1f M modules/s\n", name, iterations,
              word.size(), segments, seconds, static_cast<double>(word.size()) / seconds * 1e-6);
}

}  // namespace

int main(int argc, char** argv) {
  const int repeats = argc > 1 ? std::max(1, std::atoi(argv[1])) : 3;
  std::printf("best of %d runs; modules/s counts every string the derivation writes\n", repeats);
  bench_derivation("derive non-parametric 1.24a", kNonParametric, 10, repeats);
  bench_derivation("derive parametric 2.7a", kParametric, 20, repeats);
  bench_turtle("turtle 1.24a", kNonParametric, 9, repeats);
  bench_turtle("turtle 2.7a", kParametric, 17, repeats);
  return 0;
}
