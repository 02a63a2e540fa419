#pragma once
// Arithmetic expressions of parametric L-systems (docs/grammar.md), compiled once into a small
// stack bytecode and evaluated without allocation in the derivation's inner loop.
//
// Rejected alternative: an AST walked recursively; the flat bytecode is smaller, has no
// pointers to chase, and makes constant folding a matter of looking at the last instructions.
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace treeanim {

// A place in a grammar source. line 0 marks a one-line source (an inline scene rule),
// reported as "name:column".
struct SourcePos {
  int32_t source = 0;  // index into Grammar::sources
  int32_t line = 0;    // 1-based; 0 for a one-line source
  int32_t column = 0;  // 1-based byte column
};

// A syntax or semantic error found while reading a grammar; load_grammar turns it into an
// InputError "file:line:column: message".
struct GrammarError {
  SourcePos pos;
  std::string message;
};

// Counter-based random numbers (splitmix64): the draws of one module in one derivation step
// depend only on (seed, purpose, step, position), never on thread count or evaluation order.
struct RandomStream {
  uint64_t state = 0;
  static RandomStream keyed(uint64_t seed, uint64_t purpose, uint64_t step, uint64_t position);
  uint64_t next_u64();
  double uniform();  // [0, 1)
  double normal();   // mean 0, standard deviation 1 (Box-Muller)
};

enum class Op : uint8_t {
  kConst, kParam,                                  // push constants[arg] / formals[arg]
  kAdd, kSub, kMul, kDiv, kPow,                    // binary arithmetic
  kNeg, kNot,                                      // unary
  kLt, kLe, kGt, kGe, kEq, kNe, kAnd, kOr,         // comparisons and logic: 1 or 0
  kSin, kCos, kTan, kAsin, kAcos, kAtan, kAtan2,   // degrees
  kSqrt, kExp, kLog, kAbs, kMin, kMax, kFloor, kCeil,
  kRan, kNran,                                     // random: never folded
};

struct Instruction {
  Op op;
  uint32_t arg;  // constant or formal index for kConst / kParam
};

// One compiled expression: a range of ExprProgram::code.
struct Expr {
  uint32_t begin = 0;
  uint32_t end = 0;  // begin == end: no expression (a missing condition or probability)
  SourcePos pos;     // where its text starts
  bool present() const { return end > begin; }
};

// The code of every expression of one grammar.
struct ExprProgram {
  std::vector<Instruction> code;     // (instructions)
  std::vector<SourcePos> code_pos;   // (instructions) the operator's place, for runtime errors
  std::vector<double> constants;     // (constants)
  // expr => true when it is one constant (its value in *value).
  bool is_constant(const Expr& expr, double* value) const;
};

// Thrown by evaluate on a runtime error; the deriver adds the step and the production.
struct EvalError {
  SourcePos pos;
  std::string message;
};

// Names an expression may use: the production's formal parameters (which shadow defines),
// then the grammar's defines (already resolved to numbers).
struct ExprScope {
  const std::vector<std::string>* formals = nullptr;
  const std::vector<std::pair<std::string, double>>* defines = nullptr;
};

// Deepest operand stack an expression may need; deeper ones are rejected when compiled.
constexpr int kMaxExprStack = 32;

// (text, *pos at the expression's first character) => compiled Expr; *pos is left on the first
// character that cannot continue the expression (',' ')' ':' or the end). `line` gives the
// source and line of `text` (column = index + 1). Constant sub-expressions are folded.
// Throws GrammarError.
Expr compile_expression(ExprProgram& program, std::string_view text, size_t* pos,
                        SourcePos line, const ExprScope& scope);

// (expr, formal values, random stream) => value. Throws EvalError on division by zero or a
// non-finite result (sqrt of a negative number, log of 0, overflow).
double evaluate(const ExprProgram& program, const Expr& expr, const double* formals,
                RandomStream& random);

}  // namespace treeanim
