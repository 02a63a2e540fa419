// cpp subset for cpfg grammars (docs/grammar.md "Preprocessor"): comments, #define, #include,
// #ifdef. Macro expansion is depth-limited (kMaxExpansion) and never re-expands a macro inside
// its own expansion, so no input makes it loop or recurse without bound.
#include "lsystem/preprocess.h"

#include <algorithm>
#include <cctype>

#include "common/message_text.h"

namespace treeanim {

namespace {

constexpr int kMaxExpansion = 32;  // nested macro expansions
constexpr int kMaxIncludes = 16;   // nested #include
constexpr size_t kMaxLineLength = 1 << 20;  // one line after expansion
// The whole grammar after expansion, far past any real one: #includes that each include the next
// twice, or macros of macros, multiply a few kilobytes into gigabytes, and the parsed rules take
// some 20 times their text.
constexpr size_t kMaxGrammarBytes = size_t(64) << 20;

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r'; }
bool starts_name(char c) { return std::isalpha(static_cast<unsigned char>(c)) || c == '_'; }
bool in_name(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }

[[noreturn]] void fail(SourcePos at, const std::string& message) { throw GrammarError{at, message}; }

// text => the same text with each character of a comment blanked to one space (newlines kept,
// so lines and columns, counted in characters, stay).
std::string strip_comments(const std::string& text, int32_t source, bool single_line) {
  std::string out;
  out.reserve(text.size());
  int32_t line = 1, column = 1;  // where text[k] stands
  for (size_t k = 0; k < text.size();) {
    // "//" starts a comment, as cpp (which cpfg runs) reads it, after a module too ("FF// x");
    // a run of three or more '/' is roll modules (ABOP's "/////").
    const bool slash = text[k] == '/' && k + 1 < text.size();
    const bool line_comment = slash && text[k + 1] == '/' && (out.empty() || out.back() != '/') &&
                              (k + 2 >= text.size() || text[k + 2] != '/');
    size_t end = k + 1;  // past the comment, or past this byte
    if (line_comment) {
      end = std::min(text.find('\n', k), text.size());
    } else if (slash && text[k + 1] == '*') {
      const size_t close = text.find("*/", k + 2);
      if (close == std::string::npos)
        fail({source, single_line ? 0 : line, column}, "'/*' comment is never closed (expected '*/')");
      end = close + 2;
    }
    const bool comment = end > k + 1;
    for (; k < end; ++k) {
      const char c = text[k];
      if (c == '\n' && !single_line) {
        ++line;
        column = 1;
      } else if (!continues_character(c)) {  // a single-line text's newline is one of its characters
        ++column;
      }
      if (!comment || c == '\n') out += c;
      else if (!continues_character(c)) out += ' ';
    }
  }
  return out;
}

SourceLine make_line(std::string_view text, SourcePos start) {
  SourceLine line;
  line.text = std::string(text);
  line.start = start;
  line.columns.reserve(text.size());
  int32_t column = start.column - 1;  // a byte that continues a character takes its column
  for (const char c : text) line.columns.push_back({start.source, start.line, continues_character(c) ? column : ++column});
  return line;
}

SourceLine slice(const SourceLine& line, size_t begin, size_t end) {
  SourceLine out;
  out.text = line.text.substr(begin, end - begin);
  out.columns.assign(line.columns.begin() + static_cast<std::ptrdiff_t>(begin), line.columns.begin() + static_cast<std::ptrdiff_t>(end));
  out.start = begin < line.columns.size() ? line.columns[begin] : line.start;
  return out;
}

void append(SourceLine& to, std::string_view text, SourcePos at) {
  to.text += text;
  to.columns.insert(to.columns.end(), text.size(), at);
}

size_t skip_spaces(const std::string& text, size_t k) {
  while (k < text.size() && is_space(text[k])) ++k;
  return k;
}

}  // namespace

void Preprocessor::run(const std::string& name, const std::string& text, bool single_line) {
  const int32_t source = hooks_.add_source(name);
  current_ = name;
  const std::string clean = strip_comments(text, source, single_line);
  const size_t open_conditions = conditions_.size();
  // Where clean[start] stands: a file's line and column 1, or a single-line text's (a scene's
  // string) column counted from the string's start, its newlines characters like any other.
  int32_t number = 1, column = 1;
  size_t start = 0, stop = 0;
  const auto at_start = [&] { return single_line ? SourcePos{source, 0, column} : SourcePos{source, number, 1}; };
  const auto next_line = [&] {
    if (single_line)
      for (size_t k = start; k <= stop; ++k) column += continues_character(clean[k]) ? 0 : 1;
    start = stop + 1;
    stop = std::min(clean.find('\n', start), clean.size());
    ++number;
  };
  for (stop = std::min(clean.find('\n'), clean.size());;) {
    // Before its columns (12 bytes a character) are made: a 100 MB line took 2.9 GB.
    if (stop - start > kMaxLineLength) fail(at_start(), "a line longer than 1 MiB");
    SourceLine line = make_line(std::string_view(clean).substr(start, stop - start), at_start());
    const size_t hash = skip_spaces(line.text, 0);
    // A line continues on the next one after a trailing backslash, as in cpp; cpfg files also
    // end continued lines with two backslashes, read as one continuation.
    while (!line.text.empty() && line.text.back() == '\\' && stop < clean.size()) {
      for (size_t b = line.text.size(); b > 0 && line.text[b - 1] == '\\'; --b) line.text[b - 1] = ' ';
      next_line();
      if (line.text.size() + (stop - start) > kMaxLineLength) fail(at_start(), "a line longer than 1 MiB");
      const SourceLine more = make_line(std::string_view(clean).substr(start, stop - start), at_start());
      line.text += more.text;
      line.columns.insert(line.columns.end(), more.columns.begin(), more.columns.end());
    }
    const bool active = std::all_of(conditions_.begin(), conditions_.end(), [](const Condition& c) { return c.taken; });
    if (hash < line.text.size() && line.text[hash] == '#' && (hash + 1 >= line.text.size() || !std::ispunct(static_cast<unsigned char>(line.text[hash + 1])))) {
      size_t word = skip_spaces(line.text, hash + 1), end = word;
      while (end < line.text.size() && in_name(line.text[end])) ++end;
      const std::string directive_name = line.text.substr(word, end - word);
      const bool conditional = directive_name == "ifdef" || directive_name == "ifndef" || directive_name == "else" ||
                               directive_name == "endif" || directive_name == "if" || directive_name == "elif";
      if (conditional || active) {
        if (directive_name.empty() || (word > hash + 1 && !conditional && directive_name != "define" && directive_name != "include"))
          ;  // '#' alone or '# text': a comment line (cpp's null directive)
        else
          directive(directive_name, line, hash);
      }
    } else if (active) {
      const SourceLine expanded = expand(line);
      read_ += expanded.text.size() + 1;
      if (read_ > kMaxGrammarBytes)
        fail(line.start, "the grammar grows past 64 MiB with its #includes and macros expanded");
      hooks_.line(expanded);
    }
    if (stop == clean.size()) break;
    next_line();
  }
  if (!single_line && conditions_.size() != open_conditions)
    fail(conditions_.back().at, "#ifdef or #ifndef is never closed (expected #endif)");
}

void Preprocessor::finish() const {
  if (!conditions_.empty()) fail(conditions_.back().at, "#ifdef or #ifndef is never closed (expected #endif)");
}

void Preprocessor::directive(const std::string& name, const SourceLine& line, size_t hash) {
  const SourcePos at = line.columns[hash];
  size_t k = skip_spaces(line.text, line.text.find(name, hash + 1) + name.size());
  if (name == "define") return define(line, k);
  if (name == "ifdef" || name == "ifndef") {
    size_t end = k;
    while (end < line.text.size() && in_name(line.text[end])) ++end;
    if (end == k) fail(line.columns[std::min(k, line.columns.size() - 1)], "expected a name after '#" + name + "'");
    const std::string macro = line.text.substr(k, end - k);
    const bool defined = find(macro, {}) != nullptr || hooks_.is_number(macro);
    conditions_.push_back({defined == (name == "ifdef"), false, at});
    return;
  }
  if (name == "else" || name == "endif") {
    if (conditions_.empty()) fail(at, "'#" + name + "' without #ifdef or #ifndef");
    if (name == "endif") return conditions_.pop_back();
    Condition& open = conditions_.back();
    if (open.in_else) fail(at, "a second '#else' for one #ifdef");
    open.taken = !open.taken;
    open.in_else = true;
    return;
  }
  if (name == "include") {
    const size_t open = k;
    const char close = open < line.text.size() && line.text[open] == '<' ? '>' : '"';
    const size_t end = open < line.text.size() ? line.text.find(close, open + 1) : std::string::npos;
    if (open >= line.text.size() || (line.text[open] != '"' && line.text[open] != '<') || end == std::string::npos)
      fail(at, "expected a file name in quotes after '#include'");
    if (++include_depth_ > kMaxIncludes) fail(at, "#include nested more than 16 deep");
    const auto [file, text] = hooks_.include(line.text.substr(open + 1, end - open - 1), current_, at);
    const std::string outer = current_;
    run(file, text, false);
    current_ = outer;
    --include_depth_;
    return;
  }
  if (name == "ignore" || name == "consider")  // ABOP's listings print the statement so (Fig. 1.31)
    fail(at, "'#" + name + ":' is ABOP's way of printing the statement; write '" + name + ":' without the '#'");
  fail(at, "unsupported preprocessor directive '#" + name + "' (supported: #define, #include, #ifdef, #ifndef, #else, #endif; '# ' starts a comment)");
}

void Preprocessor::define(const SourceLine& line, size_t k) {
  const SourcePos after = k < line.columns.size() ? line.columns[k] : SourcePos{line.start.source, line.start.line, static_cast<int32_t>(line.text.size()) + 1};
  size_t end = k;
  if (k < line.text.size() && starts_name(line.text[k]))
    while (end < line.text.size() && in_name(line.text[end])) ++end;
  if (end == k) fail(after, "expected a name after '#define'");
  Macro macro;
  macro.name = line.text.substr(k, end - k);
  k = end;
  if (k < line.text.size() && line.text[k] == '(') {
    macro.function_like = true;
    for (;;) {
      k = skip_spaces(line.text, k + 1);
      size_t stop = k;
      while (stop < line.text.size() && in_name(line.text[stop])) ++stop;
      if (stop > k) {
        const std::string parameter = line.text.substr(k, stop - k);
        // As cpp: which argument a repeated name stands for is no one's guess.
        if (std::find(macro.parameters.begin(), macro.parameters.end(), parameter) != macro.parameters.end())
          fail(line.columns[k], "parameter '" + parameter + "' appears twice in macro '" + macro.name + "'");
        macro.parameters.push_back(parameter);
      }
      k = skip_spaces(line.text, stop);
      if (k < line.text.size() && line.text[k] == ')') break;
      if (k >= line.text.size() || line.text[k] != ',')
        fail(line.columns[std::min(k, line.columns.size() - 1)], "expected ',' or ')' in the parameters of macro '" + macro.name + "'");
    }
    ++k;
  }
  k = skip_spaces(line.text, k);
  size_t body_end = line.text.size();
  while (body_end > k && is_space(line.text[body_end - 1])) --body_end;
  for (const Macro& m : macros_)
    if (m.name == macro.name) fail(after, "'" + macro.name + "' is already defined");
  macro.body = expand(slice(line, k, body_end));  // empty for cpp's flag (#define NAME): text of nothing
  if (!macro.function_like && hooks_.define_number(macro.name, macro.body, after)) return;
  if (macro.function_like && hooks_.define_macro) hooks_.define_macro(macro.name);
  macros_.push_back(std::move(macro));
}

const Preprocessor::Macro* Preprocessor::find(const std::string& name,
                                               const std::vector<const Macro*>& expanding) const {
  for (const Macro& m : macros_)
    if (m.name == name) return std::find(expanding.begin(), expanding.end(), &m) == expanding.end() ? &m : nullptr;
  return nullptr;
}

SourceLine Preprocessor::expand(const SourceLine& line) const {
  std::vector<const Macro*> expanding;
  return expand_within(line, expanding, 0);
}

SourceLine Preprocessor::expand_within(const SourceLine& line, std::vector<const Macro*>& expanding, int depth) const {
  if (macros_.empty()) return line;
  if (depth > kMaxExpansion) fail(line.start, "macros expand more than 32 levels deep");
  SourceLine out;
  out.start = line.start;
  const std::string& t = line.text;
  for (size_t k = 0; k < t.size();) {
    if (!starts_name(t[k]) || (k > 0 && in_name(t[k - 1]))) {
      out.text += t[k];
      out.columns.push_back(line.columns[k]);
      ++k;
      continue;
    }
    size_t end = k;
    while (end < t.size() && in_name(t[end])) ++end;
    const Macro* macro = find(t.substr(k, end - k), expanding);
    const SourcePos at = line.columns[k];
    size_t open = skip_spaces(t, end);
    if (!macro || (macro->function_like && (open >= t.size() || t[open] != '('))) {
      append(out, std::string_view(t).substr(k, end - k), at);
      k = end;
      continue;
    }
    SourceLine body = macro->body;
    if (macro->function_like) {
      // Arguments: split at commas outside parentheses.
      std::vector<std::string> args;
      int nesting = 0;
      size_t arg_begin = open + 1, j = open + 1;
      for (; j < t.size(); ++j) {
        if (t[j] == '(') ++nesting;
        else if (t[j] == ')' && nesting-- == 0) break;
        else if (t[j] == ',' && nesting == 0) {
          args.push_back(t.substr(arg_begin, j - arg_begin));
          arg_begin = j + 1;
        }
      }
      if (j >= t.size()) fail(at, "expected ')' to close the arguments of macro '" + macro->name + "'");
      if (j > arg_begin || !args.empty() || !macro->parameters.empty()) args.push_back(t.substr(arg_begin, j - arg_begin));
      if (args.size() != macro->parameters.size())
        fail(at, "macro '" + macro->name + "' expects " + std::to_string(macro->parameters.size()) + " arguments, got " +
                     std::to_string(args.size()));
      // Each argument is expanded first, as cpp does, this macro still allowed in it: D(D(1)).
      for (std::string& arg : args) {
        const SourceLine whole{arg, std::vector<SourcePos>(arg.size(), at), at};
        arg = expand_within(whole, expanding, depth + 1).text;
      }
      SourceLine substituted;
      const std::string& b = macro->body.text;
      for (size_t q = 0; q < b.size();) {
        if (starts_name(b[q]) && (q == 0 || !in_name(b[q - 1]))) {
          size_t e = q;
          while (e < b.size() && in_name(b[e])) ++e;
          const auto p = std::find(macro->parameters.begin(), macro->parameters.end(), b.substr(q, e - q));
          if (p != macro->parameters.end()) {
            append(substituted, args[static_cast<size_t>(p - macro->parameters.begin())], at);
            // Checked as it grows: each use of an argument copies it (5,000 uses took 1.9 GB).
            if (substituted.text.size() > kMaxLineLength) fail(at, "a line grows past 1 MiB when its macros are expanded");
            q = e;
            continue;
          }
          append(substituted, b.substr(q, e - q), at);
          q = e;
          continue;
        }
        append(substituted, std::string_view(b).substr(q, 1), at);
        ++q;
      }
      body = substituted;
      end = j + 1;
    }
    std::fill(body.columns.begin(), body.columns.end(), at);
    // The expansion is expanded again without this macro (cpp's rule against self-reference).
    expanding.push_back(macro);
    const SourceLine expanded = expand_within(body, expanding, depth + 1);
    expanding.pop_back();
    out.text += expanded.text;
    out.columns.insert(out.columns.end(), expanded.columns.size(), at);
    if (out.text.size() > kMaxLineLength) fail(at, "a line grows past 1 MiB when its macros are expanded");
    k = end;
  }
  return out;
}

}  // namespace treeanim
