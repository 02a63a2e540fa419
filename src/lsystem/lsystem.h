#pragma once
// Stage entry point: L-system options => derived module string => turtle => Skeleton.
#include <cstddef>
#include <filesystem>
#include <functional>
#include <vector>

#include "lsystem/derive.h"
#include "lsystem/grammar.h"
#include "lsystem/lsystem_options.h"
#include "lsystem/skeleton.h"
#include "lsystem/turtle.h"
#include "lsystem/view_file.h"

namespace treeanim {

struct GrowthStats {
  size_t modules = 0;  // modules in the derived string (after decomposition)
  int iterations = 0;  // derivation steps applied
};

// options => grammar read from the file or the inline rules, scene defines applied.
// Throws InputError (file:line:column, or a JSON pointer for a define the file lacks).
Grammar load_grammar(const LsystemOptions& options, const ViewSettings& view = {});

// options => the view file's settings (none without lsystem.view). Throws InputError.
ViewSettings load_view(const LsystemOptions& options);

// options => the files the grammar and view file read beyond those the scene names: the
// grammar's #includes and fopen files, the view's surfaces, curves and functions (each
// parsed, not grown). Empty for a grammar of the scene or the library without a view file.
// Throws InputError.
std::vector<std::filesystem::path> grammar_input_files(const LsystemOptions& options);

// options + grammar => derivation settings: the scene's iterations override "derivation
// length:", the scene seed is mixed with the grammar's "seed:".
DerivationSettings derivation_settings(const LsystemOptions& options, const Grammar& grammar);

// options + grammar + view => turtle settings (scene values override the view file's, which
// override the grammar's directives).
TurtleSettings turtle_settings(const LsystemOptions& options, const Grammar& grammar, const ViewSettings& view = {});

// options => the name messages give the grammar: its file, the species' grammar, or the
// scene's inline rules ("scene.json: /lsystem").
std::string grammar_name(const LsystemOptions& options);

// options => whether the seed changes what grows: a stochastic rule, or an expression that
// draws (ran, nran, bran, biran); else every seed grows the same tree.
bool seed_shapes_growth(const LsystemOptions& options);

// options (grammar file or inline rules, defines, seed, step) => skeleton (scene units);
// `stepped` is told of each derivation step: its number, of how many, and its modules. Throws InputError
// with file:line:column for grammar errors, and at the module cap.
Skeleton grow_skeleton(const LsystemOptions& options, GrowthStats* stats,
                       const std::function<void(int step, int steps, size_t modules)>& stepped = {});

}  // namespace treeanim
