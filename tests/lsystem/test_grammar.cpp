// Grammar parser: directives, rule structure, the shipped grammars, and malformed grammars
// with their exact "file:line:column: message".
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "common/errors.h"
#include "lsystem/grammar.h"
#include "input_error_of.h"

namespace treeanim {
namespace {

Grammar parse_defined(const std::string& text, const std::vector<std::pair<std::string, double>>& defines = {}) {
  return parse_grammar({{"g.lsys", text, false}}, defines);
}

std::string grammar_error_of(const std::string& text) {
  return input_error_of([&] { parse_defined(text); });
}

TEST(Grammar, DirectivesAndRules) {
  const Grammar g = parse_defined(
      "# a comment line\n"
      "#define r 0.5   /* trailing comment */\n"
      "#define q (r*4)\n"
      "lsystem: 1\n"
      "derivation length: 3\n"
      "angle: 22.5\n"
      "seed: 42\n"
      "ignore: +-F\n"
      "tropism: 0, -1, 0 0.2\n"
      "axiom: A(1)B#C\n"
      "B(x) < A(y) > [C]D : y > 0 --> A(y*q) : 2\n"
      "A(y) -> *\n"
      "homomorphism\n"
      "B --> F\n"
      "decomposition:\n"
      "maximum depth: 3\n"
      "D --> EE\n"
      "endlsystem\n"
      "this line is never read\n");
  ASSERT_EQ(g.defines.size(), 2u);
  EXPECT_EQ(g.defines[1].first, "q");
  EXPECT_EQ(g.defines[1].second, 2.0);
  EXPECT_EQ(g.derivation_length, 3);
  EXPECT_EQ(g.angle, 22.5);
  EXPECT_EQ(g.seed, 42u);
  EXPECT_TRUE(g.lsystems[0].context_skips['+'] && g.lsystems[0].context_skips['-'] && g.lsystems[0].context_skips['F']);
  EXPECT_FALSE(g.lsystems[0].context_skips['A']);
  EXPECT_EQ(*g.tropism, Eigen::Vector3d(0, -1, 0));
  EXPECT_EQ(g.tropism_elasticity, 0.2);
  ASSERT_EQ(g.axiom.size(), 4u);  // A(1) B # C: '#' right after a module is a module
  EXPECT_EQ(g.axiom[2].symbol, '#');
  ASSERT_EQ(g.lsystems[0].productions.rules.size(), 2u);
  const Rule& r = g.lsystems[0].productions.rules[0];
  EXPECT_EQ(r.predecessor, 'A');
  EXPECT_EQ(r.left_end - r.left_begin, 1u);
  EXPECT_EQ(r.right_end - r.right_begin, 4u);  // [ C ] D
  EXPECT_EQ(r.slot_count, 2);
  EXPECT_TRUE(r.condition.present());
  EXPECT_TRUE(r.probability.present());
  EXPECT_EQ(r.pos.line, 11);
  EXPECT_EQ(g.lsystems[0].productions.rules[1].successor_end, g.lsystems[0].productions.rules[1].successor_begin);  // '*'
  EXPECT_EQ(g.lsystems[0].homomorphism.rules.size(), 1u);
  EXPECT_EQ(g.lsystems[0].decomposition.rules.size(), 1u);
  EXPECT_EQ(g.lsystems[0].decomposition.max_depth, 3);
}

TEST(Grammar, ArrowsAndTurnSymbolsAsPredecessors) {
  const Grammar g = parse_defined("axiom: A\nA->B\n- --> +\n--->&\n+ > - --> ^\n");
  ASSERT_EQ(g.lsystems[0].productions.rules.size(), 4u);
  EXPECT_EQ(g.lsystems[0].productions.rules[0].predecessor, 'A');
  EXPECT_EQ(g.lsystems[0].productions.successor[g.lsystems[0].productions.rules[0].successor_begin].symbol, 'B');
  EXPECT_EQ(g.lsystems[0].productions.rules[1].predecessor, '-');
  EXPECT_EQ(g.lsystems[0].productions.rules[2].predecessor, '-');
  EXPECT_EQ(g.lsystems[0].productions.successor[g.lsystems[0].productions.rules[2].successor_begin].symbol, '&');
  EXPECT_EQ(g.lsystems[0].productions.rules[3].predecessor, '+');
  EXPECT_EQ(g.lsystems[0].productions.patterns[g.lsystems[0].productions.rules[3].right_begin].symbol, '-');
}

TEST(Grammar, SceneDefinesOverrideFileDefines) {
  const Grammar g = parse_defined("#define a 1\n#define b (a+1)\naxiom: F\n", {{"a", 10}});
  ASSERT_EQ(g.defines.size(), 2u);
  EXPECT_EQ(g.defines[0], (std::pair<std::string, double>("a", 10)));
  EXPECT_EQ(g.defines[1], (std::pair<std::string, double>("b", 11)));
  EXPECT_EQ(g.file_defines, (std::vector<std::string>{"a", "b"}));
}

TEST(Grammar, InlineRulesAreNamedByPointer) {
  try {
    parse_grammar({{"s.json: /lsystem/productions/0", "A --> B", true}, {"s.json: /lsystem/productions/1", "B --> C(", true}},
                  {}, GrammarText{"s.json: /lsystem/axiom", "A", true});
    FAIL();
  } catch (const InputError& error) {
    EXPECT_STREQ(error.what(), "s.json: /lsystem/productions/1, column 9: expected a number, a name or '(', got the end of the expression");
  }
  try {
    parse_grammar({}, {}, GrammarText{"s.json: /lsystem/axiom", "A[B", true});
    FAIL();
  } catch (const InputError& error) {
    EXPECT_STREQ(error.what(), "s.json: /lsystem/axiom, column 2: unbalanced brackets: '[' is never closed (expected ']' before the end of the axiom)");
  }
}

// Every grammar shipped in grammars/ parses (the ABOP figures and the demo tree).
TEST(Grammar, ShippedGrammarsParse) {
  const std::filesystem::path folder = std::filesystem::path(TREEANIM_SOURCE_DIR) / "grammars";
  int count = 0;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    if (entry.path().extension() != ".lsys") continue;
    std::ifstream in(entry.path());
    std::ostringstream text;
    text << in.rdbuf();
    SCOPED_TRACE(entry.path().string());
    EXPECT_NO_THROW(parse_grammar({{entry.path().string(), text.str(), false}}, {}));
    ++count;
  }
  EXPECT_GE(count, 1);
}

struct Malformed {
  const char* text;
  const char* message;
};

// At least 15 malformed grammars, each with its exact message.
TEST(Grammar, MalformedGrammarsReportFileLineColumn) {
  const Malformed cases[] = {
      {"axiom: F\nderivaton length: 5\n",
       "g.lsys:2:1: unknown directive 'derivaton length:' (expected one of axiom:, derivation length:, angle:, seed:, "
       "ignore:, consider:, tropism:, maximum depth:, width factor:, lsystem:, start:, starteach:, end:, endeach:, "
       "define:, homomorphism, decomposition, endlsystem, ring lsystem, "
       "#define; did you mean 'derivation length:'?)"},
      {"axiom: F\nF --> F[+F\n",
       "g.lsys:2:8: unbalanced brackets: '[' is never closed (expected ']' before the end of the successor)"},
      {"axiom: F]\n", "g.lsys:1:9: unbalanced brackets: ']' closes no '[' in the axiom"},
      {"axiom: A(1)\nA(x) --> F(x*)\n", "g.lsys:2:14: expected a number, a name or '(', got ')'"},
      {"axiom: A(1)\nA(x) --> A(x+y)\n",
       "g.lsys:2:14: unknown name 'y' (expected a formal parameter (x))"},
      {"#define len 2\naxiom: A(1)\nA(x) --> F(lenn)\n",
       "g.lsys:3:12: unknown name 'lenn' (expected a formal parameter (x) or a define (len); did you mean 'len'?)"},
      {"axiom: A(1)\nA(x) --> F(min(x))\n", "g.lsys:2:12: min expects 2 arguments, got 1"},
      {"axiom: A /* never closed\n", "g.lsys:1:10: '/*' comment is never closed (expected '*/')"},
      {"axiom: A\nderivation length: 2\nA B\n", "g.lsys:3:1: expected a directive or a production 'predecessor --> successor', got 'A B'"},
      {"F --> FF\n", "g.lsys:1:1: expected an 'axiom:' line; the grammar has none"},
      {"axiom: F\naxiom: G\n", "g.lsys:2:1: a second 'axiom:'; the grammar has one already"},
      {"axiom: F(1\n", "g.lsys:1:11: expected ',' or ')' after a parameter of 'F', got the end of the axiom"},
      {"axiom: F\nderivation length: 2.5\n", "g.lsys:2:20: expected an integer in [0, 100000], got 2.5"},
      {"axiom: A(1,2)\nA(x,x) --> A(x,x)\n", "g.lsys:2:5: formal parameter 'x' appears twice in the rule"},
      {"axiom: A\nA[B] --> C\n", "g.lsys:2:2: a bracket cannot be in a predecessor"},
      {"axiom: A(1)\nA(x) --> A(foo(x))\n", "g.lsys:2:12: unknown function 'foo'"},
      {"#define\naxiom: F\n", "g.lsys:1:8: expected a name after '#define'"},
      {"#define M(a, a) F(a)\naxiom: M(1, 2)\n", "g.lsys:1:14: parameter 'a' appears twice in macro 'M'"},
      {"axiom: A(1)\nA(1) --> B\n",
       "g.lsys:2:3: expected a formal parameter name (predecessors and contexts take names, not expressions)"},
      // A line that starts with the arrow continues only a head written above it.
      {"axiom: F-F\n-> F\n", "g.lsys:2:1: expected a predecessor module before the arrow"},
      {"axiom: F\nderivation length: 1\n--> F\n", "g.lsys:3:1: expected a predecessor module before the arrow"},
      {"axiom: F\nF --> G\n--> H\n", "g.lsys:3:1: expected a predecessor module before the arrow"},
      {"axiom: A\n[B < A --> C\n",
       "g.lsys:2:1: a bracket cannot be in a left context (it already skips branches)"},
      {"ignore: F\nconsider: A\naxiom: A\n", "g.lsys:2:1: 'ignore:' and 'consider:' cannot both be given"},
      {"axiom: A(1)\nA(x) : x = 1 --> B\n", "g.lsys:2:10: expected '==' to compare, got '='"},
      {"axiom: A\nA -->\n", "g.lsys:2:6: expected a successor after the arrow (write '*' for an empty successor)"},
      {"axiom: A\nA --> B*C\n", "g.lsys:2:8: '*' is not a module; alone it stands for an empty successor"},
      {"axiom: A\ndecomposition\nB < A --> C\n",
       "g.lsys:3:3: contexts are only allowed in productions and homomorphism rules, not in decomposition rules "
       "(cpfg matches them in the word before the step)"},
      {"#include \"x.h\"\naxiom: A\n",
       "g.lsys:1:1: cannot read the included file 'x.h' (no such file)"},
      {"axiom: A(1/0)\n", "g.lsys:1:11: division by zero"},
      {"axiom: A\ntropism: 0 -1 0\n", "g.lsys:2:16: expected 4 values 'Tx Ty Tz e' after 'tropism:', got 3"},
      {"#define a 1\n#define a 2\naxiom: A\n", "g.lsys:2:9: 'a' is already defined"},
      {"axiom: A\nmaximum depth: 0\n", "g.lsys:2:16: expected an integer in [1, 100000], got 0"},
  };
  for (const Malformed& c : cases) EXPECT_EQ(grammar_error_of(c.text), c.message) << c.text;
}

// The message starts with the name the text was given (a path for files).
TEST(Grammar, MessageNamesTheSource) {
  const std::string text = "axiom: A(1)\n# a comment\nA(x) --> A(x) B(sqrt(x, 2))\n";
  try {
    parse_grammar({{"tests/lsystem/bad/arity.lsys", text, false}}, {});
    FAIL();
  } catch (const InputError& error) {
    EXPECT_STREQ(error.what(), "tests/lsystem/bad/arity.lsys:3:17: sqrt expects 1 argument, got 2");
  }
}

}  // namespace
}  // namespace treeanim
