#include "lsystem/derive.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <sstream>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "common/errors.h"
#include "common/message_text.h"

namespace treeanim {

namespace {

// Keys of the random streams, so that the same (step, position) never shares draws between
// purposes.
enum Purpose : uint64_t { kAxiom = 1, kProduction = 2, kDecomposition = 3, kHomomorphism = 4, kBlock = 5 };

constexpr int kMaxSlots = 64;  // formal parameters of one rule (the parser enforces it)

class Deriver {
 public:
  Deriver(const Grammar& grammar, const DerivationSettings& settings, const TurtleSettings& turtle = {})
      : g_(grammar), settings_(settings), turtle_(turtle), variables_(grammar.initial_values) {
    variables_.resize(grammar.variables.size() + 1, 0.0);
    start_loop_budget(settings.max_loop_turns);
  }

  // Start, then per step StartEach / productions / decomposition / EndEach, then End (CPFG
  // manual 4.1).
  ModuleString derive(const DerivationStepped& stepped) {
    ModuleString word;
    word.clear();
    run_block(g_.start_block);
    emit_axiom(&word);
    word = finish_step(std::move(word), 0);
    ModuleString next;
    for (step_ = 1; step_ <= settings_.iterations; ++step_) {
      run_block(g_.start_each_block);
      rewrite(word, &next);
      std::swap(word, next);
      word = finish_step(std::move(word), step_);
      run_block(g_.end_each_block);
      if (stepped) stepped(step_, word.size());
    }
    step_ = settings_.iterations;
    if (settings_.iterations > 0) run_block(g_.end_block);  // cpfg runs End in its last step's Derive
    return word;
  }

  ModuleString homomorphism(const ModuleString& word) {
    if (!any_rules(&Lsystem::homomorphism)) return word;
    step_ = settings_.iterations + 1;
    ModuleString out;
    expand_all(&Lsystem::homomorphism, word, kHomomorphism, &out);
    return out;
  }

  // The global variables ([0] the last srand() argument).
  std::vector<double>& variables() { return variables_; }

  // Adds the step and the rule to a runtime error of an expression.
  [[noreturn]] void rethrow(const EvalError& error) const {
    std::string where = "while deriving step " + std::to_string(step_);
    if (step_ == 0) where = "while evaluating the axiom";
    if (step_ > settings_.iterations) where = "while applying the homomorphism";
    throw InputError(g_.where(error.pos) + ": " + error.message + " " + where + rule_place());
  }

  // The rule being applied by its place, " (rule at line:column)" in a file, the element and
  // column of an inline grammar; "" outside a rule.
  std::string rule_place() const {
    if (!rule_) return "";
    return " (rule at " +
           (rule_->pos.line == 0 ? g_.where(rule_->pos)
                                 : std::to_string(rule_->pos.line) + ":" + std::to_string(rule_->pos.column)) +
           ")";
  }

  // A call '?(label, s)' to an L-system the file does not have => what is wrong, and when.
  std::string unknown_call(double label) const {
    std::ostringstream value, called;
    value << label;
    called << std::trunc(label);  // as cpfg, a label's fraction is dropped (Grammar::lsystem_index)
    return "'?(" + value.str() + ", ...)' calls L-system " + called.str() + " " +
           (step_ == 0 ? std::string("in the axiom") : "while deriving step " + std::to_string(step_)) +
           ", but the file has no 'lsystem: " + called.str() + "'";
  }

 private:
  // The seed of the random streams: the settings' one, changed by the last srand() (cpfg 5.3).
  uint64_t seed() const {
    const double srand_value = variables_[kSrandVariable];
    return srand_value == 0.0 ? settings_.seed
                              : settings_.seed ^ (std::bit_cast<uint64_t>(srand_value) * 0x9e3779b97f4a7c15ULL);
  }

  // The seed of the homomorphism's draws: its own "seed:" (CPFG manual 4.3.3: the same draws
  // whatever the derivation's seed), else the derivation's.
  uint64_t homomorphism_seed() const {
    return g_.homomorphism_seed ? RandomStream::keyed(*g_.homomorphism_seed, kHomomorphism, 0, 0).next_u64() : seed();
  }

  // A Start/StartEach/EndEach/End block, its draws keyed by the step.
  void run_block(const Expr& block) {
    if (!block.present()) return;
    rule_ = nullptr;
    RandomStream random = RandomStream::keyed(seed(), kBlock, static_cast<uint64_t>(step_), block.begin);
    double no_slots[1] = {0.0};
    execute(g_.program, block, no_slots, random, variables_.data());
  }

  // A module parameter's expression => its value as the string keeps it (stored_parameter).
  double parameter(const Expr& expr, const double* slots, RandomStream& random) {
    const double value = evaluate(g_.program, expr, slots, random, variables_.data());
    const double stored = stored_parameter(value);
    if (!std::isfinite(stored))
      throw EvalError{expr.pos, "the value " + number_text(value) + " is past a module parameter's range: a parameter "
                                "is a 32-bit float, as in cpfg, at most 3.4e38 in magnitude"};
    return stored;
  }

  // The axiom's modules, their parameters evaluated with the axiom's random stream.
  void emit_axiom(ModuleString* out) {
    RandomStream random = RandomStream::keyed(seed(), kAxiom, 0, 0);
    for (const SuccessorModule& m : g_.axiom) {
      out->symbols.push_back(m.symbol);
      for (uint32_t p = 0; p < m.arity; ++p)
        out->params.push_back(parameter(g_.axiom_params[m.first_param + p], nullptr, random));
      out->param_offsets.push_back(static_cast<uint32_t>(out->params.size()));
    }
    check_cap(*out);
  }

  // Whether some L-system has rules in this section.
  bool any_rules(RuleSet Lsystem::*section) const {
    return std::any_of(g_.lsystems.begin(), g_.lsystems.end(), [&](const Lsystem& ls) { return !(ls.*section).empty(); });
  }

  // After productions (or the axiom): decomposition, then cuts. cpfg decomposes what each step
  // writes, never the axiom (generate.c, ApplyProd): step 1's productions see the axiom as written.
  ModuleString finish_step(ModuleString word, int step) {
    step_ = step;
    if (step > 0 && any_rules(&Lsystem::decomposition)) {
      ModuleString out;
      expand_all(&Lsystem::decomposition, word, kDecomposition, &out);
      word = std::move(out);
    }
    // A '%' may come from a rule or stand in the axiom (cpfg cuts any it finds in the string).
    if (std::any_of(g_.lsystems.begin(), g_.lsystems.end(),
                    [](const Lsystem& ls) { return ls.productions.any_cut || ls.decomposition.any_cut; }) ||
        std::any_of(g_.axiom.begin(), g_.axiom.end(), [](const SuccessorModule& m) { return m.symbol == '%'; }))
      cut_branches(&word);
    if (g_.calls) {  // every call names an L-system (the next step, or the turtle, follows them)
      enter(0);
      follow_calls(word, 0, word.size());
    }
    if (g_.queries) answer(&word);
    return word;
  }

  // Query modules (CPFG manual 6.9): the turtle interprets the word as it is drawn, through the
  // homomorphism, and every '?' with its letter that the homomorphism leaves as it is takes the
  // value it asks for.
  void answer(ModuleString* word) {
    if (!any_rules(&Lsystem::homomorphism)) return answer_queries(word, turtle_);
    const int step = step_;
    step_ = settings_.iterations + 1;
    ModuleString drawn;
    expand_all(&Lsystem::homomorphism, *word, kHomomorphism, &drawn, &drawn_at_);
    step_ = step;
    answer_queries(&drawn, turtle_);
    for (size_t i = 1; i < word->size(); ++i) {
      const uint32_t d = drawn_at_[i];
      if (word->symbols[i - 1] != '?' || !word->params_of(i - 1).empty() || drawn_at_[i + 1] != d + 1 ||
          drawn_at_[i] != drawn_at_[i - 1] + 1 ||
          drawn.symbols[d] != word->symbols[i] || drawn.params_of(d).size() != word->params_of(i).size())
        continue;
      std::copy(drawn.params_of(d).begin(), drawn.params_of(d).end(), word->params.begin() + word->param_offsets[i]);
    }
  }

  // Parameters a string may hold per module of its cap: a module takes up to 255, and 20 million
  // of those (40 GB) filled the memory before the module cap was reached.
  static constexpr size_t kParamsPerModule = 4;
  bool past_cap(const ModuleString& word) const {
    return word.size() > settings_.max_modules || word.params.size() > kParamsPerModule * settings_.max_modules;
  }
  void check_cap(const ModuleString& word) const {
    if (!past_cap(word)) return;
    const bool homomorphism = step_ > settings_.iterations;
    const std::string when = step_ == 0     ? std::string("the axiom")
                             : homomorphism ? "the homomorphism"
                                            : "derivation step " + std::to_string(step_) + " of " +
                                                  std::to_string(settings_.iterations);
    const bool modules = word.size() > settings_.max_modules;
    throw InputError(g_.sources.at(0) + ": " + when + " reached " +
                     (modules ? std::to_string(word.size()) + " modules, more than"
                              : std::to_string(word.params.size()) + " parameters, more than " +
                                    std::to_string(kParamsPerModule) + " x") +
                     " lsystem.max_modules = " + std::to_string(settings_.max_modules) +
                     (homomorphism ? " (lower lsystem.iterations or the homomorphism's 'maximum depth:', or raise "
                                     "lsystem.max_modules)"
                                   : " (lower lsystem.iterations or raise lsystem.max_modules)"));
  }

  static void copy_module(const ModuleString& in, size_t i, ModuleString* out) {
    out->symbols.push_back(in.symbols[i]);
    const uint32_t b = in.param_offsets[i], e = in.param_offsets[i + 1];
    if (e > b) out->params.insert(out->params.end(), in.params.begin() + b, in.params.begin() + e);
    out->param_offsets.push_back(static_cast<uint32_t>(out->params.size()));
  }

  // One parallel rewriting step: word => *next.
  void rewrite(const ModuleString& word, ModuleString* next) {
    next->clear();
    // Strings usually grow by a small factor per step; never reserve past the cap.
    const size_t expected = std::min(word.size() * 2, settings_.max_modules + 1);
    next->symbols.reserve(expected);
    next->param_offsets.reserve(expected + 1);
    next->params.reserve(std::min(word.params.size() * 2, expected * 4));
    if (std::any_of(g_.lsystems.begin(), g_.lsystems.end(), [](const Lsystem& ls) { return ls.productions.any_context; }))
      match_brackets(word);
    word_ = &word;
    if (g_.calls) rewrite_modules<true>(word, next);
    else rewrite_modules<false>(word, next);
    word_ = nullptr;
  }

  // The modules of word rewritten in order; with kCalls, those between a call '?(label, s)' and
  // its '$' by the productions of L-system `label` (CPFG manual 7.2).
  template <bool kCalls>
  void rewrite_modules(const ModuleString& word, ModuleString* next) {
    enter(0);
    const RuleSet* set = &ls_->productions;
    double slots[kMaxSlots];
    for (size_t i = 0; i < word.size(); ++i) {
      const auto s = static_cast<unsigned char>(word.symbols[i]);
      if (set->first_rule[s] == set->first_rule[s + 1]) {
        copy_module(word, i, next);
        if constexpr (kCalls) set = &follow_calls(word, i, 1)->productions;
        continue;
      }
      RandomStream random = RandomStream::keyed(seed(), kProduction, static_cast<uint64_t>(step_), i);
      const Rule* rule = select(*set, word.symbols[i], word.params_of(i), i, slots, random);
      const size_t used = rule ? rule->length() : 1;
      if (rule) emit_successor(*set, *rule, slots, random, next);
      else copy_module(word, i, next);
      if constexpr (kCalls) set = &follow_calls(word, i, used)->productions;
      i += used - 1;
      if (past_cap(*next)) check_cap(*next);
    }
  }

  // The L-system `index` is the only one called; => it.
  const Lsystem* enter(uint32_t index) {
    calls_.assign(1, index);
    return ls_ = &g_.lsystems[index];
  }

  // Modules [i, i + count) of word passed: a call '?(label, s)' makes L-system `label` current,
  // a '$' returns to its caller (one without a call is passed over, as cpfg does). => the
  // current L-system.
  const Lsystem* follow_calls(const ModuleString& word, size_t i, size_t count) {
    for (size_t k = i; k < i + count; ++k) {
      if (word.symbols[k] == '$' && calls_.size() > 1) calls_.pop_back();
      if (word.symbols[k] != '?' || word.params_of(k).empty()) continue;
      const double label = word.params_of(k)[0];
      const int index = g_.lsystem_index(label);
      if (index < 0) throw InputError(g_.sources.at(0) + ": " + unknown_call(label));
      calls_.push_back(static_cast<uint32_t>(index));
    }
    return ls_ = &g_.lsystems[calls_.back()];
  }

  // match_[k] for every bracket of word: the index of its partner; the walks' stops, which
  // depend on the L-system's skips, are found again when first asked (left_stops, right_stops).
  void match_brackets(const ModuleString& word) {
    left_stops_.clear();
    right_stops_.clear();
    match_.assign(word.size(), -1);
    std::vector<int32_t> open;
    for (size_t k = 0; k < word.size(); ++k) {
      if (word.symbols[k] == '[') open.push_back(static_cast<int32_t>(k));
      else if (word.symbols[k] == ']' && !open.empty()) {
        match_[k] = open.back();
        match_[static_cast<size_t>(open.back())] = static_cast<int32_t>(k);
        open.pop_back();
      }
    }
  }

  // The rule rewriting a module (symbol, params; at `index` of word_, where contexts and a strict
  // predecessor of several modules are matched; a module from a successor (derived_) takes the
  // contexts of `index` and only rules of one module),
  // its formal parameters bound in slots; nullptr when none applies. The first applicable rule
  // wins; when it has a probability, one of all applicable rules with a probability is drawn
  // with weights proportional to them. In a stochastic set (cpfg's, with 'seed:') every
  // applicable rule is drawn from, one without a probability weighing 1, and when every weight
  // is 0 the first applies, as cpfg's SelectProd does.
  const Rule* select(const RuleSet& set, char symbol, std::span<const double> params, size_t index,
                     double* slots, RandomStream& random) {
    const auto s = static_cast<unsigned char>(symbol);
    double total = 0;
    size_t candidates = 0;
    bool weighed = false;  // some candidate has a probability: the choice draws a number
    for (uint32_t k = set.first_rule[s]; k < set.first_rule[s + 1]; ++k) {
      const Rule& rule = set.rules[set.rule_order[k]];
      if (!applies(set, rule, params, index, slots, random)) continue;
      if (!rule.probability.present() && !set.stochastic) {
        if (candidates == 0) return &rule;
        continue;
      }
      rule_ = &rule;
      weighed = weighed || rule.probability.present();
      const double weight =
          rule.probability.present() ? evaluate(g_.program, rule.probability, slots, random, variables_.data()) : 1.0;
      if (weight < 0)
        throw EvalError{rule.probability.pos, "expected a probability >= 0, got " + number_text(weight)};
      weights_.resize(candidates + 1);
      chosen_.resize(candidates + 1);
      chosen_slots_.resize((candidates + 1) * kMaxSlots);
      weights_[candidates] = weight;
      chosen_[candidates] = &rule;
      std::copy(slots, slots + rule.slot_count, chosen_slots_.begin() + static_cast<std::ptrdiff_t>(candidates * kMaxSlots));
      ++candidates;
      total += weight;
    }
    if (candidates == 0 || (total <= 0 && !set.stochastic)) return nullptr;
    if (std::isinf(total)) {
      // Finite weights whose sum overflows (1e308 twice): scaled by a power of two, exactly, so
      // that the draw keeps their ratios rather than falling to the last rule every time.
      const int exponent = std::ilogb(*std::max_element(weights_.begin(), weights_.begin() + candidates));
      total = 0;
      for (size_t c = 0; c < candidates; ++c) total += weights_[c] = std::ldexp(weights_[c], -exponent);
    }
    // A lone rule without a probability applies without a draw, as outside a stochastic set.
    const bool draws = total > 0 && (weighed || candidates > 1);
    const double draw = draws ? random.uniform() * total : 0.0;
    double sum = 0;
    size_t pick = draws ? candidates - 1 : 0;
    for (size_t c = 0; c < candidates && draws; ++c) {
      sum += weights_[c];
      if (draw < sum && weights_[c] > 0) {
        pick = c;
        break;
      }
    }
    const Rule* rule = chosen_[pick];
    // Its formals and locals as they were bound (running its blocks again would repeat their effects).
    const auto bound = chosen_slots_.begin() + static_cast<std::ptrdiff_t>(pick * kMaxSlots);
    std::copy(bound, bound + rule->slot_count, slots);
    return rule;
  }

  // Symbol arity, strict predecessor, contexts and condition of one rule; binds its formals
  // into slots.
  bool applies(const RuleSet& set, const Rule& rule, std::span<const double> params, size_t index,
               double* slots, RandomStream& random) {
    if (rule.arity != params.size()) return false;
    for (size_t p = 0; p < params.size(); ++p) slots[rule.predecessor_slot + p] = params[p];
    if (rule.cpfg_parts && rule.length() > 1 && !match_tail(set, rule, index, slots)) return false;
    if (rule.left_end > rule.left_begin && !match_left(set, rule, index, slots)) return false;
    if (rule.right_end > rule.right_begin && !match_right(set, rule, index, slots)) return false;
    rule_ = &rule;
    if (rule.cpfg_parts && rule.before.present()) {
      std::fill(slots + rule.predecessor_slot + rule.arity, slots + rule.slot_count, 0.0);  // locals start at 0
      execute(g_.program, rule.before, slots, random, variables_.data());
    }
    if (rule.condition.present() && evaluate(g_.program, rule.condition, slots, random, variables_.data()) == 0.0)
      return false;
    if (rule.cpfg_parts && rule.after.present()) execute(g_.program, rule.after, slots, random, variables_.data());
    return true;
  }

  static void bind(const ModuleString& word, size_t j, const PatternModule& pattern, double* slots) {
    const std::span<const double> values = word.params_of(j);
    for (size_t p = 0; p < values.size(); ++p) slots[pattern.first_slot + p] = values[p];
  }

  // The strict predecessor after its first module: the modules right after it, one by one
  // (no module passed over; CPFG manual 3.1).
  bool match_tail(const RuleSet& set, const Rule& rule, size_t index, double* slots) const {
    if (derived_) return match_tail_ahead(set, rule, slots);
    if (!word_ || index + rule.length() > word_->size()) return false;
    for (uint32_t p = rule.tail_begin; p < rule.tail_end; ++p) {
      const PatternModule& pattern = set.patterns[p];
      const size_t j = index + 1 + (p - rule.tail_begin);
      if (word_->symbols[j] != pattern.symbol || word_->params_of(j).size() != pattern.arity) return false;
      bind(*word_, j, pattern, slots);
    }
    return true;
  }

  // The same for a module of a successor: the modules after it in that successor, with the
  // parameters its rule's application evaluated (ahead_); none past the successor's end.
  bool match_tail_ahead(const RuleSet& set, const Rule& rule, double* slots) const {
    if (!ahead_.valid) return false;
    const Frame& frame = frames_[ahead_.frame];
    if (ahead_.position + (rule.length() - 1) > frame.rule->successor_end) return false;
    size_t at = ahead_.cursor;
    for (uint32_t p = rule.tail_begin; p < rule.tail_end; ++p) {
      const PatternModule& pattern = set.patterns[p];
      const SuccessorModule& module = set.successor[ahead_.position + (p - rule.tail_begin)];
      if (module.symbol != pattern.symbol || module.arity != pattern.arity) return false;
      for (uint32_t k = 0; k < module.arity; ++k) slots[pattern.first_slot + k] = frame_params_[at + k];
      at += module.arity;
    }
    return true;
  }

  // Left context: walks left, skipping complete branches (']' ... '[') and climbing out of the
  // current branch ('['), passing over ignored symbols; in a ring L-system the string's start
  // goes on at its end (CPFG manual 3.1.1), at most one turn per pattern module.
  bool match_left(const RuleSet& set, const Rule& rule, size_t index, double* slots) {
    const ModuleString& w = *word_;
    const std::vector<int32_t>& stop = left_stops(ls_->context_skips);
    ptrdiff_t j = static_cast<ptrdiff_t>(index) - 1;
    uint32_t turns = 0;
    for (uint32_t p = rule.left_end; p-- > rule.left_begin;) {
      const PatternModule& pattern = set.patterns[p];
      for (;;) {
        if (j < 0) {
          if (!ls_->ring || ++turns > rule.left_end - rule.left_begin) return false;
          j = static_cast<ptrdiff_t>(w.size()) - 1;
          continue;
        }
        j = stop[static_cast<size_t>(j)];
        if (j >= 0) break;
      }
      const auto k = static_cast<size_t>(j);
      if (w.symbols[k] != pattern.symbol || w.params_of(k).size() != pattern.arity) return false;
      bind(w, k, pattern, slots);
      --j;
    }
    return true;
  }

  // For each k of word_, where a left walk from k stops for `skips`: k itself, or the first
  // module to its left after lateral branches (']' to its '['), '[' and skipped symbols, or
  // -1 past the start. Found once per word and skip table, left to right, since each entry
  // follows from one before it: a walk per module stepped over every earlier sibling branch
  // (quadratic: 200,000 branches of one axis took a minute).
  const std::vector<int32_t>& left_stops(const std::array<bool, 256>& skips) {
    for (const auto& [table, stops] : left_stops_)
      if (table == &skips) return stops;
    const ModuleString& w = *word_;
    std::vector<int32_t> stops(w.size());
    auto before = [&](int32_t k) { return k > 0 ? stops[static_cast<size_t>(k - 1)] : -1; };
    for (size_t k = 0; k < w.size(); ++k) {
      const char c = w.symbols[k];
      if (c == ']') stops[k] = match_[k] < 0 ? -1 : before(match_[k]);
      else if (c == '[' || skips[static_cast<unsigned char>(c)]) stops[k] = before(static_cast<int32_t>(k));
      else stops[k] = static_cast<int32_t>(k);
    }
    left_stops_.emplace_back(&skips, std::move(stops));
    return left_stops_.back().second;
  }

  // For each k of word_, where a right walk from k stops for `skips` (a pattern module other
  // than '['): k itself, or the first module to its right after lateral branches ('[' to past
  // its ']', or into it when '[' is skipped) and skipped symbols; -1 at a ']' that ends the
  // branch, the word's size past its end. Found once per word and skip table, right to left.
  const std::vector<int32_t>& right_stops(const std::array<bool, 256>& skips) {
    for (const auto& [table, stops] : right_stops_)
      if (table == &skips) return stops;
    const ModuleString& w = *word_;
    const auto n = static_cast<int32_t>(w.size());
    std::vector<int32_t> stops(w.size() + 1);
    stops[w.size()] = n;
    for (size_t k = w.size(); k-- > 0;) {
      const char c = w.symbols[k];
      if (c == '[') stops[k] = skips['['] ? stops[k + 1] : match_[k] < 0 ? n : stops[static_cast<size_t>(match_[k]) + 1];
      else if (c == ']') stops[k] = skips[']'] ? stops[k + 1] : -1;
      else stops[k] = skips[static_cast<unsigned char>(c)] ? stops[k + 1] : static_cast<int32_t>(k);
    }
    right_stops_.emplace_back(&skips, std::move(stops));
    return right_stops_.back().second;
  }

  // Right context: walks right, skipping lateral branches and ignored symbols, failing at the
  // end of the current branch (']'); pattern brackets enter a branch ('[') or leave it (']').
  // An ignored '[' is entered and an ignored ']' passed (cpfg); a ring L-system's end goes on
  // at its start.
  bool match_right(const RuleSet& set, const Rule& rule, size_t index, double* slots) {
    const ModuleString& w = *word_;
    const std::array<bool, 256>& skips = ls_->context_skips;
    const std::vector<int32_t>& stop = right_stops(skips);
    const size_t n = w.size();
    size_t j = derived_ ? origin_end_ : index + rule.length();
    uint32_t turns = 0;
    for (uint32_t p = rule.right_begin; p < rule.right_end; ++p) {
      const PatternModule& pattern = set.patterns[p];
      if (pattern.symbol == ']' || pattern.symbol == '=') {  // '=' (cpfg): to the branch's end, before its ']'
        while (j < n && w.symbols[j] != ']') j = w.symbols[j] == '[' ? static_cast<size_t>(match_[j]) + 1 : j + 1;
        if (pattern.symbol == '=') continue;
        if (j >= n) return false;
        ++j;
        continue;
      }
      for (;;) {
        if (j >= n) {
          if (!ls_->ring || ++turns > rule.right_end - rule.right_begin) return false;
          j = 0;
          continue;
        }
        if (pattern.symbol != '[') {
          if (stop[j] < 0) return false;
          j = static_cast<size_t>(stop[j]);
          if (j < n) break;
          continue;
        }
        const char c = w.symbols[j];  // a '[' in the pattern stops at the word's next '['
        if (c == ']' && !skips[']']) return false;
        if (c != '[' && skips[static_cast<unsigned char>(c)]) ++j;
        else break;
      }
      if (w.symbols[j] != pattern.symbol || w.params_of(j).size() != pattern.arity) return false;
      bind(w, j, pattern, slots);
      ++j;
    }
    return true;
  }

  void emit_successor(const RuleSet& set, const Rule& rule, double* slots, RandomStream& random,
                      ModuleString* out) {
    rule_ = &rule;
    for (uint32_t m = rule.successor_begin; m < rule.successor_end; ++m) {
      const SuccessorModule& module = set.successor[m];
      out->symbols.push_back(module.symbol);
      for (uint32_t p = 0; p < module.arity; ++p)
        out->params.push_back(parameter(set.successor_params[module.first_param + p], slots, random));
      out->param_offsets.push_back(static_cast<uint32_t>(out->params.size()));
      // A call whose label is computed is checked where its rule writes it.
      if (g_.calls && module.symbol == '?' && module.arity > 0) {
        const double label = out->params[out->params.size() - module.arity];
        if (g_.lsystem_index(label) < 0) throw InputError(g_.where(module.pos) + ": " + unknown_call(label) + rule_place());
      }
    }
  }

  // Context-free rules of a section applied recursively (up to its max_depth) to every module,
  // each with its L-system's rules: word => *out. at, when given: (word size + 1) where each
  // module's expansion starts in *out (the modules a strict predecessor of several replaces
  // start where the next one does).
  void expand_all(RuleSet Lsystem::*section, const ModuleString& word, Purpose purpose, ModuleString* out,
                  std::vector<uint32_t>* at = nullptr) {
    expanding_ = purpose;
    modules_begun_ = 0;
    out->clear();
    out->symbols.reserve(word.size());
    out->param_offsets.reserve(word.size() + 1);
    if (at) at->assign(word.size() + 1, 0);
    if (std::any_of(g_.lsystems.begin(), g_.lsystems.end(), [&](const Lsystem& ls) { return (ls.*section).any_context; }))
      match_brackets(word);
    const uint64_t key = purpose == kHomomorphism ? homomorphism_seed() : seed();
    const RuleSet* set = &(enter(0)->*section);
    for (size_t i = 0; i < word.size();) {
      RandomStream random = RandomStream::keyed(key, purpose, static_cast<uint64_t>(step_), i);
      const size_t used = expand(*set, word, i, random, out);
      if (at) std::fill(at->begin() + static_cast<std::ptrdiff_t>(i) + 1, at->begin() + static_cast<std::ptrdiff_t>(i + used) + 1,
                        static_cast<uint32_t>(out->size()));
      if (g_.calls) set = &(follow_calls(word, i, used)->*section);
      i += used;
      if (past_cap(*out)) check_cap(*out);
    }
  }

  // A rule being expanded: its bound slots live in frame_slots_[slots, slots + slot_count).
  // In a set with strict predecessors of several modules (RuleSet::any_strict_tail), its
  // successor's parameters were evaluated when it was applied: frame_params_[params, ...), the
  // next module's from `cursor`; else params is kNoParams and each module's are evaluated in turn.
  static constexpr size_t kNoParams = static_cast<size_t>(-1);
  struct Frame {
    const Rule* rule;
    uint32_t next;   // next successor module
    int depth;
    size_t slots;
    size_t params = kNoParams;
    size_t cursor = 0;
  };
  // The successor modules after the one being begun, for match_tail_ahead: those of
  // frames_[frame] from `position`, their parameters at frame_params_[cursor].
  struct Ahead {
    bool valid = false;
    size_t frame = 0;
    uint32_t position = 0;
    size_t cursor = 0;
  };

  // frames_.back() => popped, with its slots and parameters.
  void pop_frame() {
    const Frame& frame = frames_.back();
    frame_slots_.resize(frame.slots);
    if (frame.params != kNoParams) frame_params_.resize(frame.params);
    frames_.pop_back();
  }

  // Module `index` of word (with the modules after it, for a strict predecessor of several)
  // => its expansion appended to *out, depth first in successor order, with an explicit stack
  // (frames_) instead of recursion; the last module of a successor replaces its rule's frame,
  // so a rule that ends by calling itself runs in constant space. Successor modules are
  // expanded one by one (a rule of several modules applies to the word only); their contexts
  // are those of module `index` in word (CPFG manual 4.3.2). => the modules of word used.
  size_t expand(const RuleSet& set, const ModuleString& word, size_t index, RandomStream& random,
                ModuleString* out) {
    frames_.clear();
    frame_slots_.clear();
    frame_params_.clear();
    word_ = &word;
    const size_t used = begin_module(set, word.symbols[index], word.params_of(index), index, 0, random, out);
    derived_ = true;
    origin_end_ = index + used;
    while (!frames_.empty()) {
      Frame& frame = frames_.back();
      const Rule& rule = *frame.rule;
      if (frame.next == rule.successor_end) {  // its last modules matched a strict predecessor before
        pop_frame();
        continue;
      }
      rule_ = &rule;
      const SuccessorModule& module = set.successor[frame.next++];
      const int depth = frame.depth + 1;
      scratch_.clear();
      if (frame.params != kNoParams) {
        scratch_.assign(frame_params_.begin() + std::ptrdiff_t(frame.cursor),
                        frame_params_.begin() + std::ptrdiff_t(frame.cursor + module.arity));
        frame.cursor += module.arity;
      } else {
        const double* slots = frame_slots_.data() + frame.slots;
        for (uint32_t p = 0; p < module.arity; ++p)
          scratch_.push_back(parameter(set.successor_params[module.first_param + p], slots, random));
      }
      const size_t at = frames_.size() - 1;
      const bool last = frame.next == rule.successor_end;
      ahead_ = {.valid = !last && frame.params != kNoParams, .frame = at, .position = frame.next, .cursor = frame.cursor};
      if (last) pop_frame();
      params_.assign(scratch_.begin(), scratch_.end());
      const size_t used = begin_module(set, module.symbol, params_, index, depth, random, out);
      ahead_.valid = false;
      for (size_t skipped = 1; skipped < used; ++skipped) {  // the rest of the strict predecessor it matched
        Frame& from = frames_[at];
        from.cursor += set.successor[from.next++].arity;
      }
      if (past_cap(*out)) check_cap(*out);
    }
    word_ = nullptr;
    derived_ = false;
    return used;
  }

  // A module at `depth` (its contexts those of `index` in word_): copied to *out when no rule
  // applies, else its rule's frame pushed. => the modules its rule replaces (1 when none).
  size_t begin_module(const RuleSet& set, char symbol, std::span<const double> params, size_t index, int depth,
                      RandomStream& random, ModuleString* out) {
    if (++modules_begun_ > kModulesBegunPerModule * settings_.max_modules) fail_expansion_work();
    double slots[kMaxSlots];
    const Rule* rule = depth < set.max_depth ? select(set, symbol, params, index, slots, random) : nullptr;
    if (!rule) {
      out->symbols.push_back(symbol);
      out->params.insert(out->params.end(), params.begin(), params.end());
      out->param_offsets.push_back(static_cast<uint32_t>(out->params.size()));
      return 1;
    }
    if (rule->successor_begin != rule->successor_end) {  // else erased
      frames_.push_back({rule, rule->successor_begin, depth, frame_slots_.size()});
      frame_slots_.insert(frame_slots_.end(), slots, slots + rule->slot_count);
      if (set.any_strict_tail) {
        // Its successor's parameters now, with its slots, in module order.
        Frame& frame = frames_.back();
        frame.params = frame.cursor = frame_params_.size();
        rule_ = rule;
        for (uint32_t m = rule->successor_begin; m < rule->successor_end; ++m)
          for (uint32_t p = 0; p < set.successor[m].arity; ++p)
            frame_params_.push_back(parameter(set.successor_params[set.successor[m].first_param + p],
                                              frame_slots_.data() + frame.slots, random));
      }
    }
    return rule->length();
  }

  // Rules that recurse to their 'maximum depth:' without growing the word (A(n) --> A(n-1)A(n-1)
  // ending in an erasure) take time the module cap never sees: a pass that begins more modules
  // than this many per module of the cap stops (a pass begins each module it writes once, and
  // each rule it applies once more).
  static constexpr size_t kModulesBegunPerModule = 8;
  [[noreturn]] void fail_expansion_work() const {
    const std::string section = expanding_ == kHomomorphism ? "homomorphism" : "decomposition";
    throw InputError(g_.sources.at(0) + ": the " + section + (expanding_ == kHomomorphism ? "" : " of derivation step " + std::to_string(step_)) +
                     " applied more than " + std::to_string(kModulesBegunPerModule) + " x lsystem.max_modules = " +
                     std::to_string(kModulesBegunPerModule * settings_.max_modules) +
                     " rules and modules (its rules recurse too far: lower its 'maximum depth:', or raise "
                     "lsystem.max_modules)");
  }

  // '%' removes itself and the rest of its branch (up to, not including, the closing ']').
  static void cut_branches(ModuleString* word) {
    ModuleString out;
    out.clear();
    for (size_t i = 0; i < word->size(); ++i) {
      if (word->symbols[i] != '%') {
        copy_module(*word, i, &out);
        continue;
      }
      int depth = 0;
      size_t j = i + 1;
      for (; j < word->size(); ++j) {
        if (word->symbols[j] == '[') ++depth;
        else if (word->symbols[j] == ']' && depth-- == 0) break;
      }
      i = j - 1;  // the loop's ++i lands on the ']' (kept) or the end
    }
    *word = std::move(out);
  }

  const Grammar& g_;
  const DerivationSettings& settings_;
  const TurtleSettings turtle_;         // answers the query modules
  int step_ = 0;
  Purpose expanding_ = kDecomposition;  // the section expand_all applies
  size_t modules_begun_ = 0;            // by expand_all's pass so far (kModulesBegunPerModule)
  const Rule* rule_ = nullptr;          // the rule being evaluated, for error messages
  const ModuleString* word_ = nullptr;  // the word being rewritten (contexts)
  bool derived_ = false;                // the module being expanded comes from a successor: its contexts are its origin's
  size_t origin_end_ = 0;               // past the modules of word_ the expansion started from
  const Lsystem* ls_ = nullptr;         // the L-system rewriting the current module (its contexts' skips, ring)
  std::vector<uint32_t> calls_;         // indices of the L-systems called at the current module, innermost last
  std::vector<int32_t> match_;          // (n) bracket partners of word_, -1 elsewhere
  std::vector<std::pair<const std::array<bool, 256>*, std::vector<int32_t>>> left_stops_;   // per skip table
  std::vector<std::pair<const std::array<bool, 256>*, std::vector<int32_t>>> right_stops_;  // per skip table
  std::vector<double> weights_;         // stochastic candidates' weights
  std::vector<const Rule*> chosen_;     // stochastic candidates
  std::vector<double> scratch_;         // parameter values of the module being expanded
  std::vector<double> params_;          // the same, while its own rule is selected
  std::vector<Frame> frames_;           // rules being expanded, innermost last
  std::vector<double> frame_slots_;     // their bound formals and locals
  std::vector<double> frame_params_;    // their successors' parameters, where evaluated when applied (Frame::params)
  Ahead ahead_;                         // the successor modules after the one being begun
  std::vector<double> chosen_slots_;    // (candidates x kMaxSlots) slots of stochastic candidates
  std::vector<double> variables_;       // global variables; [0] the last srand() argument
  std::vector<uint32_t> drawn_at_;      // where each module's homomorphism starts (query pass)
};

}  // namespace

ModuleString derive(const Grammar& grammar, const DerivationSettings& settings, const TurtleSettings& turtle,
                    std::vector<double>* variables, const DerivationStepped& stepped) {
  Deriver deriver(grammar, settings, turtle);
  try {
    ModuleString word = deriver.derive(stepped);
    if (variables) *variables = deriver.variables();
    return word;
  } catch (const EvalError& error) {
    deriver.rethrow(error);
  }
}

ModuleString apply_homomorphism(const Grammar& grammar, const ModuleString& word,
                                const DerivationSettings& settings, const std::vector<double>* variables) {
  Deriver deriver(grammar, settings);
  if (variables) deriver.variables() = *variables;
  try {
    return deriver.homomorphism(word);
  } catch (const EvalError& error) {
    deriver.rethrow(error);
  }
}

}  // namespace treeanim
