#include "lsystem/expression.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iterator>
#include <numbers>

#include "common/did_you_mean.h"

namespace treeanim {

namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

struct Function {
  const char* name;
  Op op;
  int arity;
};

// The cpfg manual's function library (chapter 5), plus abs, min and max.
constexpr std::array<Function, 30> kFunctions{{
    {"sin", Op::kSin, 1},   {"cos", Op::kCos, 1},     {"tan", Op::kTan, 1},
    {"asin", Op::kAsin, 1}, {"acos", Op::kAcos, 1},   {"atan", Op::kAtan, 1},
    {"atan2", Op::kAtan2, 2}, {"sqrt", Op::kSqrt, 1}, {"exp", Op::kExp, 1},
    {"log", Op::kLog, 1},   {"abs", Op::kAbs, 1},     {"fabs", Op::kAbs, 1},
    {"min", Op::kMin, 2},   {"max", Op::kMax, 2},     {"floor", Op::kFloor, 1},
    {"ceil", Op::kCeil, 1}, {"trunc", Op::kTrunc, 1}, {"sign", Op::kSign, 1},
    {"pow", Op::kPow, 2},   {"func", Op::kFunc, 2},   {"ran", Op::kRan, 1},
    {"nran", Op::kNran, 2}, {"bran", Op::kBran, 2},   {"biran", Op::kBiran, 2},
    {"srand", Op::kSrand, 1}, {"fmod", Op::kRem, 2},   {"curveX", Op::kCurve, 2},
    {"curveY", Op::kCurve, 2}, {"curveZ", Op::kCurve, 2}, {"curveGAL", Op::kCurveLength, 1},
}};

// Operands an instruction pops.
int arity_of(Op op) {
  switch (op) {
    case Op::kConst: case Op::kParam: case Op::kLoadVar: case Op::kJump: return 0;
    case Op::kNeg: case Op::kNot: case Op::kStoreVar: case Op::kStoreParam: case Op::kPop:
    case Op::kJumpIfZero: case Op::kIndex: case Op::kLoadElem: case Op::kFclose: case Op::kFscan: return 1;
    case Op::kStoreElem: return 2;
    case Op::kAdd: case Op::kSub: case Op::kMul: case Op::kDiv: case Op::kPow: case Op::kRem: case Op::kIntRem:
    case Op::kLt: case Op::kLe: case Op::kGt: case Op::kGe: case Op::kEq: case Op::kNe: return 2;
    default: break;
  }
  for (const Function& f : kFunctions)
    if (f.op == op) return f.arity;
  return 0;
}

// Values an instruction pushes.
int results_of(Op op) {
  switch (op) {
    case Op::kStoreVar: case Op::kStoreParam: case Op::kPop: case Op::kJump: case Op::kJumpIfZero:
    case Op::kStoreElem:
      return 0;
    default: return 1;
  }
}

// Pure operations of constants may be computed when compiled.
bool foldable(Op op) {
  switch (op) {
    case Op::kConst: case Op::kParam: case Op::kRan: case Op::kNran: case Op::kBran: case Op::kBiran:
    case Op::kSrand: case Op::kLoadVar: case Op::kStoreVar: case Op::kStoreParam: case Op::kPop:
    case Op::kJump: case Op::kJumpIfZero: case Op::kLoadElem: case Op::kStoreElem:
    case Op::kFopen: case Op::kFclose: case Op::kFscan:
      return false;
    default: return true;
  }
}

std::string plural(int n, const char* word) {
  return std::to_string(n) + " " + word + (n == 1 ? "" : "s");
}

// The candidate `word` is most likely a typo of, or "" (at most one edit per three letters,
// and never a whole rewrite, so that one-letter names are not "corrected" into others).
std::string suggestion(const std::string& word, const std::vector<std::string>& candidates) {
  const std::string near = closest_match(word, candidates);
  if (near.empty()) return "";
  const size_t distance = edit_distance(word, near);
  if (distance >= word.size() || distance > std::max<size_t>(1, word.size() / 3)) return "";
  return near;
}

// Recursive-descent compiler of one expression into program.code. Precedence, lowest first, is
// cpfg's (its parser, lsys_input.y): ?: || && (== !=) (< <= > >=) (+ -) (* / %) ^ unary, each
// binary level grouping to the left, so -2^2 = 4 and 2^3^2 = 64 as cpfg computes them.
class Compiler {
 public:
  Compiler(ExprProgram& program, std::string_view text, size_t pos, const TextOrigin& line,
           const ExprScope& scope)
      : program_(program), text_(text), pos_(pos), line_(line), scope_(scope) {}

  // => the compiled expression; pos() is left after it.
  Expr compile() {
    Expr expr;
    skip_space();
    expr.pos = at(pos_);
    expr.begin = static_cast<uint32_t>(program_.code.size());
    barrier_ = program_.code.size();
    parse_conditional();
    expr.end = static_cast<uint32_t>(program_.code.size());
    return expr;
  }

  // "{ statements }" at pos() => the compiled block (it leaves nothing on the stack).
  Expr compile_block(const StatementScope& statements) {
    statements_ = &statements;
    Expr block;
    skip_space();
    block.pos = at(pos_);
    block.begin = static_cast<uint32_t>(program_.code.size());
    barrier_ = program_.code.size();
    parse_block();
    block.end = static_cast<uint32_t>(program_.code.size());
    return block;
  }
  size_t pos() const { return pos_; }

 private:
  SourcePos at(size_t index) const { return line_.at(index); }
  [[noreturn]] void fail(size_t index, const std::string& message) const {
    throw GrammarError{at(index), message};
  }
  char peek(size_t ahead = 0) const {
    return pos_ + ahead < text_.size() ? text_[pos_ + ahead] : '\0';
  }
  void skip_space() {
    while (pos_ < text_.size() && (text_[pos_] == ' ' || text_[pos_] == '\t')) ++pos_;
  }
  // Consumes `token` (after spaces) when it is next.
  bool accept(std::string_view token) {
    skip_space();
    if (text_.substr(pos_, token.size()) != token) return false;
    pos_ += token.size();
    return true;
  }
  std::string describe_next() const {
    if (pos_ >= text_.size()) return "the end of the expression";
    return std::string("'") + text_[pos_] + "'";
  }

  void emit(Op op, uint32_t arg, size_t where) {
    program_.code.push_back({op, arg});
    program_.code_pos.push_back(at(where));
    depth_ += results_of(op) - arity_of(op);
    if (depth_ > kMaxExprStack) fail(where, "expression too deeply nested");
    if (foldable(op)) fold(arity_of(op));
  }
  // A jump whose target is patched later; returns its index.
  size_t emit_jump(Op op, size_t where) {
    emit(op, 0, where);
    return program_.code.size() - 1;
  }
  // The jump at `index` goes to the next instruction; nothing before it may be folded since.
  void land(size_t index) {
    program_.code[index].arg = static_cast<uint32_t>(program_.code.size());
    barrier_ = program_.code.size();
  }
  void emit_constant(double value, size_t where) {
    program_.constants.push_back(value);
    emit(Op::kConst, static_cast<uint32_t>(program_.constants.size() - 1), where);
  }
  // When the operands of the instruction just emitted are all constants, replaces them and it
  // by their value (division by zero or a non-finite value is then a compile-time error).
  void fold(int operands) {
    const size_t n = program_.code.size();
    if (n < barrier_ + 1 + static_cast<size_t>(operands)) return;  // an operand is a jump's target
    for (int k = 1; k <= operands; ++k)
      if (program_.code[n - 1 - k].op != Op::kConst) return;
    Expr tail;
    tail.begin = static_cast<uint32_t>(n - 1 - operands);
    tail.end = static_cast<uint32_t>(n);
    double value = 0;
    try {
      RandomStream unused;
      value = evaluate(program_, tail, nullptr, unused);
    } catch (const EvalError& error) {
      throw GrammarError{error.pos, error.message};
    }
    const SourcePos where = program_.code_pos[tail.begin];
    program_.code.resize(tail.begin);
    program_.code_pos.resize(tail.begin);
    program_.constants.push_back(value);
    program_.code.push_back({Op::kConst, static_cast<uint32_t>(program_.constants.size() - 1)});
    program_.code_pos.push_back(where);
  }

  // c ? a : b (right-associative, below ||), compiled with jumps so that only one side runs. A
  // chain c1 ? a1 : c2 ? a2 : ... is a loop (every side's end jumps past the whole chain); a
  // '?' inside a then-side nests, as a parenthesis does (a recursion per '?' overflowed the
  // stack on a chain of 60,000).
  void parse_conditional() {
    std::vector<size_t> skips_else;
    for (;;) {
      parse_or();
      skip_space();
      const size_t where = pos_;
      if (!accept("?")) break;
      const size_t skip_then = emit_jump(Op::kJumpIfZero, where);
      if (++nesting_ > kMaxNesting) fail(where, "expression too deeply nested");
      parse_conditional();
      --nesting_;
      skip_space();
      if (!accept(":")) fail(pos_, "expected ':' of the '?' at column " + std::to_string(where + 1) + ", got " + describe_next());
      skips_else.push_back(emit_jump(Op::kJump, where));
      --depth_;  // one of the two sides is on the stack
      land(skip_then);
    }
    for (const size_t skip : skips_else) land(skip);
  }

  // a || b and a && b, 1 or 0, as in C and cpfg: b runs only when a leaves the answer open
  // (x != 0 && 1 / x > 0 divides by nothing), compiled as a ? 1 : b != 0 and a ? b != 0 : 0.
  void parse_or() {
    parse_and();
    for (;;) {
      const size_t where = (skip_space(), pos_);
      if (!accept("||")) return;
      logic_operand(where, true);
    }
  }
  void parse_and() {
    parse_comparison();
    for (;;) {
      const size_t where = (skip_space(), pos_);
      if (!accept("&&")) return;
      logic_operand(where, false);
    }
  }
  // The left operand on the stack => the right one parsed (parse_and's for ||, parse_comparison's
  // for &&) and run only when needed; the result 1 or 0 on the stack.
  void logic_operand(size_t where, bool is_or) {
    const size_t n = program_.code.size();
    if (n > barrier_ && program_.code[n - 1].op == Op::kConst) {
      // A constant left side decides now, so that `#define B (A && 1)` stays a constant: the
      // right side is parsed (its errors reported) and kept only where it decides, as right != 0.
      const double left = program_.constants[program_.code[n - 1].arg];
      program_.code.pop_back(), program_.code_pos.pop_back(), --depth_;
      const size_t right = program_.code.size(), barrier = barrier_;
      is_or ? parse_and() : parse_comparison();
      if (is_or ? left != 0 : left == 0) {
        program_.code.resize(right), program_.code_pos.resize(right), --depth_;
        barrier_ = barrier;
        emit_constant(is_or ? 1 : 0, where);
      } else {
        emit_constant(0, where);
        emit(Op::kNe, 0, where);
      }
      return;
    }
    const size_t to_right = emit_jump(Op::kJumpIfZero, where);
    if (is_or) {  // a true: 1
      emit_constant(1, where);
      const size_t past = emit_jump(Op::kJump, where);
      --depth_;  // one of the two sides is on the stack
      land(to_right);
      parse_and();
      emit_constant(0, where);
      emit(Op::kNe, 0, where);
      land(past);
    } else {  // a false: 0
      parse_comparison();
      emit_constant(0, where);
      emit(Op::kNe, 0, where);
      const size_t past = emit_jump(Op::kJump, where);
      --depth_;
      land(to_right);
      emit_constant(0, where);
      land(past);
    }
  }
  void parse_comparison() {  // == and != bind less tightly than < <= > >=, as in C and cpfg
    parse_relation();
    for (;;) {
      skip_space();
      const size_t where = pos_;
      Op op;
      if (accept("==")) op = Op::kEq;
      else if (accept("!=") || accept("<>")) op = Op::kNe;  // cpfg reads both (lsys_input.l)
      else if (peek() == '=') fail(pos_, "expected '==' to compare, got '='");
      else return;
      parse_relation();
      emit(op, 0, where);
    }
  }
  void parse_relation() {
    parse_sum();
    for (;;) {
      skip_space();
      const size_t where = pos_;
      Op op;
      if (accept("<=")) op = Op::kLe;
      else if (accept(">=")) op = Op::kGe;
      else if (text_.substr(pos_, 2) == "<>") return;  // cpfg's !=, compared a level below
      else if (accept("<")) op = Op::kLt;
      else if (accept(">")) op = Op::kGt;
      else return;
      parse_sum();
      emit(op, 0, where);
    }
  }
  void parse_sum() {
    parse_product();
    for (;;) {
      skip_space();
      const size_t where = pos_;
      if (accept("+")) { parse_product(); emit(Op::kAdd, 0, where); }
      else if (accept("-")) { parse_product(); emit(Op::kSub, 0, where); }
      else return;
    }
  }
  void parse_product() {
    parse_power();
    for (;;) {
      skip_space();
      const size_t where = pos_;
      if (accept("*")) { parse_power(); emit(Op::kMul, 0, where); }
      else if (accept("/")) { parse_power(); emit(Op::kDiv, 0, where); }
      else if (accept("%")) { parse_power(); emit(Op::kIntRem, 0, where); }
      else return;
    }
  }
  void parse_power() {
    parse_unary();
    for (;;) {
      skip_space();
      const size_t where = pos_;
      if (!accept("^")) return;
      parse_unary();
      emit(Op::kPow, 0, where);
    }
  }
  // Every parenthesis, call and unary operator nests the recursion one level deeper.
  void parse_unary() {
    skip_space();
    const size_t where = pos_;
    if (++nesting_ > kMaxNesting) fail(where, "expression too deeply nested");
    if (accept("-")) { parse_unary(); emit(Op::kNeg, 0, where); }
    else if (accept("+")) parse_unary();
    else if (peek() == '!' && peek(1) != '=') { ++pos_; parse_unary(); emit(Op::kNot, 0, where); }
    else parse_primary();
    --nesting_;
  }
  void parse_primary() {
    skip_space();
    const size_t start = pos_;
    const char c = peek();
    if (std::isdigit(static_cast<unsigned char>(c)) ||
        (c == '.' && std::isdigit(static_cast<unsigned char>(peek(1))))) {
      parse_number();
    } else if (std::isalpha(static_cast<unsigned char>(c)) || c == '_') {
      while (std::isalnum(static_cast<unsigned char>(peek())) || peek() == '_') ++pos_;
      const std::string name(text_.substr(start, pos_ - start));
      if (peek() == '(') {
        parse_call(name, start);
      } else if (const ArrayDecl* array = array_named(name)) {
        parse_index(*array, start);
        emit(Op::kLoadElem, array->base, start);
      } else {
        parse_name(name, start);
      }
    } else if (accept("(")) {
      parse_conditional();
      skip_space();
      if (!accept(")")) fail(pos_, "expected ')' to close the '(' at column " +
                                       std::to_string(start + 1) + ", got " + describe_next());
    } else {
      fail(pos_, "expected a number, a name or '(', got " + describe_next());
    }
  }
  void parse_number() {
    const size_t start = pos_;
    while (std::isdigit(static_cast<unsigned char>(peek()))) ++pos_;
    if (peek() == '.') {
      ++pos_;
      while (std::isdigit(static_cast<unsigned char>(peek()))) ++pos_;
    }
    if ((peek() == 'e' || peek() == 'E') &&
        (std::isdigit(static_cast<unsigned char>(peek(1))) ||
         ((peek(1) == '-' || peek(1) == '+') && std::isdigit(static_cast<unsigned char>(peek(2)))))) {
      pos_ += 2;
      while (std::isdigit(static_cast<unsigned char>(peek()))) ++pos_;
    }
    // strtod, not stod: an overflow gives inf (reported below) instead of an exception.
    const double value = std::strtod(std::string(text_.substr(start, pos_ - start)).c_str(), nullptr);
    if (!std::isfinite(value)) fail(start, "number out of range");
    emit_constant(value, start);
  }
  static int index_of(const std::vector<std::string>* names, const std::string& name) {
    if (!names) return -1;
    const auto it = std::find(names->begin(), names->end(), name);
    return it == names->end() ? -1 : static_cast<int>(it - names->begin());
  }
  const ArrayDecl* array_named(const std::string& name) const {
    for (const ArrayDecl& array : program_.arrays)
      if (array.name == name) return &array;
    return nullptr;
  }
  // "[i][j]" or "[i, j]" after an array's name => its row-major element number on the stack,
  // each index truncated and checked against its dimension when evaluated.
  void parse_index(const ArrayDecl& array, size_t start) {
    skip_space();
    if (!accept("[")) fail(pos_, "expected '[' after the array '" + array.name + "', got " + describe_next());
    for (size_t d = 0; d < array.dims.size(); ++d) {
      if (d > 0) {
        const size_t where = pos_;
        if (!accept(",") && !(accept("]") && accept("[")))
          fail(where, "expected " + indices(array) + ", got " + describe_next());
        emit_constant(array.dims[d], where);
        emit(Op::kMul, 0, where);
      }
      const size_t where = (skip_space(), pos_);
      parse_conditional();
      emit(Op::kIndex, array.dims[d], where);
      if (d > 0) emit(Op::kAdd, 0, where);
    }
    skip_space();
    if (!accept("]"))
      fail(pos_, "expected ']' after the " + indices(array) + " (at column " + std::to_string(start + 1) + "), got " +
                     describe_next());
  }
  static std::string indices(const ArrayDecl& array) {
    return std::to_string(array.dims.size()) + (array.dims.size() == 1 ? " index" : " indices") + " of '" +
           array.name + "'";
  }
  void parse_name(const std::string& name, size_t start) {
    if (const int slot = index_of(scope_.formals, name); slot >= 0) {
      emit(Op::kParam, static_cast<uint32_t>(slot), start);
      return;
    }
    if (const int variable = index_of(scope_.variables, name); variable >= 0) {
      emit(Op::kLoadVar, static_cast<uint32_t>(variable) + 1, start);
      return;
    }
    if (scope_.defines)
      for (const auto& [define, value] : *scope_.defines)
        if (define == name) {
          emit_constant(value, start);
          return;
        }
    // A view-file function's name stands for its number, as in func(BRANCH_ANGLE, x).
    for (size_t f = 0; f < program_.functions.size(); ++f)
      if (!name.empty() && program_.functions[f].name == name) {
        emit_constant(static_cast<double>(f + 1), start);
        return;
      }
    fail(start, "unknown name '" + name + "'" + known_names(name));
  }
  // " (expected a formal parameter (l, w) or a #define (r1, r2); did you mean 'r1'?)"
  std::string known_names(const std::string& name) const {
    std::vector<std::string> candidates;
    std::string list;
    auto add_all = [&](const std::vector<std::string>& all, const char* what) {
      std::vector<std::string> names;  // without arrays' elements after the first (unnamed)
      std::copy_if(all.begin(), all.end(), std::back_inserter(names), [](const std::string& n) { return !n.empty(); });
      if (names.empty()) return;
      list += std::string(list.empty() ? "" : " or ") + what + " (";
      for (size_t i = 0; i < names.size(); ++i) list += (i ? ", " : "") + names[i];
      list += ")";
      candidates.insert(candidates.end(), names.begin(), names.end());
    };
    if (scope_.formals) add_all(*scope_.formals, "a formal parameter");
    if (scope_.variables) add_all(*scope_.variables, "a variable");
    std::vector<std::string> defines;
    if (scope_.defines)
      for (const auto& entry : *scope_.defines) defines.push_back(entry.first);
    add_all(defines, "a define");
    if (list.empty()) return " (no formal parameters or defines are visible here)";
    const std::string near = suggestion(name, candidates);
    return " (expected " + list + (near.empty() ? "" : "; did you mean '" + near + "'?") + ")";
  }
  // The `noun` ("format string") of `function`, a string "..." at pos() (after spaces) => its
  // text, the escapes \n \t \" \\ undone.
  std::string parse_string(const std::string& noun, const std::string& function, size_t start) {
    skip_space();
    if (peek() != '"') fail(pos_, "expected a " + noun + " \"...\" in " + function + "(), got " + describe_next());
    std::string out;
    for (++pos_; pos_ < text_.size() && text_[pos_] != '"'; ++pos_) {
      if (text_[pos_] != '\\' || pos_ + 1 >= text_.size()) {
        out += text_[pos_];
        continue;
      }
      const char escaped = text_[++pos_];
      out += escaped == 'n' ? '\n' : escaped == 't' ? '\t' : escaped;
    }
    if (pos_ >= text_.size()) fail(start, "the " + noun + " of " + function + " is never closed (expected '\"')");
    ++pos_;
    return out;
  }
  // printf("format", values...) (CPFG manual 5.4): its values are computed and nothing is
  // printed (the output streams are treeanim's own); its value is 0.
  void parse_printf(size_t start) {
    ++pos_;  // '('
    parse_string("format string", "printf", start);
    while (accept(",")) {
      parse_conditional();
      emit(Op::kPop, 0, start);
    }
    expect(")", "to close printf(");
    emit_constant(0.0, start);
  }
  // fopen(name, "r") (CPFG manual 5.4), in a block: the file, found beside the grammar, is read
  // now; each call rewinds it and its value is the file's id. Writing is refused.
  void parse_fopen(size_t start) {
    if (!statements_ || !statements_->read_data_file)
      fail(start, "fopen opens a file in a block of statements of a grammar file (Start: { fp = fopen(\"data.txt\", \"r\"); })");
    ++pos_;  // '('
    const size_t name_at = (skip_space(), pos_);
    const std::string name = parse_string("file name", "fopen", start);
    expect(",", "after the file name of fopen");
    const size_t mode_at = (skip_space(), pos_);
    const std::string mode = parse_string("mode", "fopen", start);
    expect(")", "to close fopen(");
    if (mode != "r" && mode != "rt" && mode != "rb")
      fail(mode_at, "fopen(..., \"" + mode + "\") writes a file, which is not supported: a grammar must not write files "
                    "on a render farm (CPFG manual 5.4; fopen(name, \"r\") reads a data file beside the grammar)");
    const std::string text = statements_->read_data_file(name, at(name_at));
    program_.files.push_back({text, new_global()});
    emit(Op::kFopen, static_cast<uint32_t>(program_.files.size() - 1), start);
  }
  // fscan(file, "format", &x, &y...) (CPFG manual 5.4), in a block: C's fscanf for numbers. The
  // targets' values go through hidden globals, which keep a target's value when nothing is read
  // into it; its value is the number of values read (-1 at the end of the file).
  void parse_fscan(size_t start) {
    if (!statements_) fail(start, "fscan reads into variables in a block of statements (\"{ n = fscan(fp, \"%f\", &x); }\")");
    ++pos_;  // '('
    parse_conditional();
    expect(",", "after the file of fscan");
    const size_t format_at = (skip_space(), pos_);
    ScanCall scan{parse_string("format string", "fscan", start), 0, 0};
    if (const std::string wrong = check_scan_format(scan.format); !wrong.empty()) fail(format_at, "fscan: " + wrong);
    std::vector<std::pair<std::string, size_t>> targets;
    while (accept(",")) {
      skip_space();
      accept("&");
      const size_t name_at = (skip_space(), pos_);
      while (std::isalnum(static_cast<unsigned char>(peek())) || peek() == '_') ++pos_;
      if (pos_ == name_at || std::isdigit(static_cast<unsigned char>(text_[name_at])) ||
          array_named(std::string(text_.substr(name_at, pos_ - name_at))))
        fail(name_at, "expected a variable '&name' to read into (fscan reads into variables, not array elements)");
      targets.emplace_back(std::string(text_.substr(name_at, pos_ - name_at)), name_at);
    }
    expect(")", "to close fscan(");
    size_t conversions = 0;
    for (size_t k = 0; k + 1 < scan.format.size(); ++k)
      if (scan.format[k] == '%' && scan.format[k + 1] != '%' && scan.format[k + 1] != '*') ++conversions;
      else if (scan.format[k] == '%') ++k;
    if (targets.size() != conversions)
      fail(start, "fscan's format converts " + plural(static_cast<int>(conversions), "value") + " into " +
                      plural(static_cast<int>(targets.size()), "variable"));
    scan.values = static_cast<uint32_t>(targets.size());
    for (size_t t = 0; t < targets.size(); ++t) {
      const uint32_t hidden = new_global();
      if (t == 0) scan.first_variable = hidden;
      load_target(targets[t].first, targets[t].second);
      emit(Op::kStoreVar, hidden, targets[t].second);
    }
    program_.scans.push_back(scan);
    emit(Op::kFscan, static_cast<uint32_t>(program_.scans.size() - 1), start);
    for (size_t t = 0; t < targets.size(); ++t) {
      emit(Op::kLoadVar, scan.first_variable + static_cast<uint32_t>(t), targets[t].second);
      emit_store(targets[t].first, targets[t].second);
    }
  }
  // A variable the grammar cannot name (its name is empty) => its variables index.
  uint32_t new_global() {
    statements_->globals->push_back("");
    return static_cast<uint32_t>(statements_->globals->size());
  }
  // The value of fscan's target `name` (0 for a variable its assignment creates).
  void load_target(const std::string& name, size_t where) {
    if (const int slot = index_of(statements_->locals, name); slot >= 0) return emit(Op::kParam, static_cast<uint32_t>(slot), where);
    if (const int variable = index_of(statements_->globals, name); variable >= 0)
      return emit(Op::kLoadVar, static_cast<uint32_t>(variable) + 1, where);
    emit_constant(0.0, where);
  }
  void parse_call(const std::string& name, size_t start) {
    if (name == "printf") return parse_printf(start);
    if (name == "fopen") return parse_fopen(start);
    if (name == "fscan" || name == "fscanf") return parse_fscan(start);
    if (name == "fprintf")
      fail(start, "fprintf writes to a file, which is not supported: a grammar must not write files on a render farm "
                  "(CPFG manual 5.4; printf computes its values and prints nothing)");
    if (name == "fclose" || name == "fflush") {
      ++pos_;  // '('
      parse_conditional();
      expect(")", ("to close " + name + "(").c_str());
      if (name == "fclose") return emit(Op::kFclose, 0, start);
      emit(Op::kPop, 0, start);  // reading needs no flushing
      return emit_constant(0.0, start);
    }
    const Function* function = nullptr;
    for (const Function& f : kFunctions)
      if (name == f.name) function = &f;
    if (!function) {
      // cpfg's simulation and view functions (CPFG manual 5.6): a bake has neither to act on.
      for (const char* cpfg : {"stop", "inblob", "vvXmin", "vvYmin", "vvZmin", "vvXmax", "vvYmax", "vvZmax"})
        if (name == cpfg)
          fail(start, "'" + name + "' (CPFG manual 5.6) is not supported: a bake derives lsystem.iterations steps "
                      "and has no view volume (docs/grammar.md)");
      std::vector<std::string> names;
      for (const Function& f : kFunctions) names.emplace_back(f.name);
      const std::string near = suggestion(name, names);
      fail(start, "unknown function '" + name + "'" +
                      (near.empty() ? "" : " (did you mean '" + near + "'?)"));
    }
    ++pos_;  // '('
    int count = 0;
    size_t first_argument_end = 0;
    skip_space();
    if (!accept(")")) {
      for (;;) {
        parse_conditional();
        if (++count == 1) first_argument_end = program_.code.size();
        skip_space();
        if (accept(")")) break;
        if (!accept(",")) fail(pos_, "expected ',' or ')' in the arguments of " + name + ", got " +
                                         describe_next());
      }
    }
    if (count != function->arity)
      fail(start, name + " expects " + plural(function->arity, "argument") + ", got " +
                      std::to_string(count));
    uint32_t arg = 0;
    if (function->op == Op::kFunc) arg = view_number(first_argument_end, start, name, program_.functions.size(), "function:");
    if (function->op == Op::kCurveLength) arg = view_number(first_argument_end, start, name, program_.curves.size(), "curve:");
    if (function->op == Op::kCurve)  // curveX, curveY, curveZ: coordinate 0, 1, 2 of the curve
      arg = 3 * view_number(first_argument_end, start, name, program_.curves.size(), "curve:") +
            static_cast<uint32_t>(name.back() - 'X');
    emit(function->op, arg, start);
  }
  // func(id, x), curveX(id, t)...: id, the code ending at first_argument_end, must be a constant
  // numbering one of the view file's `count` functions (or a function's name, parse_name) or
  // curves => its index.
  uint32_t view_number(size_t first_argument_end, size_t start, const std::string& name, size_t count,
                       const char* lines) const {
    const Instruction id = program_.code[first_argument_end - 1];
    const double value = id.op == Op::kConst ? program_.constants[id.arg] : -1.0;
    if (id.op != Op::kConst || value != std::floor(value) || value < 1 || value > double(count))
      fail(start, name + " expects a constant number 1 ... " + std::to_string(count) + " (the view file's '" + lines +
                      "' lines" + (count ? ")" : ": it has none)"));
    return static_cast<uint32_t>(value) - 1;
  }

  // --- statements (cpfg manual 3.2) ---
  void expect(std::string_view token, const char* what) {
    skip_space();
    if (!accept(token)) fail(pos_, "expected '" + std::string(token) + "' " + what + ", got " + describe_next());
  }
  void parse_block() {
    if (++nesting_ > kMaxNesting) fail(pos_, "statements too deeply nested");
    expect("{", "to open a block of statements");
    for (;;) {
      skip_space();
      if (accept("}")) break;
      if (pos_ >= text_.size()) fail(pos_, "expected '}' to close the block of statements, got the end of the text");
      parse_statement();
    }
    --nesting_;
  }
  void parse_condition_in_parentheses(const char* keyword) {
    expect("(", (std::string("after '") + keyword + "'").c_str());
    parse_conditional();
    expect(")", (std::string("to close the condition of '") + keyword + "'").c_str());
  }
  bool accept_keyword(std::string_view word) {
    skip_space();
    if (text_.substr(pos_, word.size()) != word) return false;
    const char next = pos_ + word.size() < text_.size() ? text_[pos_ + word.size()] : '\0';
    if (std::isalnum(static_cast<unsigned char>(next)) || next == '_') return false;
    pos_ += word.size();
    return true;
  }
  void parse_statement() {
    skip_space();
    const size_t start = pos_;
    if (accept_keyword("if")) {
      parse_condition_in_parentheses("if");
      const size_t skip_then = emit_jump(Op::kJumpIfZero, start);
      parse_block();
      if (accept_keyword("else")) {
        const size_t skip_else = emit_jump(Op::kJump, start);
        land(skip_then);
        parse_block();
        land(skip_else);
      } else {
        land(skip_then);
      }
    } else if (accept_keyword("while")) {
      const size_t top = program_.code.size();
      barrier_ = top;
      parse_condition_in_parentheses("while");
      const size_t exit = emit_jump(Op::kJumpIfZero, start);
      parse_block();
      emit(Op::kJump, static_cast<uint32_t>(top), start);
      land(exit);
    } else if (accept_keyword("do")) {
      const size_t top = program_.code.size();
      barrier_ = top;
      parse_block();
      if (!accept_keyword("while")) fail(pos_, "expected 'while' after the block of 'do', got " + describe_next());
      parse_condition_in_parentheses("while");
      const size_t exit = emit_jump(Op::kJumpIfZero, start);
      emit(Op::kJump, static_cast<uint32_t>(top), start);
      land(exit);
      skip_space();
      accept(";");
    } else {
      parse_simple_statement(start);
    }
  }
  // "name = expression;" or "call(...);".
  void parse_simple_statement(size_t start) {
    const char c = peek();
    if (!(std::isalpha(static_cast<unsigned char>(c)) || c == '_'))
      fail(start, "expected a statement (an assignment 'name = expression;', if, while or do), got " + describe_next());
    while (std::isalnum(static_cast<unsigned char>(peek())) || peek() == '_') ++pos_;
    const std::string name(text_.substr(start, pos_ - start));
    skip_space();
    if (const ArrayDecl* array = array_named(name); array && peek() == '[') {
      parse_index(*array, start);
      expect("=", ("to assign an element of '" + name + "'").c_str());
      parse_conditional();
      emit(Op::kStoreElem, array->base, start);
    } else if (peek() == '=' && peek(1) != '=') {
      ++pos_;
      parse_conditional();
      emit_store(name, start);
    } else {
      pos_ = start;
      parse_conditional();
      emit(Op::kPop, 0, start);
    }
    expect(";", "after the statement");
  }
  void emit_store(const std::string& name, size_t start) {
    if (scope_.defines)
      for (const auto& entry : *scope_.defines)
        if (entry.first == name) fail(start, "'" + name + "' is a #define constant and cannot be assigned");
    std::vector<std::string>* locals = statements_->locals;
    std::vector<std::string>* globals = statements_->globals;
    int slot = index_of(locals, name);
    if (slot >= 0) return emit(Op::kStoreParam, static_cast<uint32_t>(slot), start);
    int variable = index_of(globals, name);
    if (variable < 0 && statements_->assign_globals) {
      globals->push_back(name);
      variable = static_cast<int>(globals->size()) - 1;
    }
    if (variable >= 0) return emit(Op::kStoreVar, static_cast<uint32_t>(variable) + 1, start);
    if (!locals) fail(start, "cannot assign '" + name + "' here");
    if (locals->size() >= kMaxLocals) fail(start, "more than 64 parameters and local variables in one rule");
    locals->push_back(name);
    emit(Op::kStoreParam, static_cast<uint32_t>(locals->size() - 1), start);
  }

  ExprProgram& program_;
  std::string_view text_;
  size_t pos_;
  const TextOrigin& line_;
  const ExprScope& scope_;
  const StatementScope* statements_ = nullptr;  // set while compiling a block
  int depth_ = 0;    // operand stack depth after the code emitted so far
  int nesting_ = 0;  // recursion depth of parse_unary and blocks (bounds the parser's own stack)
  size_t barrier_ = 0;  // code before this index is a jump target's past: never folded into
  static constexpr int kMaxNesting = 256;
  static constexpr size_t kMaxLocals = 64;  // slots of one rule (derive.cpp's kMaxSlots)
};

// Beta(a, b) by two gamma draws (Marsaglia and Tsang; a shape below 1 boosted by u^(1/a)).
double gamma_draw(double shape, RandomStream& random) {
  const double boost = shape < 1.0 ? std::pow(1.0 - random.uniform(), 1.0 / shape) : 1.0;
  const double d = (shape < 1.0 ? shape + 1.0 : shape) - 1.0 / 3.0;
  const double c = 1.0 / std::sqrt(9.0 * d);
  for (;;) {
    const double x = random.normal();
    const double v = std::pow(1.0 + c * x, 3);
    if (v <= 0) continue;
    const double u = 1.0 - random.uniform();
    if (std::log(u) < 0.5 * x * x + d - d * v + d * std::log(v)) return d * v * boost;
  }
}

// samples of f on [0, 1], x => f(x), linear between samples, clamped at the ends (cpfg 5.5).
double sample_function(const std::vector<double>& samples, double x) {
  const double t = std::clamp(x, 0.0, 1.0) * static_cast<double>(samples.size() - 1);
  const size_t k = std::min(static_cast<size_t>(t), samples.size() - 2);
  return samples[k] + (t - static_cast<double>(k)) * (samples[k + 1] - samples[k]);
}

std::string format_number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", v);
  return text;
}

[[noreturn]] void eval_fail(const ExprProgram& program, uint32_t instruction, const char* message) {
  throw EvalError{program.code_pos[instruction], message};
}

// The file an fopen returned `id` for.
const DataFile& data_file(const ExprProgram& program, uint32_t instruction, double id) {
  if (!(id >= 1 && id <= static_cast<double>(program.files.size())))
    throw EvalError{program.code_pos[instruction], "expected a file that fopen opened, got " + format_number(id)};
  return program.files[static_cast<size_t>(id) - 1];
}

}  // namespace

bool ExprProgram::is_constant(const Expr& expr, double* value) const {
  if (expr.end != expr.begin + 1 || code[expr.begin].op != Op::kConst) return false;
  *value = constants[code[expr.begin].arg];
  return true;
}

Expr compile_expression(ExprProgram& program, std::string_view text, size_t* pos,
                        const TextOrigin& line, const ExprScope& scope) {
  Compiler compiler(program, text, *pos, line, scope);
  const Expr expr = compiler.compile();
  *pos = compiler.pos();
  return expr;
}

Expr constant_expression(ExprProgram& program, double value, SourcePos pos) {
  program.constants.push_back(value);
  const auto begin = static_cast<uint32_t>(program.code.size());
  program.code.push_back({Op::kConst, static_cast<uint32_t>(program.constants.size() - 1)});
  program.code_pos.push_back(pos);
  return {begin, begin + 1, pos};
}

Expr compile_block(ExprProgram& program, std::string_view text, size_t* pos, const TextOrigin& line,
                   const StatementScope& scope) {
  const ExprScope names{scope.locals, scope.defines, scope.globals};
  Compiler compiler(program, text, *pos, line, names);
  const Expr block = compiler.compile_block(scope);
  *pos = compiler.pos();
  return block;
}

namespace {

// The loop turns left to the evaluations on this thread (start_loop_budget). One thread grows a
// tree, so whether a derivation runs out is the same for any thread count.
thread_local uint64_t loop_turns_left = kMaxLoopTurnsInAll;

// The interpreter of expressions and blocks; slots are written only by blocks' stores.
// Inlined into evaluate and execute: a call between them cost the derivation benchmark 1.5 % of
// its instructions (docs/grammar.md, "Speed").
[[gnu::always_inline]] inline double run(const ExprProgram& program, const Expr& expr, double* slots, RandomStream& random,
           double* variables) {
  double stack[kMaxExprStack];
  int top = -1;
  uint64_t jumps_back = 0;
  const Instruction* code = program.code.data();
  for (uint32_t k = expr.begin; k < expr.end; ++k) {
    const Instruction in = code[k];
    double& a = stack[top > 0 ? top - 1 : 0];  // left operand of a binary operator
    const double b = top >= 0 ? stack[top] : 0.0;
    switch (in.op) {
      case Op::kConst: stack[++top] = program.constants[in.arg]; break;
      case Op::kParam: stack[++top] = slots[in.arg]; break;
      case Op::kAdd: a = a + b; --top; break;
      case Op::kSub: a = a - b; --top; break;
      case Op::kMul: a = a * b; --top; break;
      case Op::kDiv:
        if (b == 0.0) eval_fail(program, k, "division by zero");
        a = a / b; --top; break;
      case Op::kRem:
        if (b == 0.0) eval_fail(program, k, "division by zero");
        a = std::fmod(a, b); --top; break;
      case Op::kIntRem:  // cpfg's (int)a % (int)b, without C's overflow past int
        if (std::trunc(b) == 0.0) eval_fail(program, k, "division by zero ('%' takes whole numbers: its divisor truncates to 0)");
        a = std::fmod(std::trunc(a), std::trunc(b)); --top; break;
      case Op::kPow: a = std::pow(a, b); --top; break;
      case Op::kNeg: stack[top] = -b; break;
      case Op::kNot: stack[top] = b == 0.0 ? 1.0 : 0.0; break;
      case Op::kLt: a = a < b ? 1.0 : 0.0; --top; break;
      case Op::kLe: a = a <= b ? 1.0 : 0.0; --top; break;
      case Op::kGt: a = a > b ? 1.0 : 0.0; --top; break;
      case Op::kGe: a = a >= b ? 1.0 : 0.0; --top; break;
      case Op::kEq: a = a == b ? 1.0 : 0.0; --top; break;
      case Op::kNe: a = a != b ? 1.0 : 0.0; --top; break;
      case Op::kSin: stack[top] = std::sin(b * kDegree); break;
      case Op::kCos: stack[top] = std::cos(b * kDegree); break;
      case Op::kTan: stack[top] = std::tan(b * kDegree); break;
      case Op::kAsin: stack[top] = std::asin(b) / kDegree; break;
      case Op::kAcos: stack[top] = std::acos(b) / kDegree; break;
      case Op::kAtan: stack[top] = std::atan(b) / kDegree; break;
      // cpfg's atan2(x, y) is the angle of the vector (x, y), C's atan2(y, x) (generate.c, tATAN2).
      case Op::kAtan2: a = std::atan2(b, a) / kDegree; --top; break;
      case Op::kSqrt: stack[top] = std::sqrt(b); break;
      case Op::kExp: stack[top] = std::exp(b); break;
      case Op::kLog: stack[top] = std::log(b); break;
      case Op::kAbs: stack[top] = std::abs(b); break;
      case Op::kMin: a = std::min(a, b); --top; break;
      case Op::kMax: a = std::max(a, b); --top; break;
      case Op::kFloor: stack[top] = std::floor(b); break;
      case Op::kCeil: stack[top] = std::ceil(b); break;
      case Op::kTrunc: stack[top] = std::floor(b + 0.5); break;  // cpfg's trunc rounds, halves up (generate.c, tTRUNC)
      case Op::kSign: stack[top] = b > 0.0 ? 1.0 : (b < 0.0 ? -1.0 : 0.0); break;
      case Op::kFunc: a = sample_function(program.functions[in.arg].samples, b); --top; break;
      case Op::kCurve: a = program.curves[in.arg / 3].at(b)[in.arg % 3]; --top; break;
      case Op::kCurveLength: stack[top] = program.curves[in.arg].length; break;
      case Op::kRan: stack[top] = random.uniform() * b; break;
      case Op::kNran: a = a + b * random.normal(); --top; break;
      case Op::kBran: {
        if (!(a > 0.0 && b > 0.0)) eval_fail(program, k, "bran expects two positive shapes");
        const double x = gamma_draw(a, random);
        a = x / (x + gamma_draw(b, random));
        --top;
        break;
      }
      case Op::kBiran: {
        if (!(a >= 0.0 && a <= 1e6)) eval_fail(program, k, "biran expects a count in [0, 1000000]");
        double hits = 0;
        for (int n = static_cast<int>(a); n > 0; --n) hits += random.uniform() < b ? 1.0 : 0.0;
        a = hits;
        --top;
        break;
      }
      case Op::kSrand:
        if (variables) variables[kSrandVariable] = b;
        stack[top] = 0.0;
        break;
      case Op::kLoadVar: stack[++top] = variables ? variables[in.arg] : 0.0; break;
      case Op::kStoreVar: if (variables) variables[in.arg] = b; --top; continue;
      case Op::kStoreParam: slots[in.arg] = b; --top; continue;
      case Op::kPop: --top; continue;
      case Op::kIndex:
        stack[top] = std::trunc(b);
        if (!(stack[top] >= 0.0 && stack[top] < static_cast<double>(in.arg)))
          throw EvalError{program.code_pos[k], "array index " + format_number(b) + " is outside 0 ... " +
                                                    std::to_string(in.arg - 1)};
        break;
      case Op::kLoadElem: stack[top] = variables ? variables[in.arg + static_cast<uint32_t>(b)] : 0.0; break;
      case Op::kStoreElem:
        if (variables) variables[in.arg + static_cast<uint32_t>(a)] = b;
        top -= 2;
        continue;
      case Op::kJumpIfZero:
        --top;
        if (b == 0.0) k = in.arg - 1;
        continue;
      case Op::kFopen:
        if (variables) variables[program.files[in.arg].offset_variable] = 0.0;
        stack[++top] = static_cast<double>(in.arg + 1);
        break;
      case Op::kFclose: {
        const DataFile& file = data_file(program, k, b);
        if (variables) variables[file.offset_variable] = static_cast<double>(file.text.size());
        stack[top] = 0.0;
        break;
      }
      case Op::kFscan: {
        const DataFile& file = data_file(program, k, b);
        const ScanCall& scan = program.scans[in.arg];
        if (!variables) eval_fail(program, k, "fscan reads into variables");
        auto offset = static_cast<size_t>(variables[file.offset_variable]);
        stack[top] = scan_values(file.text, &offset, scan.format, variables + scan.first_variable);
        variables[file.offset_variable] = static_cast<double>(offset);
        break;
      }
      case Op::kJump:
        if (in.arg <= k) {
          if (++jumps_back > kMaxLoopIterations) eval_fail(program, k, "a loop ran more than 10000000 times");
          if (loop_turns_left == 0)
            eval_fail(program, k, "the loops of this derivation ran past the turns it may take in all (10^9: lower "
                                  "lsystem.iterations or the loops' counts)");
          --loop_turns_left;
        }
        k = in.arg - 1;  // the loop's ++k lands on the target
        continue;
    }
    if (!std::isfinite(stack[top]))
      eval_fail(program, k, "the value is not a finite number (a square root or arcsine of an "
                            "out-of-range value, log of 0, or an overflow)");
  }
  return top >= 0 ? stack[0] : 0.0;
}

}  // namespace

void start_loop_budget(uint64_t turns) { loop_turns_left = turns; }

double evaluate(const ExprProgram& program, const Expr& expr, const double* formals,
                RandomStream& random, double* variables) {
  // An expression only reads its slots; stores come from blocks (compile_block).
  return run(program, expr, const_cast<double*>(formals), random, variables);
}

void execute(const ExprProgram& program, const Expr& block, double* slots, RandomStream& random,
             double* variables) {
  run(program, block, slots, random, variables);
}

}  // namespace treeanim
