// Grammar text => Grammar (docs/grammar.md). One line at a time: a directive, a #define, or a
// production of the current section (productions, decomposition, homomorphism).
#include <algorithm>
#include <cctype>
#include <cmath>

#include "common/errors.h"
#include "common/did_you_mean.h"
#include "lsystem/grammar.h"

namespace treeanim {

namespace {

constexpr size_t kNone = std::string_view::npos;
constexpr int kMaxSlots = 64;   // formal parameters of one rule (lc, pred, rc)
constexpr int kMaxDepth = 64;   // "maximum depth:" bound (recursion of decomposition/homomorphism)

bool is_space(char c) { return c == ' ' || c == '\t'; }

enum class Section { kProductions, kDecomposition, kHomomorphism };

// Directives that end with ':' and take a value, and section headers that take none.
const std::vector<std::string> kValueDirectives = {
    "axiom", "derivation length", "angle", "seed", "ignore", "consider",
    "tropism", "maximum depth", "width factor", "lsystem"};
const std::vector<std::string> kSectionDirectives = {"homomorphism", "decomposition", "endlsystem"};

std::string expected_directives() {
  std::string out;
  for (const std::string& d : kValueDirectives) out += d + ":, ";
  for (const std::string& d : kSectionDirectives) out += d + ", ";
  return out + "#define";
}

// Index of the first `c` at parenthesis depth 0 in text[begin, end), or kNone.
size_t find_top_level(std::string_view text, size_t begin, size_t end, char c) {
  int depth = 0;
  for (size_t k = begin; k < end; ++k) {
    if (text[k] == '(') ++depth;
    else if (text[k] == ')') --depth;
    else if (depth == 0 && text[k] == c) return k;
  }
  return kNone;
}

size_t find_last_top_level(std::string_view text, size_t begin, size_t end, char c) {
  size_t found = kNone;
  int depth = 0;
  for (size_t k = begin; k < end; ++k) {
    if (text[k] == '(') ++depth;
    else if (text[k] == ')') --depth;
    else if (depth == 0 && text[k] == c) found = k;
  }
  return found;
}

// [begin, end) without surrounding spaces.
void trim(std::string_view text, size_t* begin, size_t* end) {
  while (*begin < *end && is_space(text[*begin])) ++*begin;
  while (*end > *begin && is_space(text[*end - 1])) --*end;
}

class Parser {
 public:
  Parser(Grammar& grammar, const std::vector<std::pair<std::string, double>>& overrides)
      : g_(grammar), overrides_(overrides) {
    g_.defines = overrides;
  }

  // One grammar text, line by line.
  void parse_text(const GrammarText& text) {
    const int32_t source = add_source(text.name);
    if (source == 0) first_pos_ = {source, text.single_line ? 0 : 1, 1};
    std::string_view all(text.text);
    int32_t line = 1;
    size_t start = 0;
    while (start <= all.size() && !ended_) {
      size_t stop = all.find('\n', start);
      if (stop == kNone) stop = all.size();
      std::string_view content = all.substr(start, stop - start);
      if (!content.empty() && content.back() == '\r') content.remove_suffix(1);
      parse_line(content, {source, text.single_line ? 0 : line, 0});
      if (stop == all.size()) break;
      start = stop + 1;
      ++line;
    }
  }

  // An inline axiom (the whole text is the axiom's modules).
  void parse_inline_axiom(const GrammarText& text) {
    const SourcePos at{add_source(text.name), 0, 0};
    set_axiom(text.text, 0, text.text.size(), at, at_column(at, 0));
  }

  // Checks what needs the whole grammar, then indexes the rules.
  void finish() {
    if (!axiom_seen_) throw GrammarError{first_pos_, "expected an 'axiom:' line; the grammar has none"};
    for (RuleSet* set : {&g_.productions, &g_.decomposition, &g_.homomorphism}) set->index();
    check_arities(g_.axiom);
    for (RuleSet* set : {&g_.productions, &g_.decomposition, &g_.homomorphism})
      check_arities(set->successor);
  }

 private:
  int32_t add_source(const std::string& name) {
    g_.sources.push_back(name);
    return static_cast<int32_t>(g_.sources.size() - 1);
  }
  static SourcePos at_column(SourcePos line, size_t index) {
    return {line.source, line.line, static_cast<int32_t>(index) + 1};
  }
  [[noreturn]] static void fail(SourcePos line, size_t index, const std::string& message) {
    throw GrammarError{at_column(line, index), message};
  }
  RuleSet& current() {
    switch (section_) {
      case Section::kDecomposition: return g_.decomposition;
      case Section::kHomomorphism: return g_.homomorphism;
      case Section::kProductions: break;
    }
    return g_.productions;
  }

  void parse_line(std::string_view text, SourcePos line) {
    size_t end = strip_comment(text, line);
    size_t begin = 0;
    trim(text, &begin, &end);
    if (begin == end) return;
    if (text.substr(begin, 7) == "#define" && (begin + 7 == end || is_space(text[begin + 7])))
      return parse_define(text, begin + 7, end, line);
    if (parse_directive(text, begin, end, line)) return;
    const size_t arrow = find_arrow(text, begin, end);
    if (arrow != kNone) return parse_rule(text, begin, arrow, end, line);
    report_non_rule(text, begin, end, line);
  }

  // '#' starts a comment at the line's start or after a space; returns where the content ends.
  static size_t strip_comment(std::string_view text, SourcePos line) {
    for (size_t k = 0; k < text.size(); ++k) {
      if (text[k] != '#' || (k > 0 && !is_space(text[k - 1]))) continue;
      if (text.substr(k, 7) == "#define" && text.find_first_not_of(" \t") == k) continue;
      for (const char* unsupported : {"#include", "#ifdef", "#ifndef", "#if", "#else", "#endif", "#undef"}) {
        const std::string_view word(unsupported);
        if (text.substr(k, word.size()) == word &&
            (k + word.size() == text.size() || !std::isalpha(static_cast<unsigned char>(text[k + word.size()]))))
          fail(line, k, "unsupported preprocessor directive '" + std::string(word) +
                            "' (only #define is supported; '# ' starts a comment)");
      }
      return k;
    }
    return text.size();
  }

  // Start of "-->" or "->" (the first '>' right after a '-'), kNone when there is none.
  static size_t find_arrow(std::string_view text, size_t begin, size_t end) {
    for (size_t k = begin + 1; k < end; ++k)
      if (text[k] == '>' && text[k - 1] == '-') return (k >= begin + 2 && text[k - 2] == '-') ? k - 2 : k - 1;
    return kNone;
  }

  // A line that is neither a directive nor a production: say which it looks like.
  [[noreturn]] void report_non_rule(std::string_view text, size_t begin, size_t end, SourcePos line) {
    const size_t colon = text.find(':', begin);
    if (colon != kNone && colon < end) {
      size_t word_end = colon;
      while (word_end > begin && is_space(text[word_end - 1])) --word_end;
      const std::string_view word = text.substr(begin, word_end - begin);
      const bool wordy = word.size() >= 2 && std::all_of(word.begin(), word.end(), [](char c) {
        return std::isalpha(static_cast<unsigned char>(c)) || c == ' ';
      });
      if (wordy) {
        std::vector<std::string> known = kValueDirectives;
        const std::string near = closest_match(std::string(word), known);
        fail(line, begin, "unknown directive '" + std::string(word) + ":' (expected one of " +
                              expected_directives() +
                              (near.empty() ? "" : "; did you mean '" + near + ":'?") + ")");
      }
    }
    fail(line, begin, "expected a directive or a production 'predecessor --> successor', got '" +
                          std::string(text.substr(begin, end - begin)) + "'");
  }

  // "name:" or "name :" at text[begin]; on a match, *value is just after the colon.
  static bool match_keyword(std::string_view text, size_t begin, size_t end,
                            const std::string& keyword, bool colon, size_t* value) {
    if (text.substr(begin, keyword.size()) != keyword) return false;
    size_t k = begin + keyword.size();
    if (k < end && (std::isalnum(static_cast<unsigned char>(text[k])) || text[k] == '_')) return false;
    if (!colon) {
      *value = k;
      return true;
    }
    while (k < end && is_space(text[k])) ++k;
    if (k >= end || text[k] != ':') return false;
    *value = k + 1;
    return true;
  }

  bool parse_directive(std::string_view text, size_t begin, size_t end, SourcePos line) {
    size_t value = 0;
    for (const std::string& keyword : kSectionDirectives) {
      if (!match_keyword(text, begin, end, keyword, false, &value)) continue;
      size_t rest = value;
      if (rest < end && text[rest] == ':') ++rest;
      while (rest < end && is_space(text[rest])) ++rest;
      if (rest < end) fail(line, rest, "expected nothing after '" + keyword + "'");
      if (keyword == "homomorphism") section_ = Section::kHomomorphism;
      else if (keyword == "decomposition") section_ = Section::kDecomposition;
      else ended_ = true;
      return true;
    }
    for (const std::string& keyword : kValueDirectives) {
      if (!match_keyword(text, begin, end, keyword, true, &value)) continue;
      size_t vbegin = value, vend = end;
      trim(text, &vbegin, &vend);
      if (vbegin == vend && keyword != "ignore" && keyword != "consider")
        fail(line, value, "expected a value after '" + keyword + ":'");
      if (keyword == "axiom") set_axiom(text, vbegin, vend, line, at_column(line, begin));
      else if (keyword == "derivation length") g_.derivation_length = integer_value(text, vbegin, vend, line, 0, 100000);
      else if (keyword == "angle") g_.angle = constant_value(text, vbegin, vend, line);
      else if (keyword == "width factor") g_.width_factor = constant_value(text, vbegin, vend, line);
      else if (keyword == "seed") g_.seed = static_cast<uint64_t>(integer_value(text, vbegin, vend, line, 0, 1LL << 53));
      else if (keyword == "lsystem") integer_value(text, vbegin, vend, line, 0, 1LL << 31);
      else if (keyword == "maximum depth") current().max_depth = static_cast<int>(integer_value(text, vbegin, vend, line, 1, kMaxDepth));
      else if (keyword == "tropism") parse_tropism(text, vbegin, vend, line);
      else parse_skips(text, vbegin, vend, line, keyword == "consider", begin);
      return true;
    }
    return false;
  }

  // A constant expression filling text[begin, end).
  double constant_value(std::string_view text, size_t begin, size_t end, SourcePos line) {
    const ExprScope scope{nullptr, &g_.defines};
    size_t pos = begin;
    const Expr expr = compile_expression(g_.program, text.substr(0, end), &pos, line, scope);
    if (pos != end) fail(line, pos, "expected the end of the value, got '" + std::string(1, text[pos]) + "'");
    double value = 0;
    if (!g_.program.is_constant(expr, &value))
      fail(line, begin, "expected a constant value (no ran() or nran())");
    return value;
  }

  long long integer_value(std::string_view text, size_t begin, size_t end, SourcePos line,
                          long long lo, long long hi) {
    const double v = constant_value(text, begin, end, line);
    if (std::floor(v) != v || v < double(lo) || v > double(hi))
      fail(line, begin, "expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                            "], got " + std::string(text.substr(begin, end - begin)));
    return static_cast<long long>(v);
  }

  // "tropism: Tx Ty Tz e" (spaces or commas between the four values).
  void parse_tropism(std::string_view text, size_t begin, size_t end, SourcePos line) {
    double values[4];
    size_t k = begin;
    for (int i = 0; i < 4; ++i) {
      while (k < end && (is_space(text[k]) || text[k] == ',')) ++k;
      if (k >= end) fail(line, k, "expected 4 values 'Tx Ty Tz e' after 'tropism:', got " + std::to_string(i));
      size_t stop = k;
      while (stop < end && !is_space(text[stop]) && text[stop] != ',') ++stop;
      values[i] = constant_value(text, k, stop, line);
      k = stop;
    }
    while (k < end && (is_space(text[k]) || text[k] == ',')) ++k;
    if (k < end) fail(line, k, "expected 4 values 'Tx Ty Tz e' after 'tropism:', got more");
    const Eigen::Vector3d t(values[0], values[1], values[2]);
    if (t.norm() == 0.0) fail(line, begin, "expected a non-zero tropism direction");
    g_.tropism = t;
    g_.tropism_elasticity = values[3];
  }

  // "ignore: symbols" or "consider: symbols".
  void parse_skips(std::string_view text, size_t begin, size_t end, SourcePos line, bool consider,
                   size_t directive) {
    if (skips_kind_ != 0 && skips_kind_ != (consider ? 2 : 1))
      fail(line, directive, "'ignore:' and 'consider:' cannot both be given");
    if (skips_kind_ == 0 && consider) g_.context_skips.fill(true);
    skips_kind_ = consider ? 2 : 1;
    for (size_t k = begin; k < end; ++k) {
      const char c = text[k];
      if (is_space(c)) continue;
      if (c == '[' || c == ']') fail(line, k, "brackets cannot be listed: context matching always follows them");
      if (!std::isgraph(static_cast<unsigned char>(c))) fail(line, k, "expected module symbols (printable ASCII)");
      g_.context_skips[static_cast<unsigned char>(c)] = !consider;
    }
  }

  void parse_define(std::string_view text, size_t begin, size_t end, SourcePos line) {
    size_t k = begin;
    while (k < end && is_space(text[k])) ++k;
    const size_t name_begin = k;
    if (k < end && (std::isalpha(static_cast<unsigned char>(text[k])) || text[k] == '_'))
      while (k < end && (std::isalnum(static_cast<unsigned char>(text[k])) || text[k] == '_')) ++k;
    if (k == name_begin) fail(line, name_begin, "expected a name after '#define'");
    const std::string name(text.substr(name_begin, k - name_begin));
    while (k < end && is_space(text[k])) ++k;
    if (k == end) fail(line, k, "expected a value after '#define " + name + "'");
    if (std::find(g_.file_defines.begin(), g_.file_defines.end(), name) != g_.file_defines.end())
      fail(line, name_begin, "'" + name + "' is already defined");
    g_.file_defines.push_back(name);
    for (const auto& entry : overrides_)
      if (entry.first == name) return;  // the scene's value wins
    const double value = constant_value(text, k, end, line);
    g_.defines.emplace_back(name, value);
  }

  void set_axiom(std::string_view text, size_t begin, size_t end, SourcePos line, SourcePos directive) {
    if (axiom_seen_) throw GrammarError{directive, "a second 'axiom:'; the grammar has one already"};
    axiom_seen_ = true;
    const std::vector<std::string> no_formals;
    parse_word(text, begin, end, line, ExprScope{&no_formals, &g_.defines}, &g_.axiom, &g_.axiom_params, "axiom");
    if (g_.axiom.empty()) fail(line, begin, "expected at least one module in the axiom");
  }

  // Modules with actual parameters in text[begin, end) => appended to modules/params.
  // Brackets must balance within the word.
  void parse_word(std::string_view text, size_t begin, size_t end, SourcePos line, const ExprScope& scope,
                  std::vector<SuccessorModule>* modules, std::vector<Expr>* params, const char* what) {
    std::vector<size_t> open;  // positions of unclosed '['
    const std::string_view word = text.substr(0, end);
    for (size_t k = begin; k < end;) {
      const char c = text[k];
      if (is_space(c)) { ++k; continue; }
      check_symbol(text, k, line, what);
      if (c == '[') open.push_back(k);
      if (c == ']') {
        if (open.empty()) fail(line, k, "unbalanced brackets: ']' closes no '[' in the " + std::string(what));
        open.pop_back();
      }
      SuccessorModule module{c, 0, static_cast<uint32_t>(params->size()), at_column(line, k)};
      ++k;
      if (k < end && text[k] == '(') {
        if (c == '[' || c == ']') fail(line, k, "brackets take no parameters");
        for (;;) {
          ++k;
          params->push_back(compile_expression(g_.program, word, &k, line, scope));
          if (module.arity == 255) fail(line, k, "more than 255 parameters in one module");
          ++module.arity;
          while (k < end && is_space(text[k])) ++k;
          if (k < end && text[k] == ')') { ++k; break; }
          if (k < end && text[k] == ',') continue;
          std::string got = "the end of the ";
          got += what;
          if (k < end) got = {'\'', text[k], '\''};
          std::string message = "expected ',' or ')' after a parameter of '";
          message += c;
          fail(line, k, message + "', got " + got);
        }
      }
      modules->push_back(module);
    }
    if (!open.empty())
      fail(line, open.back(), "unbalanced brackets: '[' is never closed (expected ']' before the end of the " +
                                  std::string(what) + ")");
  }

  static void check_symbol(std::string_view text, size_t k, SourcePos line, const char* what) {
    const char c = text[k];
    if (c == '(' || c == ')') fail(line, k, std::string("expected a module symbol, got '") + c + "'");
    if (c == '*') {
      std::string message = "'*' is not a module; alone it stands for an empty ";
      message += std::string_view(what) == "axiom" ? "successor" : what;
      fail(line, k, message);
    }
    if (c == ':' || c == '<' || c == '>')
      fail(line, k, std::string("expected a module symbol, got '") + c + "'");
    if (!std::isgraph(static_cast<unsigned char>(c)))
      fail(line, k, "expected a module symbol (one printable ASCII character)");
  }

  // [lc <] pred [> rc] [: cond] --> succ [: prob]
  void parse_rule(std::string_view text, size_t begin, size_t arrow, size_t end, SourcePos line) {
    RuleSet& set = current();
    const size_t arrow_end = text[arrow + 1] == '-' ? arrow + 3 : arrow + 2;
    Rule rule;
    rule.pos = at_column(line, begin);
    std::vector<std::string> formals;

    size_t head_end = arrow;
    const size_t cond = find_top_level(text, begin, arrow, ':');
    if (cond != kNone) head_end = cond;
    size_t lt = find_top_level(text, begin, head_end, '<');
    size_t gt = find_top_level(text, begin, head_end, '>');
    if (lt != kNone && find_top_level(text, lt + 1, head_end, '<') != kNone)
      fail(line, find_top_level(text, lt + 1, head_end, '<'), "expected one '<' before the predecessor");
    if (gt != kNone && find_top_level(text, gt + 1, head_end, '>') != kNone)
      fail(line, find_top_level(text, gt + 1, head_end, '>'), "expected one '>' after the predecessor");
    if (lt != kNone && gt != kNone && gt < lt) fail(line, gt, "expected '<' (left context) before '>' (right context)");
    const bool contexts_allowed = section_ == Section::kProductions;
    if (!contexts_allowed && (lt != kNone || gt != kNone))
      fail(line, lt != kNone ? lt : gt, "contexts are only allowed in productions, not in decomposition or homomorphism rules");

    const size_t pred_begin = lt == kNone ? begin : lt + 1;
    const size_t pred_end = gt == kNone ? head_end : gt;
    if (lt != kNone) {
      rule.left_begin = static_cast<uint32_t>(set.patterns.size());
      parse_pattern(text, begin, lt, line, false, &set, &formals, "left context");
      rule.left_end = static_cast<uint32_t>(set.patterns.size());
    }
    parse_predecessor(text, pred_begin, pred_end, line, &rule, &formals);
    if (gt != kNone) {
      rule.right_begin = static_cast<uint32_t>(set.patterns.size());
      parse_pattern(text, gt + 1, head_end, line, true, &set, &formals, "right context");
      rule.right_end = static_cast<uint32_t>(set.patterns.size());
    }
    rule.slot_count = static_cast<uint16_t>(formals.size());
    const ExprScope scope{&formals, &g_.defines};
    if (cond != kNone) rule.condition = optional_expression(text, cond + 1, arrow, line, scope, "condition");

    size_t succ_end = end;
    const size_t prob = find_last_top_level(text, arrow_end, end, ':');
    if (prob != kNone) {
      rule.probability = optional_expression(text, prob + 1, end, line, scope, "probability");
      succ_end = prob;
    }
    size_t sb = arrow_end, se = succ_end;
    trim(text, &sb, &se);
    if (sb == se) fail(line, arrow_end, "expected a successor after the arrow (write '*' for an empty successor)");
    rule.successor_begin = static_cast<uint32_t>(set.successor.size());
    if (!(se == sb + 1 && text[sb] == '*'))
      parse_word(text, sb, se, line, scope, &set.successor, &set.successor_params, "successor");
    rule.successor_end = static_cast<uint32_t>(set.successor.size());
    for (uint32_t m = rule.successor_begin; m < rule.successor_end; ++m)
      if (set.successor[m].symbol == '%') set.any_cut = true;
    if (rule.has_context()) set.any_context = true;
    set.rules.push_back(rule);
  }

  // An expression filling text[begin, end), or none when it is '*'.
  Expr optional_expression(std::string_view text, size_t begin, size_t end, SourcePos line,
                           const ExprScope& scope, const char* what) {
    trim(text, &begin, &end);
    if (begin == end) fail(line, begin, std::string("expected a ") + what + " after ':'");
    if (end == begin + 1 && text[begin] == '*') return {};
    size_t pos = begin;
    const Expr expr = compile_expression(g_.program, text.substr(0, end), &pos, line, scope);
    if (pos != end)
      fail(line, pos, std::string("expected the end of the ") + what + ", got '" + std::string(1, text[pos]) + "'");
    return expr;
  }

  void parse_predecessor(std::string_view text, size_t begin, size_t end, SourcePos line, Rule* rule,
                         std::vector<std::string>* formals) {
    trim(text, &begin, &end);
    if (begin == end) fail(line, begin, "expected a predecessor module before the arrow");
    check_symbol(text, begin, line, "predecessor");
    if (text[begin] == '[' || text[begin] == ']') fail(line, begin, "a bracket cannot be a predecessor");
    rule->predecessor = text[begin];
    rule->predecessor_slot = static_cast<uint16_t>(formals->size());
    size_t k = begin + 1;
    rule->arity = static_cast<uint8_t>(parse_formals(text, &k, end, line, formals));
    while (k < end && is_space(text[k])) ++k;
    if (k < end)
      fail(line, k, "expected one module as predecessor (write a context with '<' or '>'), got '" +
                        std::string(text.substr(begin, end - begin)) + "'");
  }

  // Context modules with formal parameters in text[begin, end); '*' alone = no context.
  void parse_pattern(std::string_view text, size_t begin, size_t end, SourcePos line, bool brackets,
                     RuleSet* set, std::vector<std::string>* formals, const char* what) {
    trim(text, &begin, &end);
    if (begin == end) fail(line, begin, std::string("expected a ") + what + " (or '*' for none)");
    if (end == begin + 1 && text[begin] == '*') return;
    for (size_t k = begin; k < end;) {
      const char c = text[k];
      if (is_space(c)) { ++k; continue; }
      check_symbol(text, k, line, what);
      if (!brackets && (c == '[' || c == ']'))
        fail(line, k, "brackets are not supported in a left context (it already skips branches)");
      PatternModule module{c, 0, static_cast<uint16_t>(formals->size())};
      ++k;
      module.arity = static_cast<uint8_t>(parse_formals(text, &k, end, line, formals));
      if ((c == '[' || c == ']') && module.arity) fail(line, k - 1, "brackets take no parameters");
      set->patterns.push_back(module);
    }
  }

  // "(a, b)" at text[*k] => names appended to formals; returns their count.
  int parse_formals(std::string_view text, size_t* k, size_t end, SourcePos line, std::vector<std::string>* formals) {
    if (*k >= end || text[*k] != '(') return 0;
    int count = 0;
    for (;;) {
      ++*k;
      while (*k < end && is_space(text[*k])) ++*k;
      const size_t name_begin = *k;
      if (*k < end && (std::isalpha(static_cast<unsigned char>(text[*k])) || text[*k] == '_'))
        while (*k < end && (std::isalnum(static_cast<unsigned char>(text[*k])) || text[*k] == '_')) ++*k;
      if (*k == name_begin)
        fail(line, name_begin, "expected a formal parameter name (predecessors and contexts take names, not expressions)");
      const std::string name(text.substr(name_begin, *k - name_begin));
      if (std::find(formals->begin(), formals->end(), name) != formals->end())
        fail(line, name_begin, "formal parameter '" + name + "' appears twice in the rule");
      formals->push_back(name);
      if (formals->size() > kMaxSlots) fail(line, name_begin, "more than 64 formal parameters in one rule");
      ++count;
      while (*k < end && is_space(text[*k])) ++*k;
      if (*k < end && text[*k] == ')') { ++*k; return count; }
      if (*k < end && text[*k] == ',') continue;
      fail(line, *k, "expected ',' or ')' after formal parameter '" + name + "'");
    }
  }

  // A module written with an arity that no rule for its symbol takes would never be rewritten
  // (ABOP matches symbol and parameter count): almost always a typo, so it is an error.
  void check_arities(const std::vector<SuccessorModule>& modules) const {
    for (const SuccessorModule& m : modules) {
      const Rule* example = nullptr;
      bool matched = false;
      for (const RuleSet* set : {&g_.productions, &g_.decomposition, &g_.homomorphism}) {
        const auto s = static_cast<unsigned char>(m.symbol);
        for (uint32_t i = set->first_rule[s]; i < set->first_rule[s + 1]; ++i) {
          const Rule& r = set->rules[set->rule_order[i]];
          example = &r;
          if (r.arity == m.arity) matched = true;
        }
      }
      if (example && !matched)
        throw GrammarError{m.pos, std::string("wrong number of arguments: '") + m.symbol + "' has " +
                                      std::to_string(m.arity) + " here, but its rule at " +
                                      std::to_string(example->pos.line) + ":" + std::to_string(example->pos.column) +
                                      " expects " + std::to_string(example->arity)};
    }
  }

  Grammar& g_;
  const std::vector<std::pair<std::string, double>>& overrides_;
  Section section_ = Section::kProductions;
  int skips_kind_ = 0;  // 0 none, 1 ignore:, 2 consider:
  bool axiom_seen_ = false;
  bool ended_ = false;  // after "endlsystem"
  SourcePos first_pos_;  // the first text's start, for errors about what is missing
};

}  // namespace

void RuleSet::index() {
  std::array<uint32_t, 256> count{};
  for (const Rule& r : rules) ++count[static_cast<unsigned char>(r.predecessor)];
  first_rule[0] = 0;
  for (int s = 0; s < 256; ++s) first_rule[s + 1] = first_rule[s] + count[s];
  rule_order.assign(rules.size(), 0);
  std::array<uint32_t, 256> next{};
  for (int s = 0; s < 256; ++s) next[s] = first_rule[s];
  for (uint32_t r = 0; r < rules.size(); ++r) rule_order[next[static_cast<unsigned char>(rules[r].predecessor)]++] = r;
}

std::string Grammar::where(const SourcePos& pos) const {
  const std::string& name = sources.at(static_cast<size_t>(pos.source));
  if (pos.line == 0) return name + ":" + std::to_string(pos.column);
  return name + ":" + std::to_string(pos.line) + ":" + std::to_string(pos.column);
}

Grammar parse_grammar(const std::vector<GrammarText>& texts,
                      const std::vector<std::pair<std::string, double>>& define_overrides,
                      const std::optional<GrammarText>& axiom_text) {
  Grammar grammar;
  Parser parser(grammar, define_overrides);
  try {
    if (axiom_text) parser.parse_inline_axiom(*axiom_text);
    for (const GrammarText& text : texts) parser.parse_text(text);
    parser.finish();
  } catch (const GrammarError& error) {
    throw InputError(grammar.where(error.pos) + ": " + error.message);
  }
  return grammar;
}

}  // namespace treeanim
