// libFuzzer target: one expression => compile (with formals and defines in scope) =>
// evaluate. Bad expressions must end in GrammarError / EvalError, never a crash.
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "lsystem/expression.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace treeanim;
  const std::string text(reinterpret_cast<const char*>(data), size);
  static const std::vector<std::string> formals{"x", "y", "l", "w"};
  static const std::vector<std::pair<std::string, double>> defines{{"r", 0.9}, {"a", 45}, {"x", 3}};
  const double values[] = {1.5, -2.0, 0.0, 1e300};
  ExprProgram program;
  try {
    size_t pos = 0;
    const Expr expr = compile_expression(program, text, &pos, SourcePos{0, 1, 1}, {&formals, &defines});
    if (pos > text.size()) __builtin_trap();  // the contract: pos stays inside the text
    RandomStream random = RandomStream::keyed(1, 2, 3, 4);
    if (expr.present()) evaluate(program, expr, values, random);
  } catch (const GrammarError&) {
  } catch (const EvalError&) {
  }
  return 0;
}
