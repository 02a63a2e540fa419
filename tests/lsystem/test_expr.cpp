// Expression compiler and evaluator: values against hand-computed results.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "lsystem/expression.h"

namespace treeanim {
namespace {

struct Compiled {
  ExprProgram program;
  Expr expr;
};

const std::vector<std::string> kFormals = {"x", "y"};
const std::vector<std::pair<std::string, double>> kDefines = {{"k", 10.0}, {"x", 99.0}};

// text => compiled over formals (x, y) and the define k (x is also a define: formals win).
Compiled compile(const std::string& text) {
  Compiled c;
  size_t pos = 0;
  c.expr = compile_expression(c.program, text, &pos, SourcePos{0, 1, 0}, ExprScope{&kFormals, &kDefines});
  EXPECT_EQ(pos, text.size()) << text;
  return c;
}

double eval(const std::string& text, double x = 2.0, double y = 3.0) {
  const Compiled c = compile(text);
  const double formals[2] = {x, y};
  RandomStream random = RandomStream::keyed(1, 2, 3, 4);
  return evaluate(c.program, c.expr, formals, random);
}

TEST(Expression, ArithmeticPrecedence) {
  EXPECT_EQ(eval("1+2*3"), 7.0);
  EXPECT_EQ(eval("(1+2)*3"), 9.0);
  // cpfg's precedence (lsys_input.y): ^ groups to the left, unary minus binds tighter.
  EXPECT_EQ(eval("2^3^2"), 64.0);
  EXPECT_EQ(eval("-2^2"), 4.0);
  EXPECT_EQ(eval("-x^2"), 4.0);
  EXPECT_EQ(eval("2^-1"), 0.5);
  EXPECT_EQ(eval("2*3^2"), 18.0);        // ^ before * /
  EXPECT_EQ(eval("!0^2"), 1.0);
  EXPECT_EQ(eval("7-2-1"), 4.0);         // left-associative
  EXPECT_EQ(eval("8/2/2"), 2.0);
  EXPECT_EQ(eval("1/3"), 1.0 / 3.0);
  EXPECT_EQ(eval(".5e1 + 1E-1"), 5.1);
}

// '%' is cpfg's: the remainder of the operands truncated to whole numbers, with the dividend's
// sign as in C; fmod() is C's, of the reals.
TEST(Expression, RemainderTakesWholeNumbersAsCpfg) {
  EXPECT_EQ(eval("7.5 % 2"), 1.0);
  EXPECT_EQ(eval("7 % 2.9"), 1.0);
  EXPECT_EQ(eval("-7 % 3"), -1.0);
  EXPECT_EQ(eval("7 % -3"), 1.0);
  EXPECT_EQ(eval("fmod(7.5, 2)"), 1.5);
  EXPECT_EQ(eval("1e300 % 7"), std::fmod(1e300, 7.0));  // no int to overflow
  EXPECT_EQ(eval("2 * 7 % 4"), 2.0);                     // left to right with * and /
}

TEST(Expression, NamesFormalsShadowDefines) {
  EXPECT_EQ(eval("x*y+k"), 16.0);
  EXPECT_EQ(eval("x", 7.0), 7.0);
}

TEST(Expression, ComparisonsAndLogic) {
  EXPECT_EQ(eval("x < y"), 1.0);
  EXPECT_EQ(eval("x >= y"), 0.0);
  EXPECT_EQ(eval("x == 2 && y != 2"), 1.0);
  EXPECT_EQ(eval("x > 5 || y <= 3"), 1.0);
  EXPECT_EQ(eval("!(x == 2)"), 0.0);
  EXPECT_EQ(eval("!0 + !5"), 1.0);
  EXPECT_EQ(eval("1 + 2 < 4"), 1.0);  // arithmetic before comparison
  EXPECT_EQ(eval("0 == 0 < 5"), 0.0);  // < before ==, as in C and cpfg: 0 == (0 < 5)
  EXPECT_EQ(eval("1 < 2 == 1"), 1.0);
  EXPECT_EQ(eval("3 != 2 > 1"), 1.0);
  // The right operand runs only when the left leaves the answer open, as in C and cpfg.
  EXPECT_EQ(eval("x != 0 && 1 / x > 0", 0.0), 0.0);
  EXPECT_EQ(eval("x == 0 || 1 / x > 0", 0.0), 1.0);
  EXPECT_EQ(eval("x != 0 && 1 / x > 0", 4.0), 1.0);
  EXPECT_EQ(eval("x && y && 0 || y"), 1.0);  // && before ||
  EXPECT_EQ(eval("x && 7"), 1.0);            // 1 or 0, whatever the operands
  EXPECT_EQ(eval("0 || 0 || x - 2"), 0.0);
  EXPECT_EQ(eval("(x || y) + (0 && y) + (3 && 0.5)"), 2.0);
  EXPECT_EQ(eval("x > 1 ? 0 && y : 5 && y"), 0.0);  // a constant left side where a jump lands
  EXPECT_EQ(eval("x > 3 ? 0 && y : 5 && y - 3"), 0.0);
  EXPECT_EQ(eval("x > 3 ? 0 : 5 && y"), 1.0);
}

// A constant left side decides at compile time: such an expression is still a constant.
TEST(Expression, LogicOfConstantsIsFolded) {
  for (const auto& [text, expected] : std::vector<std::pair<std::string, double>>{
           {"1 && 2 || 0", 1.0}, {"0 && k", 0.0}, {"k || 0", 1.0}, {"0 || k > 20", 0.0}, {"!(0 || 0) && 3", 1.0}}) {
    const Compiled c = compile(text);
    double value = -1;
    EXPECT_TRUE(c.program.is_constant(c.expr, &value)) << text;
    EXPECT_EQ(value, expected) << text;
  }
  const Compiled c = compile("1 && x");  // the right side decides: x != 0 at run time
  double value = 0;
  EXPECT_FALSE(c.program.is_constant(c.expr, &value));
  EXPECT_EQ(eval("1 && x", 0.0), 0.0);
  EXPECT_EQ(eval("0 || x", 4.0), 1.0);
}

TEST(Expression, FunctionsInDegrees) {
  EXPECT_NEAR(eval("sin(30)"), 0.5, 1e-15);
  EXPECT_NEAR(eval("cos(60)"), 0.5, 1e-15);
  EXPECT_NEAR(eval("tan(45)"), 1.0, 1e-15);
  EXPECT_NEAR(eval("asin(0.5)"), 30.0, 1e-12);
  EXPECT_NEAR(eval("acos(0.5)"), 60.0, 1e-12);
  EXPECT_NEAR(eval("atan(1)"), 45.0, 1e-12);
  // cpfg's own (generate.c): atan2(x, y) is the angle of the vector (x, y); trunc rounds, halves up.
  EXPECT_NEAR(eval("atan2(1, -1)"), -45.0, 1e-12);
  EXPECT_NEAR(eval("atan2(-1, 1)"), 135.0, 1e-12);
  EXPECT_EQ(eval("trunc(2.7)"), 3.0);
  EXPECT_EQ(eval("trunc(2.5)"), 3.0);
  EXPECT_EQ(eval("trunc(2.4)"), 2.0);
  EXPECT_EQ(eval("trunc(-2.7)"), -3.0);
  EXPECT_EQ(eval("trunc(-2.5)"), -2.0);
  EXPECT_EQ(eval("sqrt(16)"), 4.0);
  EXPECT_NEAR(eval("exp(1)"), std::numbers::e, 1e-15);
  EXPECT_NEAR(eval("log(exp(2))"), 2.0, 1e-15);
  EXPECT_EQ(eval("abs(-3.5)"), 3.5);
  EXPECT_EQ(eval("min(x, y)"), 2.0);
  EXPECT_EQ(eval("max(x, y)"), 3.0);
  EXPECT_EQ(eval("floor(-1.5)"), -2.0);
  EXPECT_EQ(eval("ceil(1.2)"), 2.0);
}

TEST(Expression, ConstantsAreFoldedToOneInstruction) {
  const Compiled c = compile("2*k + sin(30)*4 - 1");
  double value = 0;
  ASSERT_TRUE(c.program.is_constant(c.expr, &value));
  EXPECT_NEAR(value, 21.0, 1e-12);
  EXPECT_FALSE(compile("x*2").program.is_constant(compile("x*2").expr, &value));
  EXPECT_FALSE(compile("ran(1)").program.is_constant(compile("ran(1)").expr, &value));
}

TEST(Expression, RandomIsReproducibleAndInRange) {
  const Compiled c = compile("ran(x)");
  const double formals[2] = {2.0, 0.0};
  double sum = 0;
  for (uint64_t position = 0; position < 2000; ++position) {
    RandomStream a = RandomStream::keyed(7, 2, 1, position);
    RandomStream b = RandomStream::keyed(7, 2, 1, position);
    const double v = evaluate(c.program, c.expr, formals, a);
    EXPECT_EQ(v, evaluate(c.program, c.expr, formals, b));
    EXPECT_GE(v, 0.0);
    EXPECT_LT(v, 2.0);
    sum += v;
  }
  EXPECT_NEAR(sum / 2000, 1.0, 0.05);  // mean of U[0,2): 1, sd of the mean 0.013
  const Compiled n = compile("nran(5, 2)");
  double mean = 0, square = 0;
  for (uint64_t position = 0; position < 4000; ++position) {
    RandomStream r = RandomStream::keyed(7, 2, 1, position);
    const double v = evaluate(n.program, n.expr, formals, r);
    mean += v / 4000;
    square += v * v / 4000;
  }
  EXPECT_NEAR(mean, 5.0, 0.1);                           // sd of the mean 0.032
  EXPECT_NEAR(std::sqrt(square - mean * mean), 2.0, 0.1);
}

TEST(Expression, RuntimeErrorsNameTheOperator) {
  const Compiled c = compile("1 + 4/(x-2)");
  const double formals[2] = {2.0, 0.0};
  RandomStream random;
  try {
    evaluate(c.program, c.expr, formals, random);
    FAIL() << "expected a division by zero";
  } catch (const EvalError& error) {
    EXPECT_EQ(error.message, "division by zero");
    EXPECT_EQ(error.pos.line, 1);
    EXPECT_EQ(error.pos.column, 6);  // the '/'
  }
  const Compiled s = compile("sqrt(x - 5)");
  EXPECT_THROW(evaluate(s.program, s.expr, formals, random), EvalError);
}

// text => the GrammarError message "column: message".
std::string compile_error(const std::string& text) {
  ExprProgram program;
  size_t pos = 0;
  try {
    compile_expression(program, text, &pos, SourcePos{0, 1, 0}, ExprScope{&kFormals, &kDefines});
  } catch (const GrammarError& error) {
    return std::to_string(error.pos.column) + ": " + error.message;
  }
  return "no error, stopped at " + std::to_string(pos);
}

TEST(Expression, CompileErrors) {
  EXPECT_EQ(compile_error("x*"), "3: expected a number, a name or '(', got the end of the expression");
  EXPECT_EQ(compile_error("(x+1"), "5: expected ')' to close the '(' at column 1, got the end of the expression");
  EXPECT_EQ(compile_error("x + kk"),
            "5: unknown name 'kk' (expected a formal parameter (x, y) or a define (k, x); did you mean 'k'?)");
  EXPECT_EQ(compile_error("sin(1, 2)"), "1: sin expects 1 argument, got 2");
  EXPECT_EQ(compile_error("nran(1)"), "1: nran expects 2 arguments, got 1");
  EXPECT_EQ(compile_error("sinh(1)"), "1: unknown function 'sinh' (did you mean 'sin'?)");
  EXPECT_EQ(compile_error("x = 1"), "3: expected '==' to compare, got '='");
  EXPECT_EQ(compile_error("1/(2-2)"), "2: division by zero");
  EXPECT_EQ(compile_error("5 % 0.5"), "3: division by zero ('%' takes whole numbers: its divisor truncates to 0)");
  EXPECT_EQ(compile_error("x, 1"), "no error, stopped at 1");  // ',' ends an actual parameter
  EXPECT_EQ(compile_error(std::string(300, '(') + "1" + std::string(300, ')')), "257: expression too deeply nested");
  EXPECT_EQ(compile_error(std::string(17, '1') + "e999"), "1: number out of range");
}

}  // namespace
}  // namespace treeanim
