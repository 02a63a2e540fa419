// Grammar text => Grammar (docs/grammar.md). One line at a time: a directive, a #define, or a
// production of the current section (productions, decomposition, homomorphism).
#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <functional>
#include <optional>
#include <sstream>

#include "common/errors.h"
#include "common/did_you_mean.h"
#include "common/direction.h"
#include "common/message_text.h"
#include "common/read_text_file.h"
#include "lsystem/grammar.h"
#include "lsystem/lsystem_options.h"
#include "lsystem/preprocess.h"

namespace treeanim {

namespace {

constexpr size_t kNone = std::string_view::npos;
constexpr int kMaxSlots = 64;   // formal parameters of one rule (lc, pred, rc)
constexpr int kMaxDepth = 100'000;  // "maximum depth:" bound (the expansion keeps its own stack)
constexpr long long kMaxArrayElements = 1'000'000;  // elements of all cpfg arrays together

bool is_space(char c) { return c == ' ' || c == '\t'; }

// Whether a #define body is one operand (signs, then a number, a name, a call or a
// parenthesised expression): cpp pastes the body as text, so only such a body means the same as
// its value wherever it stands; "2+3" pasted into "N*2" makes 2+3*2.
bool single_operand(std::string_view text) {
  size_t k = 0;
  auto skip = [&] { while (k < text.size() && is_space(text[k])) ++k; };
  auto close_group = [&] {  // text[k] == '(' => past its matching ')'
    for (int depth = 0; k < text.size(); ++k)
      if (text[k] == '(') ++depth;
      else if (text[k] == ')' && --depth == 0) return ++k, true;
    return false;
  };
  for (skip(); k < text.size() && (text[k] == '-' || text[k] == '+'); skip()) ++k;
  if (k == text.size()) return false;
  const auto c = static_cast<unsigned char>(text[k]);
  if (std::isdigit(c) || c == '.') {
    while (k < text.size() && (std::isdigit(static_cast<unsigned char>(text[k])) || text[k] == '.')) ++k;
    if (k < text.size() && (text[k] == 'e' || text[k] == 'E')) {
      ++k;
      if (k < text.size() && (text[k] == '-' || text[k] == '+')) ++k;
      while (k < text.size() && std::isdigit(static_cast<unsigned char>(text[k]))) ++k;
    }
  } else if (std::isalpha(c) || c == '_') {
    while (k < text.size() && (std::isalnum(static_cast<unsigned char>(text[k])) || text[k] == '_')) ++k;
    skip();
    if (k < text.size() && text[k] == '(' && !close_group()) return false;
  } else if (c != '(' || !close_group()) {
    return false;
  }
  skip();
  return k == text.size();
}

enum class Section { kProductions, kDecomposition, kHomomorphism };

// Directives that end with ':' and take a value, and section headers that take none.
// Matched without regard to case (cpfg writes "Axiom:", "Lsystem:"...).
const std::vector<std::string> kValueDirectives = {
    "axiom", "derivation length", "angle", "seed", "ignore", "consider",
    "tropism", "maximum depth", "width factor", "lsystem", "start", "starteach", "end", "endeach",
    "define"};
const std::vector<std::string> kSectionDirectives = {"homomorphism", "decomposition", "endlsystem", "ring lsystem"};

bool same_letters(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
         });
}

std::string expected_directives() {
  std::string out;
  for (const std::string& d : kValueDirectives) out += d + ":, ";
  for (const std::string& d : kSectionDirectives) out += d + ", ";
  return out + "#define";
}

// Index of the first `c` at parenthesis (and brace: statement blocks of a rule's head) depth 0
// in text[begin, end), or kNone.
size_t find_top_level(std::string_view text, size_t begin, size_t end, char c) {
  int depth = 0;
  for (size_t k = begin; k < end; ++k) {
    if (text[k] == '(' || text[k] == '{') ++depth;
    else if (text[k] == ')' || text[k] == '}') --depth;
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

  // One grammar text: preprocessed (comments, #define, #include), then one statement at a
  // time; a statement continues over lines while parentheses or a block's braces are open, and
  // a rule's successor or the axiom continues on lines that start no other statement.
  void parse_text(const GrammarText& text) {
    if (!preprocessor_) preprocessor_.emplace(hooks());
    if (g_.sources.empty()) first_pos_ = {0, text.single_line ? 0 : 1, 1};
    preprocessor_->run(text.name, text.text, text.single_line);
    flush();
  }

  // What the preprocessor hands the parser, and asks of it.
  PreprocessHooks hooks() {
    PreprocessHooks hooks;
    hooks.add_source = [this](const std::string& name) { return add_source(name); };
    hooks.include = [this](const std::string& path, const std::string& from, SourcePos at) {
      return read_include(path, from, at);
    };
    hooks.define_number = [this](const std::string& name, const SourceLine& body, SourcePos at) {
      return define_number(name, body, at);
    };
    hooks.define_macro = [this](const std::string& name) { g_.file_macros.push_back(name); };
    hooks.is_number = [this](const std::string& name) {
      return std::any_of(g_.defines.begin(), g_.defines.end(), [&](const auto& d) { return d.first == name; });
    };
    hooks.line = [this](const SourceLine& line) { feed(line); };
    return hooks;
  }

  // An inline axiom (the whole text is the axiom's modules).
  void parse_inline_axiom(const GrammarText& text) {
    const SourcePos at{add_source(text.name), 0, 0};
    set_axiom(text.text, 0, text.text.size(), at, at_column(at, 0));
  }

  // Checks what needs the whole grammar, then indexes the rules.
  void finish() {
    if (preprocessor_) preprocessor_->finish();
    if (!axiom_seen_) throw GrammarError{first_pos_, "expected an 'axiom:' line; the grammar has none"};
    for (Lsystem& ls : g_.lsystems) {
      for (RuleSet* set : {&ls.productions, &ls.decomposition, &ls.homomorphism}) {
        set->index();
        check_calls(set->successor, set->successor_params);
      }
    }
    check_calls(g_.axiom, g_.axiom_params);
  }

  // Every call '?(label, s)' whose label is a constant names an L-system of the file.
  void check_calls(const std::vector<SuccessorModule>& modules, const std::vector<Expr>& params) const {
    if (!g_.calls) return;
    for (const SuccessorModule& m : modules) {
      double label = 0;
      if (m.symbol != '?' || m.arity == 0 || !g_.program.is_constant(params[m.first_param], &label) ||
          g_.lsystem_index(label) >= 0)
        continue;
      std::string labels;
      for (const Lsystem& ls : g_.lsystems) labels += (labels.empty() ? "" : ", ") + std::to_string(ls.label);
      std::ostringstream value;
      value << label;
      throw GrammarError{m.pos, "'?(" + value.str() + ", ...)' calls L-system " + value.str() +
                                    ", but the file has no 'lsystem: " + value.str() + "' (it has " + labels + ")"};
    }
  }

 private:
  int32_t add_source(const std::string& name) {
    g_.sources.push_back(name);
    return static_cast<int32_t>(g_.sources.size() - 1);
  }
  static SourcePos at_column(const TextOrigin& line, size_t index) { return line.at(index); }
  [[noreturn]] static void fail(const TextOrigin& line, size_t index, const std::string& message) {
    throw GrammarError{at_column(line, index), message};
  }
  // The L-system being read (the last "lsystem:") and its section.
  Lsystem& lsystem() { return g_.lsystems.back(); }
  bool in_sub_lsystem() const { return g_.lsystems.size() > 1; }
  RuleSet& current() {
    switch (section_) {
      case Section::kDecomposition: return lsystem().decomposition;
      case Section::kHomomorphism: return lsystem().homomorphism;
      case Section::kProductions: break;
    }
    return lsystem().productions;
  }

  // A file #included by `from`, found beside it.
  std::pair<std::string, std::string> read_include(const std::string& path, const std::string& from, SourcePos at) {
    const std::filesystem::path resolved = std::filesystem::path(from).parent_path() / path;
    std::string text, reason;
    if (!read_text_file(resolved, text, reason))
      throw GrammarError{at, "cannot read the included file '" + resolved.string() + "' (" + reason + ")"};
    return {resolved.string(), text};
  }

  // fopen's reader (CPFG manual 5.4): a file beside the grammar file that names it, by a
  // relative path that stays in that folder.
  std::function<std::string(const std::string&, SourcePos)> data_files() {
    return [this](const std::string& name, SourcePos at) {
      const std::filesystem::path path(name);
      if (at.line == 0)
        throw GrammarError{at, "fopen reads a file beside the grammar file; an inline grammar has none"};
      if (!names_a_file_beside(path))
        throw GrammarError{at, "fopen(\"" + name + "\") names a file outside the grammar's folder: a grammar reads only "
                               "files beside it (a relative path without '..')"};
      const std::filesystem::path resolved = std::filesystem::path(g_.sources.at(static_cast<size_t>(at.source))).parent_path() / path;
      std::string text, reason;
      if (!read_text_file(resolved, text, reason))
        throw GrammarError{at, "fopen cannot read '" + resolved.string() + "' (" + reason + ")"};
      g_.data_paths.push_back(resolved.string());
      return text;
    };
  }

  // Whether the pending statement has parentheses open, or braces between a ':' and its arrow
  // (blocks of a rule's head, which follow its ':', and Start: blocks): then it goes on to the
  // next line. Any other brace is a polygon's, which never joins the next line: an axiom's
  // ("F{.+F.A", closed by a rule), an ignore: or consider: list's, a predecessor's ("{ --> {"
  // rewrites one). Read as lines join the statement, each character once (a rule of a million
  // lines was read again for each).
  bool pending_open() {
    PendingNesting& n = nesting_;
    const std::string& t = pending_.text;
    if (n.scanned == 0 && !t.empty()) {
      size_t b = 0, e = t.size(), value = 0;
      trim(t, &b, &e);
      n.symbols = match_keyword(t, b, e, "axiom", true, &value) || match_keyword(t, b, e, "ignore", true, &value) ||
                  match_keyword(t, b, e, "consider", true, &value);
    }
    for (; n.scanned < t.size(); ++n.scanned) {
      const size_t k = n.scanned;
      if (t[k] == '(') ++n.parens;
      else if (t[k] == ')') --n.parens;
      else if (t[k] == '>' && k > 0 && t[k - 1] == '-') n.past_arrow = true;
      else if (t[k] == ':' && n.parens == 0) n.past_colon = true;
      else if (!n.symbols && n.past_colon && !n.past_arrow && t[k] == '{') ++n.braces;
      else if (!n.symbols && n.past_colon && !n.past_arrow && t[k] == '}') --n.braces;
    }
    return n.parens > 0 || n.braces > 0;
  }

  // Whether text starts with a directive keyword ("name:" or a section word).
  static bool starts_directive(std::string_view text, size_t begin, size_t end) {
    size_t value = 0;
    for (const std::string& keyword : kSectionDirectives)
      if (match_keyword(text, begin, end, keyword, false, &value)) return true;
    const size_t colon = text.find(':', begin);
    if (colon == kNone || colon >= end) return false;
    const std::string_view word = text.substr(begin, colon - begin);
    return word.size() >= 2 && std::all_of(word.begin(), word.end(), [](char c) {
             return std::isalpha(static_cast<unsigned char>(c)) || c == ' ';
           });
  }

  void feed(const SourceLine& line) {
    size_t begin = 0, end = line.text.size();
    trim(line.text, &begin, &end);
    // After "endlsystem" only the next "lsystem:" (a sub-L-system, CPFG manual 7.2) is read;
    // it is always a statement of its own.
    size_t value = 0;
    const bool opens = match_keyword(line.text, begin, end, "lsystem", true, &value);
    if (ended_ && !opens) return;
    if (opens) {
      flush();
      pending_ = line;
      flush();
      return;
    }
    if (begin == end) {  // a blank line ends a statement, unless it has open parentheses or blocks
      if (!pending_open()) flush();
      return;
    }
    if (!pending_.text.empty() && continues(line.text, begin, end)) {
      pending_.text += ' ';
      pending_.columns.push_back(line.columns[begin]);
      pending_.text += line.text;
      pending_.columns.insert(pending_.columns.end(), line.columns.begin(), line.columns.end());
      return;
    }
    flush();
    pending_ = line;
  }

  bool continues(std::string_view text, size_t begin, size_t end) {
    const std::string_view last = pending_.text;
    if (pending_open()) return true;
    size_t b = 0, e = last.size(), value = 0;
    trim(last, &b, &e);
    const bool rule = find_arrow(last, b, e) != kNone;
    const bool axiom = match_keyword(last, b, e, "axiom", true, &value);
    // A line that starts with the arrow ends a head written above it; after an axiom, a whole
    // rule or a directive it is a rule without a predecessor, and is told so at its own line.
    if (text.substr(begin, 2) == "->" || text.substr(begin, 3) == "-->") {
      const auto any_of = [&](const std::vector<std::string>& keywords, bool colon) {
        return std::any_of(keywords.begin(), keywords.end(),
                           [&](const std::string& keyword) { return match_keyword(last, b, e, keyword, colon, &value); });
      };
      return !rule && !any_of(kValueDirectives, true) && !any_of(kSectionDirectives, false);
    }
    // A rule's head not yet at its arrow ("A(x) :" then a block on the next line) goes on.
    if (!rule && !axiom) return !starts_directive(last, b, e) && looks_like_head(last, b, e);
    if (find_arrow(text, begin, end) != kNone || starts_directive(text, begin, end)) return false;
    // A rule's head written over lines starts with its own context or condition.
    return !looks_like_head(text, begin, end);
  }

  // Whether text[begin, end) has a context ('<', '>') or a condition (':') outside parentheses
  // and blocks: a rule's head, which no successor has.
  static bool looks_like_head(std::string_view text, size_t begin, size_t end) {
    return find_top_level(text, begin, end, ':') != kNone || find_top_level(text, begin, end, '<') != kNone ||
           find_top_level(text, begin, end, '>') != kNone;
  }

  void flush() {
    if (pending_.text.empty()) return;
    const SourceLine statement = std::move(pending_);
    pending_ = SourceLine{};
    nesting_ = PendingNesting{};
    parse_line(statement.text, TextOrigin{statement.start, &statement.columns});
  }

  void parse_line(std::string_view text, const TextOrigin& line) {
    size_t end = text.size();
    size_t begin = 0;
    trim(text, &begin, &end);
    size_t value = 0;
    if (ended_ && !match_keyword(text, begin, end, "lsystem", true, &value)) return;
    ended_ = false;
    if (begin == end) return;
    if (parse_directive(text, begin, end, line)) return;
    const size_t arrow = find_arrow(text, begin, end);
    if (arrow != kNone) return parse_rule(text, begin, arrow, end, line);
    report_non_rule(text, begin, end, line);
  }

  // Start of "-->" or "->" (the first '>' right after a '-'), kNone when there is none.
  static size_t find_arrow(std::string_view text, size_t begin, size_t end) {
    for (size_t k = begin + 1; k < end; ++k)
      if (text[k] == '>' && text[k - 1] == '-') return (k >= begin + 2 && text[k - 2] == '-') ? k - 2 : k - 1;
    return kNone;
  }

  // A line that is neither a directive nor a production: say which it looks like.
  [[noreturn]] void report_non_rule(std::string_view text, size_t begin, size_t end, const TextOrigin& line) {
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
                          excerpt(text.substr(begin, end - begin)) + "'");
  }

  // "name:" or "name :" at text[begin]; on a match, *value is just after the colon.
  static bool match_keyword(std::string_view text, size_t begin, size_t end,
                            const std::string& keyword, bool colon, size_t* value) {
    if (!same_letters(text.substr(begin, keyword.size()), keyword)) return false;
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

  bool parse_directive(std::string_view text, size_t begin, size_t end, const TextOrigin& line) {
    size_t value = 0;
    for (const std::string& keyword : kSectionDirectives) {
      if (!match_keyword(text, begin, end, keyword, false, &value)) continue;
      size_t rest = value;
      while (rest < end && is_space(text[rest])) ++rest;
      if (rest < end && text[rest] == ':') ++rest;
      while (rest < end && is_space(text[rest])) ++rest;
      // cpfg's "homomorphism: warnings" / "no warnings" only choose messages (manual 4.3.1).
      const std::string_view option = text.substr(rest, end - rest);
      const bool section = keyword == "homomorphism" || keyword == "decomposition";
      if (rest < end && section && (same_letters(option, "warnings") || same_letters(option, "no warnings")))
        rest = end;
      if (rest < end) fail(line, rest, "expected nothing after '" + keyword + "'" +
                                           (section ? " (or ': warnings', ': no warnings')" : ""));
      if (keyword == "homomorphism") section_ = Section::kHomomorphism;
      else if (keyword == "decomposition") section_ = Section::kDecomposition;
      else if (keyword == "ring lsystem") lsystem().ring = true;
      else ended_ = true;
      return true;
    }
    for (const std::string& keyword : kValueDirectives) {
      if (!match_keyword(text, begin, end, keyword, true, &value)) continue;
      // "AXIOM : c --> ..." is a rule whose predecessor spells a directive.
      if (keyword == "axiom" && find_arrow(text, value, end) != kNone) return false;
      size_t vbegin = value, vend = end;
      trim(text, &vbegin, &vend);
      if (vbegin == vend && keyword != "ignore" && keyword != "consider")
        fail(line, value, "expected a value after '" + keyword + ":'");
      // A sub-L-system's derivation length and seed are the first L-system's (CPFG manual 7.2).
      const bool first = !in_sub_lsystem();
      if (keyword == "start" || keyword == "starteach" || keyword == "end" || keyword == "endeach")
        parse_control_block(text, vbegin, vend, line, keyword, begin);
      else if (keyword == "define") parse_arrays(text, vbegin, vend, line);
      else if (keyword == "axiom") set_axiom(text, vbegin, vend, line, at_column(line, begin));
      else if (keyword == "derivation length") {
        const auto length = static_cast<int>(integer_value(text, vbegin, vend, line, 0, 100000));
        if (first) g_.derivation_length = length;
      } else if (keyword == "angle") {
        const double angle = constant_value(text, vbegin, vend, line);
        if (!(std::abs(angle) <= 360)) fail(line, vbegin, "expected an angle in [-360, 360] degrees, as lsystem.angle");
        g_.angle = angle;
      } else if (keyword == "width factor") {
        const double factor = constant_value(text, vbegin, vend, line);
        if (!(factor > 0 && std::isfinite(factor)))
          fail(line, vbegin, "expected a width factor above 0, as lsystem.width_factor");
        g_.width_factor = factor;
      }
      else if (keyword == "seed") {
        // After "homomorphism" it seeds the homomorphism's own draws (CPFG manual 4.3.3); the
        // decomposition draws with the productions (4.4).
        if (section_ == Section::kDecomposition)
          fail(line, begin, "a decomposition draws with the productions' random numbers: 'seed:' belongs before "
                            "'decomposition' (CPFG manual 4.4)");
        const auto seed = static_cast<uint64_t>(integer_value(text, vbegin, vend, line, 0, 1LL << 53));
        if (section_ == Section::kHomomorphism) {
          if (first) g_.homomorphism_seed = seed;
        } else {
          lsystem().productions.stochastic = true;
          if (first) g_.seed = seed;
        }
      } else if (keyword == "lsystem") lsystem_label(text, vbegin, vend, line);
      else if (keyword == "maximum depth") current().max_depth = static_cast<int>(integer_value(text, vbegin, vend, line, 1, kMaxDepth));
      else if (keyword == "tropism") parse_tropism(text, vbegin, vend, line);
      else parse_skips(text, vbegin, vend, line, keyword == "consider", begin);
      return true;
    }
    return false;
  }

  // A constant expression filling text[begin, end).
  double constant_value(std::string_view text, size_t begin, size_t end, const TextOrigin& line) {
    const ExprScope scope{nullptr, &g_.defines};
    size_t pos = begin;
    const Expr expr = compile_expression(g_.program, text.substr(0, end), &pos, line, scope);
    if (pos != end) fail(line, pos, "expected the end of the value, got '" + std::string(1, text[pos]) + "'");
    double value = 0;
    if (!g_.program.is_constant(expr, &value))
      fail(line, begin, "expected a constant value (no ran() or nran())");
    return value;
  }

  long long integer_value(std::string_view text, size_t begin, size_t end, const TextOrigin& line,
                          long long lo, long long hi) {
    const double v = constant_value(text, begin, end, line);
    if (std::floor(v) != v || v < double(lo) || v > double(hi)) {
      // A name's value (a #define, or the scene's lsystem.defines) is shown after it.
      const std::string written(text.substr(begin, end - begin));
      const std::string value = exact_number_text(v);
      fail(line, begin, "expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " +
                            written + (written == value ? "" : " = " + value));
    }
    return static_cast<long long>(v);
  }

  // "tropism: Tx Ty Tz e" (spaces or commas between the four values).
  void parse_tropism(std::string_view text, size_t begin, size_t end, const TextOrigin& line) {
    double values[4];
    size_t k = begin, elasticity = begin;
    for (int i = 0; i < 4; ++i) {
      while (k < end && (is_space(text[k]) || text[k] == ',')) ++k;
      elasticity = k;
      if (k >= end) fail(line, k, "expected 4 values 'Tx Ty Tz e' after 'tropism:', got " + std::to_string(i));
      size_t stop = k;
      while (stop < end && !is_space(text[stop]) && text[stop] != ',') ++stop;
      values[i] = constant_value(text, k, stop, line);
      k = stop;
    }
    while (k < end && (is_space(text[k]) || text[k] == ',')) ++k;
    if (k < end) fail(line, k, "expected 4 values 'Tx Ty Tz e' after 'tropism:', got more");
    const Eigen::Vector3d t(values[0], values[1], values[2]);
    if (!unit_direction(t) || !(t.norm() <= kMaxTropism))
      fail(line, begin, "expected a non-zero tropism direction at most 1e6 long");
    if (!(std::abs(values[3]) <= kMaxTropism))
      fail(line, elasticity, "expected an elasticity in [-1e6, 1e6]");
    g_.tropism = t;
    g_.tropism_elasticity = values[3];
  }

  // "ignore: symbols" or "consider: symbols". Brackets may be among them (a skipped '[' or ']'
  // changes right contexts only, as in cpfg; see docs/grammar.md).
  void parse_skips(std::string_view text, size_t begin, size_t end, const TextOrigin& line, bool consider,
                   size_t directive) {
    std::array<bool, 256>& skips = lsystem().context_skips;
    if (skips_kind_ != 0 && skips_kind_ != (consider ? 2 : 1))
      fail(line, directive, "'ignore:' and 'consider:' cannot both be given");
    if (skips_kind_ == 0 && consider) skips.fill(true);
    skips_kind_ = consider ? 2 : 1;
    for (size_t k = begin; k < end; ++k) {
      const char c = text[k];
      if (is_space(c)) continue;
      if (!std::isgraph(static_cast<unsigned char>(c))) fail(line, k, "expected module symbols (printable ASCII)");
      skips[static_cast<unsigned char>(c)] = !consider;
    }
  }

  // "#define NAME body" (no arguments) => true when body is a constant expression of one operand
  // (single_operand): the grammar keeps NAME as a number, which the scene's lsystem.defines may
  // replace. Otherwise (2+3, ran(), a module text, a name defined later) the preprocessor
  // expands the body as text, as cpp does.
  bool define_number(const std::string& name, const SourceLine& body, SourcePos at) {
    if (std::find(g_.file_defines.begin(), g_.file_defines.end(), name) != g_.file_defines.end())
      throw GrammarError{at, "'" + name + "' is already defined"};
    g_.file_defines.push_back(name);
    // The scene's value wins over a constant, even one that cannot be computed; a text macro
    // it cannot replace (the text would be dropped for a number, silently).
    const bool overridden = std::any_of(overrides_.begin(), overrides_.end(), [&](const auto& e) { return e.first == name; });
    // More than one operand is text, as cpp pastes it (the scene's value replaces it whole).
    if (!overridden && !single_operand(body.text)) return false;
    const ExprScope scope{nullptr, &g_.defines, nullptr};
    const TextOrigin origin{body.start, &body.columns};
    const size_t code_size = g_.program.code.size(), constants = g_.program.constants.size();
    auto forget_code = [&] {
      g_.program.code.resize(code_size);
      g_.program.code_pos.resize(code_size);
      g_.program.constants.resize(constants);
    };
    try {
      size_t pos = 0;
      const Expr expr = compile_expression(g_.program, body.text, &pos, origin, scope);
      double value = 0;
      if (pos == body.text.size() && g_.program.is_constant(expr, &value)) {
        if (!overridden) g_.defines.emplace_back(name, value);
        else forget_code();
        return true;
      }
    } catch (const GrammarError& error) {
      // A constant that cannot be computed (division by zero...) is an error where it is
      // written; anything else is text.
      if (error.message.find("division by zero") != std::string::npos || error.message.find("finite") != std::string::npos) {
        if (!overridden) throw;
        forget_code();
        return true;
      }
    }
    forget_code();
    if (overridden)
      throw GrammarError{at, "lsystem.defines gives '" + name + "' a value, but this #define is text (" +
                                 excerpt(body.text) + "), not a constant: only a constant #define takes the scene's "
                                 "value"};
    return false;
  }

  // "define: { array name[d1][d2] = { values }; array other[d]; }" (CPFG manual 2.2.2):
  // dimensions are constants ("[d1, d2]" also), values fill the elements in row-major order
  // (the rest start at 0).
  void parse_arrays(std::string_view text, size_t begin, size_t end, const TextOrigin& line) {
    const std::string_view body = text.substr(0, end);
    size_t k = begin;
    auto skip = [&] { while (k < end && is_space(body[k])) ++k; };
    auto expect = [&](char c, const std::string& what) {
      skip();
      if (k >= end || body[k] != c) fail(line, k, std::string("expected '") + c + "' " + what);
      ++k;
    };
    expect('{', "after 'define:'");
    for (;;) {
      skip();
      if (k < end && body[k] == '}') break;
      size_t value = 0;
      if (!match_keyword(body, k, end, "array", false, &value) || value >= end || !is_space(body[value]))
        fail(line, k, "expected 'array name[dimensions];' or '}' in 'define:'");
      k = value;
      skip();
      const size_t name_at = k;
      while (k < end && (std::isalnum(static_cast<unsigned char>(body[k])) || body[k] == '_')) ++k;
      const std::string name(body.substr(name_at, k - name_at));
      if (name.empty() || std::isdigit(static_cast<unsigned char>(name[0])))
        fail(line, name_at, "expected an array name after 'array'");
      if (std::find(g_.variables.begin(), g_.variables.end(), name) != g_.variables.end() ||
          std::any_of(g_.defines.begin(), g_.defines.end(), [&](const auto& d) { return d.first == name; }))
        fail(line, name_at, "'" + name + "' is already a variable or a define");
      ArrayDecl array{name, static_cast<uint32_t>(g_.variables.size() + 1), {}};
      size_t elements = 1;
      expect('[', "after the array's name");
      for (;;) {
        const size_t at = k;
        const long long size = integer_value(body, k, dimension_end(body, k, end), line, 1, kMaxArrayElements);
        k = dimension_end(body, k, end);
        elements *= static_cast<size_t>(size);
        if (g_.variables.size() + elements > kMaxArrayElements)
          fail(line, at, "more than " + std::to_string(kMaxArrayElements) + " array elements in the grammar");
        array.dims.push_back(static_cast<uint32_t>(size));
        if (k < end && body[k] == ',') { ++k; continue; }
        expect(']', "after a dimension");
        skip();
        if (k < end && body[k] == '[') { ++k; continue; }
        break;
      }
      g_.variables.push_back(name);
      g_.variables.resize(g_.variables.size() + elements - 1);
      g_.initial_values.resize(g_.variables.size() + 1, 0.0);
      skip();
      if (k < end && body[k] == '=') {
        ++k;
        expect('{', "to open the values of '" + name + "'");
        for (size_t n = 0;; ++n) {
          skip();
          const size_t at = k;
          const size_t stop = value_end(body, k, end);
          if (stop == end) fail(line, k, "expected '}' to close the values of '" + name + "'");
          if (n == elements) fail(line, at, "more values than the " + std::to_string(elements) + " elements of '" + name + "'");
          size_t vb = k, ve = stop;
          trim(body, &vb, &ve);
          g_.initial_values[array.base + n] = constant_value(body, vb, ve, line);
          k = stop + 1;
          if (body[stop] == '}') break;
        }
      }
      g_.program.arrays.push_back(std::move(array));
      expect(';', "after the array '" + name + "'");
    }
    ++k;
    skip();
    if (k < end && body[k] == ';') ++k;
    skip();
    if (k < end) fail(line, k, "expected the end of 'define:', got '" + std::string(1, body[k]) + "'");
  }

  // The end of a dimension starting at text[k]: the ',' or ']' after it (or end).
  static size_t dimension_end(std::string_view text, size_t k, size_t end) {
    return std::min({find_top_level(text, k, end, ','), find_top_level(text, k, end, ']'), end});
  }

  // The end of an initial value starting at text[k]: the ',' or '}' after it outside
  // parentheses (or end).
  static size_t value_end(std::string_view text, size_t k, size_t end) {
    int depth = 0;
    for (; k < end; ++k) {
      if (text[k] == '(') ++depth;
      else if (text[k] == ')') --depth;
      else if (depth == 0 && (text[k] == ',' || text[k] == '}')) return k;
    }
    return end;
  }

  // "Lsystem: label": a number or a name (cpfg reads a name as 0). The first one labels the
  // L-system that is derived; each later one starts a sub-L-system (CPFG manual 7.2).
  void lsystem_label(std::string_view text, size_t begin, size_t end, const TextOrigin& line) {
    for (size_t k = begin; k < end; ++k)
      if (!std::isalnum(static_cast<unsigned char>(text[k])) && text[k] != '_')
        fail(line, k, "expected a label (a number or a name) after 'lsystem:'");
    if (labelled_) {
      g_.lsystems.emplace_back();
      section_ = Section::kProductions;
      skips_kind_ = 0;
      sub_axiom_seen_ = false;
    }
    labelled_ = true;
    int label = 0;
    size_t digits = 0;
    for (size_t k = begin; k < end && std::isdigit(static_cast<unsigned char>(text[k])); ++k, ++digits) {
      if (digits == 9) fail(line, begin, "expected a label of at most 9 digits (a call names it as a number)");
      label = label * 10 + (text[k] - '0');
    }
    lsystem().label = label;
  }

  // "Start: { statements }" (also StartEach, EndEach, End), an optional ';' after it.
  void parse_control_block(std::string_view text, size_t begin, size_t end, const TextOrigin& line,
                           const std::string& keyword, size_t directive) {
    if (in_sub_lsystem())
      fail(line, directive, "a sub-L-system's '" + keyword + ":' block is not supported (cpfg gives each call of a "
                            "sub-L-system its own copy of the variables, CPFG manual 7.2)");
    if (text[begin] != '{') fail(line, begin, "expected '{' after '" + keyword + ":'");
    const StatementScope scope{nullptr, &g_.variables, true, &g_.defines, data_files()};
    size_t pos = begin;
    const Expr block = compile_block(g_.program, text.substr(0, end), &pos, line, scope);
    while (pos < end && (is_space(text[pos]) || text[pos] == ';')) ++pos;
    if (pos < end) fail(line, pos, "expected the end of the '" + keyword + ":' block, got '" + std::string(1, text[pos]) + "'");
    if (keyword == "start") g_.start_block = block;
    else if (keyword == "starteach") g_.start_each_block = block;
    else if (keyword == "endeach") g_.end_each_block = block;
    else g_.end_block = block;
  }

  // A sub-L-system's axiom is read and not used (CPFG manual 7.2: it runs only on its own).
  void set_axiom(std::string_view text, size_t begin, size_t end, const TextOrigin& line, SourcePos directive) {
    bool& seen = in_sub_lsystem() ? sub_axiom_seen_ : axiom_seen_;
    if (seen)
      throw GrammarError{directive, std::string("a second 'axiom:'; the ") + (in_sub_lsystem() ? "sub-L-system" : "grammar") +
                                        " has one already"};
    seen = true;
    const std::vector<std::string> no_formals;
    std::vector<SuccessorModule> sub_axiom;
    std::vector<Expr> sub_params;
    std::vector<SuccessorModule>* axiom = in_sub_lsystem() ? &sub_axiom : &g_.axiom;
    parse_word(text, begin, end, line, ExprScope{&no_formals, &g_.defines, &g_.variables}, axiom,
               in_sub_lsystem() ? &sub_params : &g_.axiom_params, "axiom");
    if (axiom->empty()) fail(line, begin, "expected at least one module in the axiom");
  }

  // Modules with actual parameters in text[begin, end) => appended to modules/params.
  // Brackets must balance within the word.
  void parse_word(std::string_view text, size_t begin, size_t end, const TextOrigin& line, const ExprScope& scope,
                  std::vector<SuccessorModule>* modules, std::vector<Expr>* params, const char* what) {
    std::vector<size_t> open;  // positions of unclosed '['
    const std::string_view word = text.substr(0, end);
    char previous = 0;  // the module before
    size_t previous_at = 0;  // and where it is
    for (size_t k = begin; k < end;) {
      const char c = text[k];
      if (is_space(c)) { ++k; continue; }
      check_symbol(text, k, line, what);
      if (c == '?' && is_call(text, k, end)) g_.calls = true;
      else if (c == '?' && is_query(text, k, end, line) && section_ != Section::kHomomorphism) g_.queries = true;
      // @L("label", ...), @S("command") and @I("object", s) take a string first (CPFG manual 6.10, 9.4, 9.5).
      const bool takes_string = previous == '@' && (c == 'L' || c == 'S' || c == 'I');
      if (previous == '@' && c == 'P')
        fail(line, previous_at, "'@P' (@PS, @PC, @PD: a bicubic patch from turtle positions, CPFG manual 6.7.2) is not "
                          "supported; draw the surface from a '.s' file with '~id' (a 'surface:' line of the view file)");
      previous = c;
      previous_at = k;
      if (c == '[') open.push_back(k);
      if (c == ']') {
        if (open.empty()) fail(line, k, "unbalanced brackets: ']' closes no '[' in the " + std::string(what));
        open.pop_back();
      }
      SuccessorModule module{c, 0, static_cast<uint32_t>(params->size()), at_column(line, k)};
      k = parameters_at(text, k + 1, end);
      if (k < end && text[k] == '(') {
        if (c == '[' || c == ']') fail(line, k, "brackets take no parameters");
        for (;;) {
          ++k;
          while (k < end && is_space(text[k])) ++k;
          if (k < end && text[k] == '"') {
            if (!takes_string || module.arity > 0)
              fail(line, k, "a string parameter is only read first in @L(\"label\"), @S(\"command\") and @I(\"object\", s)");
            const size_t quote = k;
            for (++k; k < end && text[k] != '"'; ++k) k += text[k] == '\\' ? 1 : 0;
            if (k >= end) fail(line, quote, "the string is never closed (expected '\"')");
            ++k;
            // Its value is its number in the file, as cpfg numbers strings; nothing reads the text.
            params->push_back(constant_expression(g_.program, static_cast<double>(strings_++), at_column(line, quote)));
          } else {
            params->push_back(compile_expression(g_.program, word, &k, line, scope));
          }
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

  // '?' at text[k] with parameters: a call of a sub-L-system '?(label, scale)' (CPFG manual 7.2).
  static bool is_call(std::string_view text, size_t k, size_t end) {
    const size_t p = parameters_at(text, k + 1, end);
    return p < end && text[p] == '(';
  }

  // '?' at text[k]: true for a query module ?P ?H ?U ?L (CPFG manual 6.9); a lone '?' is a
  // module like any other; ?E is refused.
  static bool is_query(std::string_view text, size_t k, size_t end, const TextOrigin& line) {
    const char next = k + 1 < end ? text[k + 1] : ' ';
    if (next == 'E')
      fail(line, k, "'?E' communicates with an environment process, which is not supported (CPFG manual 6.9)");
    return next == 'P' || next == 'H' || next == 'U' || next == 'L';
  }

  // Past a module symbol at text[k - 1]: the '(' of its parameters when only spaces come
  // before it (cpfg reads "\ (90)" as "\(90)": '(' is never a module), else k.
  static size_t parameters_at(std::string_view text, size_t k, size_t end) {
    size_t p = k;
    while (p < end && is_space(text[p])) ++p;
    return p < end && text[p] == '(' ? p : k;
  }

  static void check_symbol(std::string_view text, size_t k, const TextOrigin& line, const char* what) {
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
  void parse_rule(std::string_view text, size_t begin, size_t arrow, size_t end, const TextOrigin& line) {
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
    // Homomorphism rules match contexts in the word being drawn (CPFG manual 4.3.2). cpfg
    // matches a decomposition rule's contexts in the word before the step, which the
    // decomposition here (run on the word after it) never sees.
    if (section_ == Section::kDecomposition && (lt != kNone || gt != kNone))
      fail(line, lt != kNone ? lt : gt,
           "contexts are only allowed in productions and homomorphism rules, not in decomposition rules "
           "(cpfg matches them in the word before the step)");

    const size_t pred_begin = lt == kNone ? begin : lt + 1;
    const size_t pred_end = gt == kNone ? head_end : gt;
    if (lt != kNone) {
      rule.left_begin = static_cast<uint32_t>(set.patterns.size());
      parse_pattern(text, begin, lt, line, false, &set, &formals, "left context");
      rule.left_end = static_cast<uint32_t>(set.patterns.size());
    }
    parse_predecessor(text, pred_begin, pred_end, line, &rule, &set, &formals);
    if (gt != kNone) {
      rule.right_begin = static_cast<uint32_t>(set.patterns.size());
      parse_pattern(text, gt + 1, head_end, line, true, &set, &formals, "right context");
      rule.right_end = static_cast<uint32_t>(set.patterns.size());
    }
    if (cond != kNone) parse_statements(text, cond + 1, arrow, line, &formals, &rule);
    rule.slot_count = static_cast<uint16_t>(formals.size());
    const ExprScope scope{&formals, &g_.defines, &g_.variables};

    size_t succ_end = end;
    const size_t prob = find_last_top_level(text, arrow_end, end, ':');
    if (prob != kNone) {
      rule.probability = optional_expression(text, prob + 1, end, line, scope, "probability");
      double weight = 0;
      if (rule.probability.present() && g_.program.is_constant(rule.probability, &weight) && !(weight >= 0)) {
        size_t at = prob + 1;
        while (at < end && is_space(text[at])) ++at;
        fail(line, at, "expected a probability >= 0, got " + number_text(weight));
      }
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
    if (rule.length() > 1) set.any_strict_tail = true;
    rule.cpfg_parts = rule.length() > 1 || rule.before.present() || rule.after.present();
    set.rules.push_back(rule);
  }

  // "[{before}] [condition] [{after}]" between the predecessor's ':' and the arrow (CPFG
  // manual 3.2); names the blocks assign for the first time become locals in formals.
  void parse_statements(std::string_view text, size_t begin, size_t end, const TextOrigin& line,
                        std::vector<std::string>* formals, Rule* rule) {
    const StatementScope statements{formals, &g_.variables, false, &g_.defines, data_files()};
    const std::string_view head = text.substr(0, end);
    auto skip = [&](size_t k) { while (k < end && is_space(text[k])) ++k; return k; };
    size_t k = skip(begin);
    if (k < end && text[k] == '{') {
      rule->before = compile_block(g_.program, head, &k, line, statements);
      k = skip(k);
    }
    size_t stop = k;
    while (stop < end && text[stop] != '{') ++stop;  // the condition ends at the after-block
    const ExprScope scope{formals, &g_.defines, &g_.variables};
    if (stop > k || !rule->before.present()) rule->condition = optional_expression(text, k, stop, line, scope, "condition");
    k = skip(stop);
    if (k < end && text[k] == '{') {
      rule->after = compile_block(g_.program, head, &k, line, statements);
      k = skip(k);
    }
    if (k < end) fail(line, k, "expected the arrow after the condition and its blocks, got '" + std::string(1, text[k]) + "'");
  }

  // An expression filling text[begin, end), or none when it is '*'.
  Expr optional_expression(std::string_view text, size_t begin, size_t end, const TextOrigin& line,
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

  // The strict predecessor: its first module, then any more (CPFG manual 3.1) as patterns.
  void parse_predecessor(std::string_view text, size_t begin, size_t end, const TextOrigin& line, Rule* rule,
                         RuleSet* set, std::vector<std::string>* formals) {
    trim(text, &begin, &end);
    if (begin == end) fail(line, begin, "expected a predecessor module before the arrow");
    check_symbol(text, begin, line, "predecessor");
    if (text[begin] == '[' || text[begin] == ']') fail(line, begin, "a bracket cannot be in a predecessor");
    rule->predecessor = text[begin];
    rule->predecessor_slot = static_cast<uint16_t>(formals->size());
    size_t k = parameters_at(text, begin + 1, end);
    rule->arity = static_cast<uint8_t>(parse_formals(text, &k, end, line, formals));
    rule->tail_begin = static_cast<uint32_t>(set->patterns.size());
    parse_modules(text, k, end, line, false, set, formals, "predecessor");
    rule->tail_end = static_cast<uint32_t>(set->patterns.size());
  }

  // Context modules with formal parameters in text[begin, end); '*' alone = no context.
  void parse_pattern(std::string_view text, size_t begin, size_t end, const TextOrigin& line, bool brackets,
                     RuleSet* set, std::vector<std::string>* formals, const char* what) {
    trim(text, &begin, &end);
    if (begin == end) fail(line, begin, std::string("expected a ") + what + " (or '*' for none)");
    if (end == begin + 1 && text[begin] == '*') return;
    parse_modules(text, begin, end, line, brackets, set, formals, what);
  }

  // Modules with formal parameters in text[begin, end) => appended to set->patterns.
  void parse_modules(std::string_view text, size_t begin, size_t end, const TextOrigin& line, bool brackets,
                     RuleSet* set, std::vector<std::string>* formals, const char* what) {
    for (size_t k = begin; k < end;) {
      const char c = text[k];
      if (is_space(c)) { ++k; continue; }
      check_symbol(text, k, line, what);
      if (c == '?') is_query(text, k, end, line);
      if (!brackets && (c == '[' || c == ']'))
        fail(line, k, std::string("a bracket cannot be in a ") + what +
                          (std::string_view(what) == "left context" ? " (it already skips branches)" : ""));
      PatternModule module{c, 0, static_cast<uint16_t>(formals->size())};
      const size_t symbol_at = k;
      k = parameters_at(text, k + 1, end);
      module.arity = static_cast<uint8_t>(parse_formals(text, &k, end, line, formals));
      if ((c == '[' || c == ']') && module.arity) fail(line, k - 1, "brackets take no parameters");
      if (c == '=' && brackets && module.arity) fail(line, symbol_at, "'=' (the rest of the branch) takes no parameters");
      set->patterns.push_back(module);
    }
  }

  // "(a, b)" at text[*k] => names appended to formals; returns their count.
  int parse_formals(std::string_view text, size_t* k, size_t end, const TextOrigin& line, std::vector<std::string>* formals) {
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

  Grammar& g_;
  const std::vector<std::pair<std::string, double>>& overrides_;
  Section section_ = Section::kProductions;
  int skips_kind_ = 0;  // 0 none, 1 ignore:, 2 consider:
  bool axiom_seen_ = false;
  bool sub_axiom_seen_ = false;  // the current sub-L-system has its axiom
  uint32_t strings_ = 0;         // string parameters read so far
  bool labelled_ = false;        // an "lsystem:" line was read
  bool ended_ = false;  // after "endlsystem"
  SourcePos first_pos_;  // the first text's start, for errors about what is missing
  SourceLine pending_;   // the statement being joined from lines
  struct PendingNesting {
    size_t scanned = 0;  // characters of pending_ read
    int parens = 0, braces = 0;
    bool symbols = false, past_colon = false, past_arrow = false;  // symbols: axiom:, ignore:, consider:
  } nesting_;            // of pending_, as pending_open() read it
  std::optional<Preprocessor> preprocessor_;  // one for all texts: an inline grammar's lines share its #defines
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

int Grammar::lsystem_index(double label) const {
  for (size_t i = 0; i < lsystems.size(); ++i)
    if (static_cast<double>(lsystems[i].label) == std::trunc(label)) return static_cast<int>(i);
  return -1;
}

std::string Grammar::where(const SourcePos& pos) const {
  const std::string& name = sources.at(static_cast<size_t>(pos.source));
  if (pos.line == 0) return name + ", column " + std::to_string(pos.column);
  return name + ":" + std::to_string(pos.line) + ":" + std::to_string(pos.column);
}

Grammar parse_grammar(const std::vector<GrammarText>& texts,
                      const std::vector<std::pair<std::string, double>>& define_overrides,
                      const std::optional<GrammarText>& axiom_text,
                      std::vector<SampledFunction> functions, std::vector<ViewCurve> curves) {
  Grammar grammar;
  grammar.program.functions = std::move(functions);
  grammar.program.curves = std::move(curves);
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
