#pragma once
// Arithmetic expressions of parametric L-systems (docs/grammar.md), compiled once into a small
// stack bytecode and evaluated without allocation in the derivation's inner loop.
//
// Rejected alternative: an AST walked recursively; the flat bytecode is smaller, has no
// pointers to chase, and makes constant folding a matter of looking at the last instructions.
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "common/random.h"
#include "lsystem/data_file.h"
#include "lsystem/view_curve.h"

namespace treeanim {

// A place in a grammar source. line 0 marks a one-line source (an inline scene rule),
// reported as "name, column N".
struct SourcePos {
  int32_t source = 0;  // index into Grammar::sources
  int32_t line = 0;    // 1-based; 0 for a one-line source
  int32_t column = 0;  // 1-based byte column
};

// Where the characters of a text come from: column index + 1 of `line`, or per character
// (a statement joined from several lines, or with #define macros expanded at their use).
struct TextOrigin {
  SourcePos line;
  const std::vector<SourcePos>* columns = nullptr;  // (text size) when present
  TextOrigin(SourcePos l) : line(l) {}  // NOLINT: a plain line converts implicitly
  TextOrigin(SourcePos l, const std::vector<SourcePos>* c) : line(l), columns(c) {}
  SourcePos at(size_t index) const {
    if (!columns) return {line.source, line.line, static_cast<int32_t>(index) + 1};
    if (columns->empty()) return line;
    if (index < columns->size()) return (*columns)[index];
    SourcePos past = columns->back();  // past the end: the columns after the last character
    past.column += static_cast<int32_t>(index - columns->size()) + 1;
    return past;
  }
};

// A syntax or semantic error found while reading a grammar; load_grammar turns it into an
// InputError "file:line:column: message".
struct GrammarError {
  SourcePos pos;
  std::string message;
};

enum class Op : uint8_t {
  kConst, kParam,                                  // push constants[arg] / formals[arg]
  kAdd, kSub, kMul, kDiv, kPow,                    // binary arithmetic
  kNeg, kNot,                                      // unary
  kLt, kLe, kGt, kGe, kEq, kNe,                    // comparisons: 1 or 0 (&& and || are jumps)
  kSin, kCos, kTan, kAsin, kAcos, kAtan, kAtan2,   // degrees
  kSqrt, kExp, kLog, kAbs, kMin, kMax, kFloor, kCeil,
  kRem, kIntRem, kTrunc, kSign,                    // C's fmod, cpfg's % (of the truncated operands), trunc; sign: -1, 0, 1
  kFunc,                                           // view-file function functions[arg] at x
  kCurve, kCurveLength,                            // curves[arg / 3] coordinate arg % 3 at t; curves[arg] length
  kRan, kNran, kBran, kBiran, kSrand,              // random: never folded
  kLoadVar, kStoreVar, kStoreParam, kPop,          // variables[arg], formals[arg] (statements)
  kIndex, kLoadElem, kStoreElem,                   // array index < arg; variables[arg + index]
  kJump, kJumpIfZero,                              // to code[arg] (?:, if, while)
  kFopen, kFclose, kFscan,                         // files[arg] rewound; a file closed; scans[arg] read
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

// A cpfg array (manual 2.2.2): its elements are global variables base, base + 1, ... in row-major order.
struct ArrayDecl {
  std::string name;
  uint32_t base = 0;            // variables index of element 0
  std::vector<uint32_t> dims;   // sizes of its dimensions
};

// A view-file function (funcedit, CPFG manual 8.1.6): its name and y sampled at equally
// spaced x on [0, 1].
struct SampledFunction {
  std::string name;             // its "name:" line; empty in the older format without one
  std::vector<double> samples;  // (samples) y at x = k / (samples - 1)
};

// The code of every expression of one grammar.
struct ExprProgram {
  std::vector<Instruction> code;     // (instructions)
  std::vector<SourcePos> code_pos;   // (instructions) the operator's place, for runtime errors
  std::vector<double> constants;     // (constants)
  std::vector<SampledFunction> functions;  // func(id, x): the view file's functions, id 1, 2, ...
  std::vector<ViewCurve> curves;     // curveX(id, t) ... curveGAL(id): the view file's curves, id 1, 2, ...
  std::vector<ArrayDecl> arrays;     // names the compiler resolves to array elements
  std::vector<DataFile> files;       // fopen(name, "r"): file id k + 1 is files[k]
  std::vector<ScanCall> scans;       // fscan(file, "format", &x, ...) calls
  // expr => true when it is one constant (its value in *value).
  bool is_constant(const Expr& expr, double* value) const;
};

// Thrown by evaluate on a runtime error; the deriver adds the step and the production.
struct EvalError {
  SourcePos pos;
  std::string message;
};

// Names an expression may use: the production's formal parameters and local variables
// (which shadow the rest), the grammar's global variables, then its defines (numbers).
struct ExprScope {
  const std::vector<std::string>* formals = nullptr;
  const std::vector<std::pair<std::string, double>>* defines = nullptr;
  const std::vector<std::string>* variables = nullptr;  // globals: variables[i] is slot i
};

// Where statements put a name assigned for the first time (cpfg manual 2.2.1): a production's
// block makes it local (a slot after the formals), a Start/End block global.
struct StatementScope {
  std::vector<std::string>* locals = nullptr;     // the rule's formals, then its locals
  std::vector<std::string>* globals = nullptr;    // the grammar's variables
  bool assign_globals = false;                    // true in Start/StartEach/EndEach/End blocks
  const std::vector<std::pair<std::string, double>>* defines = nullptr;
  // fopen(name, "r") at pos => the text of the file `name` beside the grammar (throws GrammarError).
  std::function<std::string(const std::string& name, SourcePos pos)> read_data_file;
};

// Deepest operand stack an expression may need; deeper ones are rejected when compiled.
constexpr int kMaxExprStack = 32;

// (text, *pos at the expression's first character) => compiled Expr; *pos is left on the first
// character that cannot continue the expression (',' ')' ':' or the end). `line` gives the
// source and line of `text` (column = index + 1). Constant sub-expressions are folded.
// Throws GrammarError.
Expr compile_expression(ExprProgram& program, std::string_view text, size_t* pos,
                        const TextOrigin& line, const ExprScope& scope);

// value => an expression that is this constant (a string parameter's number).
Expr constant_expression(ExprProgram& program, double value, SourcePos pos);

// text at *pos = '{' => the block "{ statement ... }" compiled (cpfg manual 3.2: assignments
// "name = expression;", "if (c) {...} [else {...}]", "while (c) {...}", "do {...} while (c);",
// calls such as "srand(s);"); *pos is left after the closing '}'. Throws GrammarError.
Expr compile_block(ExprProgram& program, std::string_view text, size_t* pos, const TextOrigin& line,
                   const StatementScope& scope);

// Variable 0 holds the last srand() argument (0 until one is made); names start at 1.
constexpr uint32_t kSrandVariable = 0;

// (expr, formal values, random stream, global variables) => value. Throws EvalError on
// division by zero or a non-finite result (sqrt of a negative number, log of 0, overflow).
double evaluate(const ExprProgram& program, const Expr& expr, const double* formals,
                RandomStream& random, double* variables = nullptr);

// Runs a compiled block: it may assign the formals and locals (slots) and the globals
// (variables). Loops stop with an EvalError after kMaxLoopIterations jumps back.
void execute(const ExprProgram& program, const Expr& block, double* slots, RandomStream& random,
             double* variables);
constexpr uint64_t kMaxLoopIterations = 10'000'000;
// And every loop of the evaluations on one thread since start_loop_budget, together: rules that
// each stay under kMaxLoopIterations, applied to a doubling word, would otherwise run for days
// (some 90 ns a turn: the budget is a minute or two).
constexpr uint64_t kMaxLoopTurnsInAll = 1'000'000'000;
// A derivation's start => the loops on this thread have `turns` turns in all from now on.
void start_loop_budget(uint64_t turns);

}  // namespace treeanim
