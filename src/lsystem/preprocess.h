#pragma once
// The part of the C preprocessor that cpfg grammar files rely on (a cpfg .l file is passed
// through cpp, CPFG manual ch. 2): comments, #define (numbers, text, macros with arguments),
// #include of a file beside the including one, #ifdef / #ifndef / #else / #endif.
// text => logical lines whose characters keep their origin (file, line, column).
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "lsystem/expression.h"

namespace treeanim {

// One line after preprocessing; a macro's expansion takes the place of its use.
struct SourceLine {
  std::string text;
  std::vector<SourcePos> columns;  // (text size) origin of each character
  SourcePos start;                 // the line's first column (for an empty line)
};

struct PreprocessHooks {
  // file name => source index for SourcePos.
  std::function<int32_t(const std::string& name)> add_source;
  // path as written, the including file's name => (name, text) of the included file.
  std::function<std::pair<std::string, std::string>(const std::string& path, const std::string& from,
                                                    SourcePos at)> include;
  // "#define NAME body" with no arguments => true when the grammar keeps it as a number
  // (overridable by the scene); otherwise the body is expanded as text where NAME is used.
  std::function<bool(const std::string& name, const SourceLine& body, SourcePos at)> define_number;
  // "#define NAME(a, ...) body" => told its name (the scene's lsystem.defines cannot replace it).
  std::function<void(const std::string& name)> define_macro;
  // name => whether the grammar holds it as a number (for #ifdef).
  std::function<bool(const std::string& name)> is_number;
  // Every logical line, in order.
  std::function<void(const SourceLine& line)> line;
};

// Reads one text (a file or an inline line). Throws GrammarError.
class Preprocessor {
 public:
  explicit Preprocessor(PreprocessHooks hooks) : hooks_(std::move(hooks)) {}
  // One text: a file's (its #ifdefs closed in it), or a line of the scene's inline grammar,
  // whose #defines and #ifdefs go on into the next lines, as a file's lines do.
  void run(const std::string& name, const std::string& text, bool single_line);
  // After the last text: every #ifdef closed.
  void finish() const;

 private:
  struct Macro {
    std::string name;
    std::vector<std::string> parameters;
    bool function_like = false;
    SourceLine body;
  };
  void directive(const std::string& name, const SourceLine& line, size_t hash);
  void define(const SourceLine& line, size_t begin);
  SourceLine expand(const SourceLine& line) const;
  // `expanding`: the macros whose expansion this is, innermost last, which it does not expand
  // again; `depth`: how many expansions (of a body or an argument) this one is nested in.
  SourceLine expand_within(const SourceLine& line, std::vector<const Macro*>& expanding, int depth) const;
  const Macro* find(const std::string& name, const std::vector<const Macro*>& expanding) const;

  PreprocessHooks hooks_;
  std::vector<Macro> macros_;
  struct Condition {
    bool taken;    // the lines of this branch are read
    bool in_else;  // past its #else
    SourcePos at;  // the #ifdef or #ifndef (where an unclosed one is reported)
  };
  std::vector<Condition> conditions_;  // open #ifdef / #ifndef, innermost last
  int include_depth_ = 0;
  size_t read_ = 0;  // bytes handed to the parser, after expansion
  std::string current_;  // name of the text being read (includes are found beside it)
};

}  // namespace treeanim
