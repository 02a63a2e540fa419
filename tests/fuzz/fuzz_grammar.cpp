// libFuzzer target: grammar text => parse => derive (small module cap) => homomorphism =>
// turtle. Bad grammars must end in InputError, never a crash, hang or unbounded allocation.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "common/errors.h"
#include "lsystem/derive.h"
#include "lsystem/grammar.h"
#include "lsystem/turtle.h"

namespace {

// Small enough that every input finishes in milliseconds; the cap itself is what is tested.
constexpr size_t kFuzzModuleCap = 20'000;
// "derivation length:" may say 100000; steps beyond this only repeat the capped work.
constexpr int kFuzzMaxIterations = 12;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace treeanim;
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const Grammar grammar = parse_grammar({GrammarText{"fuzz.lsys", text, false}}, {});
    DerivationSettings settings;
    settings.iterations = std::min(grammar.derivation_length.value_or(3), kFuzzMaxIterations);
    settings.seed = 7;
    settings.max_modules = kFuzzModuleCap;
    std::vector<double> variables;
    const ModuleString word = derive(grammar, settings, {}, &variables);
    const ModuleString drawn = apply_homomorphism(grammar, word, settings, &variables);
    TurtleSettings turtle;
    turtle.angle_degrees = grammar.angle.value_or(turtle.angle_degrees);
    turtle.width_factor = grammar.width_factor.value_or(turtle.width_factor);
    turtle.calls = grammar.calls;
    interpret(drawn, turtle);
  } catch (const InputError&) {
    // The documented outcome of a bad grammar.
  }
  return 0;
}
