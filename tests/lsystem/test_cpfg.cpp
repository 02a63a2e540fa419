// cpfg's notation (docs/grammar.md "cpfg files"): grammars written for these tests in its style.
#include <gtest/gtest.h>

#include <string>

#include "common/errors.h"
#include "lsystem/derive.h"
#include "lsystem/grammar.h"

namespace treeanim {
namespace {

Grammar parse(const std::string& text) { return parse_grammar({{"plant.l", text, false}}, {}); }

std::string derive_text(const std::string& grammar, int steps) {
  const Grammar g = parse(grammar);
  const ModuleString word = derive(g, {steps, 1, 1'000'000});
  std::string out;
  for (size_t i = 0; i < word.size(); ++i) {
    out += word.symbols[i];
    const auto p = word.params_of(i);
    for (size_t k = 0; k < p.size(); ++k) out += (k ? "," : "(") + std::to_string(static_cast<int>(p[k]));
    if (!p.empty()) out += ")";
  }
  return out;
}

TEST(Cpfg, HeadersCommentsMacrosAndRulesOverLines) {
  EXPECT_EQ(derive_text("/* a bud\n   grows */\n#define GROW(x) (x)+1  // one a step\n"
                        "Lsystem: 1\nDerivation length: 2\nAxiom: A(0)\n"
                        "A(n) -->\n  F\n  A(GROW(n))\nhomomorphism: no warnings\nEndlsystem\n", 2),
            "FFA(2)");
}

TEST(Cpfg, BlocksVariablesAndControlBlocks) {
  EXPECT_EQ(derive_text("Lsystem: 1\nStart: {count = 10;}\nEndEach: {count = count + 1;}\n"
                        "derivation length: 2\nAxiom: A(0)\n"
                        "A(n) : {m = n; i = 0; while (i < 2) {m = m + 1; i = i + 1;}} m < 100 {if (m > 3) {m = 0;}}"
                        " --> A(m) B(count % 7 == 4 ? 1 : 2)\nendlsystem\n", 2),
            "A(0)B(1)B(2)");  // step 1: m = 2, count 10; step 2: m = 4 -> 0, count 11
}

TEST(Cpfg, SameSymbolWithDifferentAritiesAndDeepHomomorphism) {
  const Grammar g = parse("axiom: A A(3)\nA --> B\nA(n) --> A(n,n)\nhomomorphism\nmaximum depth: 1000\n"
                          "C(n) : n > 0 --> F C(n-1)\n");
  EXPECT_EQ(derive(g, {1, 1, 100}).size(), 2u);
  ModuleString word;
  word.clear();
  const double n = 900;
  word.push('C', {&n, 1});
  EXPECT_EQ(apply_homomorphism(g, word, {0, 1, 10'000}).size(), 901u);
}

TEST(Cpfg, UnsupportedConstructsAreRefusedWhereWritten) {
  auto error_of = [](const std::string& text) {
    try {
      parse(text);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(error_of("define: { array a[3]; }\naxiom: A\n"),
            "plant.l:1:1: arrays ('define: { array ... }') are not supported (CPFG manual 2.2.2)");
  EXPECT_EQ(error_of("axiom: A(1)\nA(x) : {y[1] = x;} --> A(x)\n"),
            "plant.l:2:10: arrays are not supported (cpfg manual 2.2.2)");
  EXPECT_EQ(error_of("axiom: A(1)\nA(x) : {while (1) {x = x;}} --> A(x)\n"), "no error");
  EXPECT_EQ(error_of("#define F(x) x\naxiom: F(1,2)\n"), "plant.l:2:8: macro 'F' expects 1 arguments, got 2");
}

TEST(Cpfg, EndlessLoopStopsWithItsPlace) {
  const Grammar g = parse("axiom: A(1)\nA(x) : {while (1) {x = x;}} --> A(x)\n");
  try {
    derive(g, {1, 1, 100});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("plant.l:2:"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("a loop ran more than 10000000 times"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace treeanim
