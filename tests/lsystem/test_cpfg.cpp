// cpfg's notation (docs/grammar.md "cpfg files"): grammars written for these tests in its style.
#include <unistd.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
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

// Spaces may come between a module and its parameters, in the axiom, predecessors and successors.
TEST(Cpfg, SpacesBeforeParameters) {
  EXPECT_EQ(derive_text("axiom: A (1)\nA (n) --> F (n) \\ (90) [ B] A(n + 1)\n", 1), "F(1)\\(90)[B]A(2)");
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

std::string error_of(const std::string& text, int steps = 1) {
  try {
    derive_text(text, steps);
  } catch (const InputError& e) {
    return std::string(e.what());
  }
  return "no error";
}

TEST(Cpfg, UnsupportedConstructsAreRefusedWhereWritten) {
  EXPECT_EQ(error_of("axiom: A(1)\nA(x) : {while (1) {x = x;}} --> A(x)\n", 0), "no error");
  EXPECT_EQ(error_of("#define F(x) x\naxiom: F(1,2)\n"), "plant.l:2:8: macro 'F' expects 1 arguments, got 2");
  EXPECT_EQ(error_of("axiom: A\nA --> B ?(1, 0.5) C $\n"),
            "plant.l:2:9: sub-L-systems ('?(id, scale) ... $') are not supported (CPFG manual 7.2)");
  EXPECT_EQ(error_of("axiom: A ?E(1)\n"),
            "plant.l:1:10: '?E' communicates with an environment process, which is not supported (CPFG manual 6.9)");
  EXPECT_EQ(error_of("axiom: A\nA[B] --> C\n"), "plant.l:2:2: a bracket cannot be in a predecessor");
}

// '=' in a right context (cpfg's generate.c) skips to the end of the current branch.
TEST(Cpfg, EqualsInARightContextSkipsTheRestOfTheBranch) {
  EXPECT_EQ(derive_text("axiom: A[BC]D\nA > [B=]D --> X\n", 1), "X[BC]D");
  EXPECT_EQ(derive_text("axiom: A[C][BE]F\nA > [=][B=]F --> X\n", 1), "X[C][BE]F");
  EXPECT_EQ(derive_text("axiom: A[BC]D\nA > [C=]D --> X\n", 1), "A[BC]D");
  EXPECT_EQ(error_of("axiom: A\nA > B=(x) --> X\n"), "plant.l:2:6: '=' (the rest of the branch) takes no parameters");
}

// A strict predecessor of several modules (CPFG manual 3.1) replaces them all, with the right
// context after its last module; in a homomorphism it applies to the derived word.
TEST(Cpfg, PredecessorOfSeveralModules) {
  EXPECT_EQ(derive_text("axiom: A(1)B(2)C\nA(x)B(y) --> D(x+y)\n", 1), "D(3)C");
  EXPECT_EQ(derive_text("axiom: A B C A B\nA B > C --> X\nB --> Y\n", 1), "XCAY");
  EXPECT_EQ(derive_text("axiom: A(1)B(2)\nA(x)B(y) : x > y --> Z\n", 1), "A(1)B(2)");
  const Grammar g = parse("axiom: A B A\nhomomorphism\nA B --> F(2)\n");
  const ModuleString drawn = apply_homomorphism(g, derive(g, {0, 1, 100}), {0, 1, 100});
  ASSERT_EQ(drawn.size(), 2u);
  EXPECT_EQ(drawn.symbols[0], 'F');
  EXPECT_EQ(drawn.symbols[1], 'A');
}

// Arrays (CPFG manual 2.2.2): row-major initialisers, "[i][j]" and "[i, j]", assignment in
// blocks, indices checked.
TEST(Cpfg, Arrays) {
  const std::string arrays = "define: {\n  array a[2][3] = {1, 2, 3,\n\n 4, 5, 6};\n  array b[2];\n}\n";
  EXPECT_EQ(derive_text(arrays + "Start: {b[1] = a[1][2] + a[0, 1];}\naxiom: A(b[1]) A(b[0])\n", 0), "A(8)A(0)");
  EXPECT_EQ(derive_text(arrays + "axiom: A(0)\nA(i) : {b[i] = b[i] + a[i][i];} * --> A(b[i] * 10 + i)\n", 1), "A(10)");
  EXPECT_EQ(error_of(arrays + "axiom: A(a[2][0])\n"), "plant.l:7:12: array index 2 is outside 0 ... 1");
  EXPECT_EQ(error_of(arrays + "axiom: A(1)\nA(x) --> A(a[0][x + 2])\n"),
            "plant.l:8:17: array index 3 is outside 0 ... 2 while deriving step 1 (rule at 8:1)");
  EXPECT_EQ(error_of("define: { array c[2] = {1, 2, 3}; }\naxiom: A\n"),
            "plant.l:1:31: more values than the 2 elements of 'c'");
  EXPECT_EQ(error_of("define: { array c[0]; }\naxiom: A\n"), "plant.l:1:19: expected an integer in [1, 1000000], got 0");
  EXPECT_EQ(error_of("define: { array c[2]; }\naxiom: A(c)\n"),
            "plant.l:2:11: expected '[' after the array 'c', got ')'");
}

// Query modules (CPFG manual 6.9): the turtle interprets the word after the axiom and after
// every step, through the homomorphism, and ?P ?H take its position and heading.
TEST(Cpfg, QueryModulesTakeTheTurtleState) {
  EXPECT_EQ(derive_text("axiom: F(1) A ?P(0,0)\nA > ?P(x,y) : y >= 2 --> B\nA --> F(1) A\n", 2), "F(1)F(1)B?P(0,2)");
  EXPECT_EQ(derive_text("axiom: +(90) ?H(0,0,0)\n", 0), "+(90)?H(-1,0,0)");
  EXPECT_EQ(derive_text("axiom: A ?P(0,0)\nhomomorphism\nA --> F(3)\n", 0), "A?P(0,3)");
  EXPECT_EQ(derive_text("axiom: ?P(5,5)\n?P(x,y) --> F(1) ?P(x,y)\n", 1), "F(1)?P(0,1)");
}

// printf is accepted and prints nothing (CPFG manual 5.4).
TEST(Cpfg, PrintfPrintsNothing) {
  EXPECT_EQ(derive_text("Start: {n = 2; printf(\"n = %f\\n\", n);}\naxiom: A(n)\n", 0), "A(2)");
}

// The preprocessor (CPFG manual ch. 2): #ifdef / #ifndef / #else / #endif, lines continued by
// one or two backslashes, and '#' inside a line is the width module, not a comment.
TEST(Cpfg, ConditionalsContinuationsAndHashInsideALine) {
  const std::string conditional = "#ifdef TALL\naxiom: F(2)\n#else\naxiom: F(1)\n#endif\n";
  EXPECT_EQ(derive_text("#define TALL 1\n" + conditional, 0), "F(2)");
  EXPECT_EQ(derive_text(conditional, 0), "F(1)");
  EXPECT_EQ(derive_text("#ifndef TALL\n#ifdef TALL\naxiom: A\n#endif\naxiom: B\n#endif\n", 0), "B");
  EXPECT_EQ(derive_text("#define GROW(x) \\\n  (x) + 1\n#define M 2 \\\\\n + 2\naxiom: A(GROW(M))\n", 0), "A(5)");
  EXPECT_EQ(derive_text("axiom: F # F ! F\n", 0), "F#F!F");
  EXPECT_EQ(error_of("axiom: A\n  #ifdef X\naxiom: A\n"), "plant.l:2:3: #ifdef or #ifndef is never closed (expected #endif)");
  EXPECT_EQ(error_of("axiom: A\n#else\n"), "plant.l:2:1: '#else' without #ifdef or #ifndef");
}

// #include finds the file beside the including one (a vlab object folder), and errors in it
// name the included file.
TEST(Cpfg, IncludeReadsTheFileBesideTheGrammar) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("treeanim_test_cpfg_include-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir / "sub");
  std::ofstream(dir / "sub" / "rules.l") << "#define N 3\nA(n) --> F(n) B(N)\n";
  std::ofstream(dir / "sub" / "broken.l") << "\nA(n) --> F(n) )\n";
  const std::string grammar = (dir / "sub" / "plant.l").string();
  const Grammar g = parse_grammar({{grammar, "axiom: A(1)\n#include \"rules.l\"\n", false}}, {});
  const ModuleString word = derive(g, {1, 1, 100});
  ASSERT_EQ(word.size(), 2u);
  EXPECT_EQ(word.symbols[1], 'B');
  EXPECT_EQ(word.params_of(1)[0], 3.0);
  try {
    parse_grammar({{grammar, "axiom: A(1)\n#include \"broken.l\"\n", false}}, {});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), (dir / "sub" / "broken.l").string() + ":2:15: expected a module symbol, got ')'");
  }
  std::filesystem::remove_all(dir);
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
