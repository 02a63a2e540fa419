#include "lsystem/expression.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <numbers>

#include "common/did_you_mean.h"

namespace treeanim {

namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

uint64_t mix64(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

struct Function {
  const char* name;
  Op op;
  int arity;
};

constexpr std::array<Function, 17> kFunctions{{
    {"sin", Op::kSin, 1},   {"cos", Op::kCos, 1},     {"tan", Op::kTan, 1},
    {"asin", Op::kAsin, 1}, {"acos", Op::kAcos, 1},   {"atan", Op::kAtan, 1},
    {"atan2", Op::kAtan2, 2}, {"sqrt", Op::kSqrt, 1}, {"exp", Op::kExp, 1},
    {"log", Op::kLog, 1},   {"abs", Op::kAbs, 1},     {"min", Op::kMin, 2},
    {"max", Op::kMax, 2},   {"floor", Op::kFloor, 1}, {"ceil", Op::kCeil, 1},
    {"ran", Op::kRan, 1},   {"nran", Op::kNran, 2},
}};

int arity_of(Op op) {
  switch (op) {
    case Op::kConst: case Op::kParam: return 0;
    case Op::kNeg: case Op::kNot: return 1;
    case Op::kAdd: case Op::kSub: case Op::kMul: case Op::kDiv: case Op::kPow:
    case Op::kLt: case Op::kLe: case Op::kGt: case Op::kGe: case Op::kEq: case Op::kNe:
    case Op::kAnd: case Op::kOr: return 2;
    default: break;
  }
  for (const Function& f : kFunctions)
    if (f.op == op) return f.arity;
  return 0;
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

// Recursive-descent compiler of one expression into program.code (precedence, lowest first:
// || && comparisons +- */ unary ^).
class Compiler {
 public:
  Compiler(ExprProgram& program, std::string_view text, size_t pos, SourcePos line,
           const ExprScope& scope)
      : program_(program), text_(text), pos_(pos), line_(line), scope_(scope) {}

  // => the compiled expression; pos() is left after it.
  Expr compile() {
    Expr expr;
    skip_space();
    expr.pos = at(pos_);
    expr.begin = static_cast<uint32_t>(program_.code.size());
    parse_or();
    expr.end = static_cast<uint32_t>(program_.code.size());
    return expr;
  }
  size_t pos() const { return pos_; }

 private:
  SourcePos at(size_t index) const {
    return {line_.source, line_.line, static_cast<int32_t>(index) + 1};
  }
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
    depth_ += 1 - arity_of(op);
    if (depth_ > kMaxExprStack) fail(where, "expression too deeply nested");
    if (op != Op::kRan && op != Op::kNran && op != Op::kConst && op != Op::kParam) fold(arity_of(op));
  }
  void emit_constant(double value, size_t where) {
    program_.constants.push_back(value);
    emit(Op::kConst, static_cast<uint32_t>(program_.constants.size() - 1), where);
  }
  // When the operands of the instruction just emitted are all constants, replaces them and it
  // by their value (division by zero or a non-finite value is then a compile-time error).
  void fold(int operands) {
    const size_t n = program_.code.size();
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

  void parse_or() {
    parse_and();
    for (;;) {
      const size_t where = (skip_space(), pos_);
      if (!accept("||")) return;
      parse_and();
      emit(Op::kOr, 0, where);
    }
  }
  void parse_and() {
    parse_comparison();
    for (;;) {
      const size_t where = (skip_space(), pos_);
      if (!accept("&&")) return;
      parse_comparison();
      emit(Op::kAnd, 0, where);
    }
  }
  void parse_comparison() {
    parse_sum();
    for (;;) {
      skip_space();
      const size_t where = pos_;
      Op op;
      if (accept("<=")) op = Op::kLe;
      else if (accept(">=")) op = Op::kGe;
      else if (accept("==")) op = Op::kEq;
      else if (accept("!=")) op = Op::kNe;
      else if (peek() == '=') fail(pos_, "expected '==' to compare, got '='");
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
    parse_unary();
    for (;;) {
      skip_space();
      const size_t where = pos_;
      if (accept("*")) { parse_unary(); emit(Op::kMul, 0, where); }
      else if (accept("/")) { parse_unary(); emit(Op::kDiv, 0, where); }
      else return;
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
    else parse_power();
    --nesting_;
  }
  // '^' binds tighter than unary minus (-2^2 = -4) and groups to the right (2^3^2 = 2^9).
  void parse_power() {
    parse_primary();
    skip_space();
    const size_t where = pos_;
    if (accept("^")) {
      parse_unary();
      emit(Op::kPow, 0, where);
    }
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
      if (peek() == '(') parse_call(name, start);
      else parse_name(name, start);
    } else if (accept("(")) {
      parse_or();
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
  void parse_name(const std::string& name, size_t start) {
    if (scope_.formals) {
      const auto& formals = *scope_.formals;
      const auto it = std::find(formals.begin(), formals.end(), name);
      if (it != formals.end()) {
        emit(Op::kParam, static_cast<uint32_t>(it - formals.begin()), start);
        return;
      }
    }
    if (scope_.defines)
      for (const auto& [define, value] : *scope_.defines)
        if (define == name) {
          emit_constant(value, start);
          return;
        }
    fail(start, "unknown name '" + name + "'" + known_names(name));
  }
  // " (expected a formal parameter (l, w) or a #define (r1, r2); did you mean 'r1'?)"
  std::string known_names(const std::string& name) const {
    std::vector<std::string> candidates;
    std::string list;
    auto add_all = [&](const std::vector<std::string>& names, const char* what) {
      if (names.empty()) return;
      list += std::string(list.empty() ? "" : " or ") + what + " (";
      for (size_t i = 0; i < names.size(); ++i) list += (i ? ", " : "") + names[i];
      list += ")";
      candidates.insert(candidates.end(), names.begin(), names.end());
    };
    if (scope_.formals) add_all(*scope_.formals, "a formal parameter");
    std::vector<std::string> defines;
    if (scope_.defines)
      for (const auto& entry : *scope_.defines) defines.push_back(entry.first);
    add_all(defines, "a define");
    if (list.empty()) return " (no formal parameters or defines are visible here)";
    const std::string near = suggestion(name, candidates);
    return " (expected " + list + (near.empty() ? "" : "; did you mean '" + near + "'?") + ")";
  }
  void parse_call(const std::string& name, size_t start) {
    const Function* function = nullptr;
    for (const Function& f : kFunctions)
      if (name == f.name) function = &f;
    if (!function) {
      std::vector<std::string> names;
      for (const Function& f : kFunctions) names.emplace_back(f.name);
      const std::string near = suggestion(name, names);
      fail(start, "unknown function '" + name + "'" +
                      (near.empty() ? "" : " (did you mean '" + near + "'?)"));
    }
    ++pos_;  // '('
    int count = 0;
    skip_space();
    if (!accept(")")) {
      for (;;) {
        parse_or();
        ++count;
        skip_space();
        if (accept(")")) break;
        if (!accept(",")) fail(pos_, "expected ',' or ')' in the arguments of " + name + ", got " +
                                         describe_next());
      }
    }
    if (count != function->arity)
      fail(start, name + " expects " + plural(function->arity, "argument") + ", got " +
                      std::to_string(count));
    emit(function->op, 0, start);
  }

  ExprProgram& program_;
  std::string_view text_;
  size_t pos_;
  SourcePos line_;
  const ExprScope& scope_;
  int depth_ = 0;    // operand stack depth after the code emitted so far
  int nesting_ = 0;  // recursion depth of parse_unary (bounds the parser's own stack)
  static constexpr int kMaxNesting = 256;
};

[[noreturn]] void eval_fail(const ExprProgram& program, uint32_t instruction, const char* message) {
  throw EvalError{program.code_pos[instruction], message};
}

}  // namespace

RandomStream RandomStream::keyed(uint64_t seed, uint64_t purpose, uint64_t step, uint64_t position) {
  return {mix64(mix64(mix64(mix64(seed) ^ purpose) ^ step) ^ position)};
}

uint64_t RandomStream::next_u64() {
  state += 0x9e3779b97f4a7c15ULL;
  return mix64(state);
}

double RandomStream::uniform() { return static_cast<double>(next_u64() >> 11) * 0x1.0p-53; }

double RandomStream::normal() {
  const double u1 = 1.0 - uniform();  // (0, 1]: log is finite
  const double u2 = uniform();
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

bool ExprProgram::is_constant(const Expr& expr, double* value) const {
  if (expr.end != expr.begin + 1 || code[expr.begin].op != Op::kConst) return false;
  *value = constants[code[expr.begin].arg];
  return true;
}

Expr compile_expression(ExprProgram& program, std::string_view text, size_t* pos,
                        SourcePos line, const ExprScope& scope) {
  Compiler compiler(program, text, *pos, line, scope);
  const Expr expr = compiler.compile();
  *pos = compiler.pos();
  return expr;
}

double evaluate(const ExprProgram& program, const Expr& expr, const double* formals,
                RandomStream& random) {
  double stack[kMaxExprStack];
  int top = -1;
  const Instruction* code = program.code.data();
  for (uint32_t k = expr.begin; k < expr.end; ++k) {
    const Instruction in = code[k];
    double& a = stack[top > 0 ? top - 1 : 0];  // left operand of a binary operator
    const double b = top >= 0 ? stack[top] : 0.0;
    switch (in.op) {
      case Op::kConst: stack[++top] = program.constants[in.arg]; break;
      case Op::kParam: stack[++top] = formals[in.arg]; break;
      case Op::kAdd: a = a + b; --top; break;
      case Op::kSub: a = a - b; --top; break;
      case Op::kMul: a = a * b; --top; break;
      case Op::kDiv:
        if (b == 0.0) eval_fail(program, k, "division by zero");
        a = a / b; --top; break;
      case Op::kPow: a = std::pow(a, b); --top; break;
      case Op::kNeg: stack[top] = -b; break;
      case Op::kNot: stack[top] = b == 0.0 ? 1.0 : 0.0; break;
      case Op::kLt: a = a < b ? 1.0 : 0.0; --top; break;
      case Op::kLe: a = a <= b ? 1.0 : 0.0; --top; break;
      case Op::kGt: a = a > b ? 1.0 : 0.0; --top; break;
      case Op::kGe: a = a >= b ? 1.0 : 0.0; --top; break;
      case Op::kEq: a = a == b ? 1.0 : 0.0; --top; break;
      case Op::kNe: a = a != b ? 1.0 : 0.0; --top; break;
      case Op::kAnd: a = (a != 0.0 && b != 0.0) ? 1.0 : 0.0; --top; break;
      case Op::kOr: a = (a != 0.0 || b != 0.0) ? 1.0 : 0.0; --top; break;
      case Op::kSin: stack[top] = std::sin(b * kDegree); break;
      case Op::kCos: stack[top] = std::cos(b * kDegree); break;
      case Op::kTan: stack[top] = std::tan(b * kDegree); break;
      case Op::kAsin: stack[top] = std::asin(b) / kDegree; break;
      case Op::kAcos: stack[top] = std::acos(b) / kDegree; break;
      case Op::kAtan: stack[top] = std::atan(b) / kDegree; break;
      case Op::kAtan2: a = std::atan2(a, b) / kDegree; --top; break;
      case Op::kSqrt: stack[top] = std::sqrt(b); break;
      case Op::kExp: stack[top] = std::exp(b); break;
      case Op::kLog: stack[top] = std::log(b); break;
      case Op::kAbs: stack[top] = std::abs(b); break;
      case Op::kMin: a = std::min(a, b); --top; break;
      case Op::kMax: a = std::max(a, b); --top; break;
      case Op::kFloor: stack[top] = std::floor(b); break;
      case Op::kCeil: stack[top] = std::ceil(b); break;
      case Op::kRan: stack[top] = random.uniform() * b; break;
      case Op::kNran: a = a + b * random.normal(); --top; break;
    }
    if (!std::isfinite(stack[top]))
      eval_fail(program, k, "the value is not a finite number (a square root or arcsine of an "
                            "out-of-range value, log of 0, or an overflow)");
  }
  return stack[0];
}

}  // namespace treeanim
