#pragma once
// Derivation of a parsed grammar (docs/grammar.md): parallel rewriting with bracket-aware
// contexts, stochastic choice, decomposition after every step, homomorphism on demand.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "lsystem/grammar.h"
#include "lsystem/module_string.h"
#include "lsystem/turtle.h"

namespace treeanim {

struct DerivationSettings {
  int iterations = 0;                // derivation steps
  uint64_t seed = 0;                 // keys every random draw (with step and position)
  size_t max_modules = 20'000'000;   // InputError as soon as a string grows past this
  uint64_t max_loop_turns = kMaxLoopTurnsInAll;  // of every loop of its rules and blocks together
};

// Told after each derivation step: its number and the modules it made (progress).
using DerivationStepped = std::function<void(int step, size_t modules)>;

// grammar + settings => the word after settings.iterations steps; decomposition rules are
// applied after every step (not to the axiom, as in cpfg), and '%' removes the rest of its branch. When the
// grammar writes query modules, the turtle interprets the word (through the homomorphism)
// after the axiom and after every step, and they take their values (CPFG manual 6.9).
// Throws InputError at the module cap and on runtime errors (division by zero...), naming the
// step and the production.
// `turtle` is the one that answers the query modules. `variables`, when given, receives the
// global variables as the End block leaves them (the homomorphism reads them); `stepped`, when
// set, is told of each step.
ModuleString derive(const Grammar& grammar, const DerivationSettings& settings, const TurtleSettings& turtle = {},
                    std::vector<double>* variables = nullptr, const DerivationStepped& stepped = {});

// word => word with the homomorphism rules applied (what the turtle reads; the derivation
// never sees it), its expressions reading `variables` (derive's; when null, their values
// before the Start block). Throws InputError like derive.
ModuleString apply_homomorphism(const Grammar& grammar, const ModuleString& word,
                                const DerivationSettings& settings, const std::vector<double>* variables = nullptr);

}  // namespace treeanim
