#pragma once
// A parsed L-system grammar (docs/grammar.md): axiom, productions, decomposition and
// homomorphism rules, with every expression compiled into one ExprProgram.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "lsystem/expression.h"
#include "lsystem/lsystem_options.h"
#include "lsystem/module_string.h"

namespace treeanim {

// One module of a context pattern: a symbol with formal parameters, or '[' / ']' (right
// contexts only).
struct PatternModule {
  char symbol = 0;
  uint8_t arity = 0;         // formal parameters
  uint16_t first_slot = 0;   // where its formals go in the rule's slot array
};

// One module of a successor: its actual parameters are Exprs in RuleSet::successor_params.
struct SuccessorModule {
  char symbol = 0;
  uint8_t arity = 0;
  uint32_t first_param = 0;  // index into RuleSet::successor_params
  SourcePos pos;             // where it is written (arity diagnostics)
};

// [lc <] pred [> rc] [: condition] --> successor [: probability]
// A strict predecessor of several modules (CPFG manual 3.1) is its first module (predecessor,
// arity) followed by the modules of tail_begin..tail_end, matched one after the other.
struct Rule {
  char predecessor = 0;
  uint8_t arity = 0;
  uint16_t predecessor_slot = 0;  // first slot of the predecessor's formals
  uint16_t slot_count = 0;        // formals of lc, pred and rc together
  uint32_t left_begin = 0, left_end = 0;    // RuleSet::patterns, in text order
  uint32_t tail_begin = 0, tail_end = 0;    // RuleSet::patterns: the strict predecessor after its first module
  uint32_t right_begin = 0, right_end = 0;  // RuleSet::patterns, in text order
  uint32_t successor_begin = 0, successor_end = 0;  // RuleSet::successor
  Expr before;       // block run when the contexts match, before the condition (cpfg)
  Expr condition;    // absent: always true
  Expr after;        // block run when the condition holds, before the successor (cpfg)
  Expr probability;  // absent: deterministic
  SourcePos pos;     // the rule's first character
  bool cpfg_parts = false;  // a strict predecessor of several modules or a block: one test for the deriver
  bool has_context() const { return left_end > left_begin || right_end > right_begin; }
  // Modules the strict predecessor replaces.
  uint32_t length() const { return 1 + tail_end - tail_begin; }
};

// The rules of one section, indexed by predecessor symbol.
struct RuleSet {
  std::vector<Rule> rules;                     // (R) in text order
  std::vector<PatternModule> patterns;         // context modules of all rules
  std::vector<SuccessorModule> successor;      // successor modules of all rules
  std::vector<Expr> successor_params;          // actual parameter expressions
  std::array<uint32_t, 257> first_rule{};      // CSR by (unsigned char) symbol into rule_order
  std::vector<uint32_t> rule_order;            // (R) rule indices grouped by symbol, text order
  int max_depth = 1;                           // decomposition / homomorphism recursion depth
  bool any_context = false;                    // some rule has a left or right context
  bool any_cut = false;                        // some successor contains '%'
  // The productions of an L-system with 'seed:' (cpfg's stochastic L-system): every applicable
  // rule is a candidate of the draw, one without a probability weighing 1.
  bool stochastic = false;
  // Some rule's strict predecessor has several modules: the recursion of a decomposition or
  // homomorphism evaluates a successor's parameters when it applies the rule, so that such a
  // predecessor can match within it (CPFG manual 4.3.1, as cpfg rewrites its successor buffer).
  bool any_strict_tail = false;

  // Builds first_rule / rule_order from rules.
  void index();
  bool empty() const { return rules.empty(); }
};

// One L-system of a file ("lsystem: N" ... "endlsystem"). The first one in the file is derived;
// the others are sub-L-systems, whose productions rewrite the modules between a call
// '?(N, scale)' and its '$' (CPFG manual 7.2).
struct Lsystem {
  int label = 0;                           // N of its "lsystem: N" line (0 without one, or a name)
  std::array<bool, 256> context_skips{};   // symbols passed over when matching contexts
  bool ring = false;                       // "ring lsystem": contexts wrap around the string's ends (3.1.1)
  RuleSet productions;
  RuleSet decomposition;
  RuleSet homomorphism;
};

struct Grammar {
  std::vector<std::string> sources;   // names of the texts (file path, or "scene.json: /lsystem/...")
  std::vector<std::string> data_paths;  // the files fopen read, in the order it read them
  ExprProgram program;                // code of every expression
  std::vector<std::pair<std::string, double>> defines;  // resolved, scene overrides applied
  std::vector<SuccessorModule> axiom;       // evaluated when derivation starts (ran() uses the seed)
  std::vector<Expr> axiom_params;           // actual parameters of the axiom's modules
  std::vector<std::string> file_defines;    // names given by #define (scene overrides checked against them)
  std::vector<std::string> file_macros;     // names given by #define NAME(a, ...): no scene value replaces one
  std::optional<int> derivation_length;
  std::optional<double> angle;        // degrees
  std::optional<double> width_factor;
  uint64_t seed = 0;
  std::optional<uint64_t> homomorphism_seed;  // "seed:" after "homomorphism": its own draws (CPFG manual 4.3.3)
  std::vector<std::string> variables;      // global variables (assigned in Start/End blocks); slot i + 1
                                           // (an array: its name, then "" for its other elements)
  std::vector<double> initial_values;      // (variables + 1) their values before the Start block (arrays' initialisers)
  Expr start_block, start_each_block, end_each_block, end_block;  // cpfg control blocks (manual 4.1)
  std::optional<Eigen::Vector3d> tropism;  // T of "tropism:"
  double tropism_elasticity = 0.0;         // e of "tropism:"
  bool queries = false;                    // the axiom or a production writes ?P ?H ?U or ?L
  bool calls = false;                      // the axiom or a successor calls a sub-L-system ('?(N, s)')
  std::vector<Lsystem> lsystems{1};        // (L) in file order: [0] is derived, the rest are sub-L-systems

  // Index in lsystems of the first "lsystem: label" (label truncated, as cpfg does), or -1.
  int lsystem_index(double label) const;

  // "file:line:column" or "name, column N" of a place.
  std::string where(const SourcePos& pos) const;
};


// Texts (read in order, as one grammar) + define overrides => grammar. `axiom_text`, when
// given, is an inline axiom (another text, single line). Throws InputError
// "name:line:column: message".
// `functions` and `curves` are the view file's, for func(id, x) (id a number or a function's
// name) and curveX(id, t)... A file's #include is read beside it.
Grammar parse_grammar(const std::vector<GrammarText>& texts,
                      const std::vector<std::pair<std::string, double>>& define_overrides,
                      const std::optional<GrammarText>& axiom_text = std::nullopt,
                      std::vector<SampledFunction> functions = {}, std::vector<ViewCurve> curves = {});

}  // namespace treeanim
