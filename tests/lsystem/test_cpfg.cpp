// cpfg's notation (docs/grammar.md "cpfg files"): grammars written for these tests in its style.
#include <unistd.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "common/errors.h"
#include "lsystem/derive.h"
#include "lsystem/grammar.h"
#include "lsystem/turtle.h"
#include "input_error_of.h"

namespace treeanim {
namespace {

Grammar parse_plant(const std::string& text) { return parse_grammar({{"plant.l", text, false}}, {}); }

// word => "A(1,2)B" (parameters truncated).
std::string text_of(const ModuleString& word) {
  std::string out;
  for (size_t i = 0; i < word.size(); ++i) {
    out += word.symbols[i];
    const auto p = word.params_of(i);
    for (size_t k = 0; k < p.size(); ++k) out += (k ? "," : "(") + std::to_string(static_cast<int>(p[k]));
    if (!p.empty()) out += ")";
  }
  return out;
}

std::string derive_text(const std::string& grammar, int steps) {
  return text_of(derive(parse_plant(grammar), {steps, 1, 1'000'000}));
}

TEST(Cpfg, HeadersCommentsMacrosAndRulesOverLines) {
  EXPECT_EQ(derive_text("/* a bud\n   grows */\n#define GROW(x) (x)+1  // one a step\n"
                        "Lsystem: 1\nDerivation length: 2\nAxiom: A(0)\n"
                        "A(n) -->\n  F\n  A(GROW(n))\nhomomorphism: no warnings\nEndlsystem\n", 2),
            "FFA(2)");
}

// A macro's arguments are expanded before they are put in, as cpp does, the macro itself
// included (it is not expanding yet); its body is then expanded without it.
TEST(Cpfg, MacroArgumentsAreExpandedFirst) {
  EXPECT_EQ(derive_text("#define D(a) (a*2)\naxiom: F(D(D(1)))\n", 0), "F(4)");
  EXPECT_EQ(derive_text("#define D(a) (a*2)\n#define E(a) D(a)+1\naxiom: F(E(D(3)))\n", 0), "F(13)");
  EXPECT_EQ(derive_text("#define N 3\n#define D(a) (a*2)\naxiom: F(D(N))\n", 0), "F(6)");
  std::string deep = "1";
  for (int i = 0; i < 40; ++i) deep = "D(" + deep + ")";
  EXPECT_NE(input_error_of([&] {
              parse_plant("#define D(a) (a+1)\naxiom: F(" + deep + ")\n");
            }).find("macros expand more than 32 levels deep"),
            std::string::npos);
}

// A scene define replaces a constant #define, even one that cannot be computed, and refuses a
// text one, which it would have dropped for a number.
TEST(Cpfg, SceneDefinesReplaceConstantsOnly) {
  const std::string grammar = "#define K F(2)\n#define L (1/0)\naxiom: F(1) K F(L)\n";
  EXPECT_EQ(text_of(derive(parse_grammar({{"plant.l", "#define L (1/0)\naxiom: F(L)\n", false}}, {{"L", 3}}), {0, 1, 100})),
            "F(3)");
  EXPECT_EQ(input_error_of([&] { parse_grammar({{"plant.l", grammar, false}}, {{"K", 5}, {"L", 3}}); }),
            "plant.l:1:9: lsystem.defines gives 'K' a value, but this #define is text (F(2)), not a constant: only a "
            "constant #define takes the scene's value");
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

// A block after a rule's ':' continues over lines until its braces close; any other brace is a
// polygon's and never takes in the next line: a predecessor's, an axiom's, an ignore: list's.
// A head ends on the next line at the arrow that starts it.
TEST(Cpfg, AnArrowLineEndsTheHeadAboveIt) {
  EXPECT_EQ(derive_text("axiom: A(1)\nA(n) : n > 0\n  --> B(n)\n", 1), "B(1)");
  EXPECT_EQ(derive_text("axiom: A\nderivation length: 1\nA\n--> B\n", 1), "B");
}

TEST(Cpfg, OnlyABlockTakesInTheNextLine) {
  EXPECT_EQ(derive_text("axiom: A(1)\nA(n) : {m = n;\nm = m + 1;} m > 0 --> A(m)\n", 2), "A(3)");
  EXPECT_EQ(derive_text("axiom: A{.F}\n{ --> {\nA --> FA\n", 1), "FA{.F}");
  EXPECT_EQ(derive_text("ignore: {}\naxiom: A{B}\nA < B --> C\n", 1), "A{C}");
}

// The homomorphism reads the globals as the derivation's End block leaves them.
TEST(Cpfg, HomomorphismReadsTheGlobalsTheDerivationLeaves) {
  const Grammar g = parse_plant(
      "Start: {ang = 30;}\nEnd: {ang = ang + 1;}\nderivation length: 1\naxiom: A\n"
      "homomorphism\nA --> +(ang) F\n");
  std::vector<double> variables;
  const ModuleString word = derive(g, {1, 1, 100}, {}, &variables);
  const ModuleString drawn = apply_homomorphism(g, word, {1, 1, 100}, &variables);
  ASSERT_EQ(drawn.size(), 2u);
  EXPECT_EQ(drawn.params_of(0)[0], 31.0);
  EXPECT_EQ(apply_homomorphism(g, word, {1, 1, 100}).params_of(0)[0], 0.0);  // before the Start block
}

TEST(Cpfg, SameSymbolWithDifferentAritiesAndDeepHomomorphism) {
  const Grammar g = parse_plant(
      "axiom: A A(3)\nA --> B\nA(n) --> A(n,n)\nhomomorphism\nmaximum depth: 1000\n"
      "C(n) : n > 0 --> F C(n-1)\n");
  EXPECT_EQ(derive(g, {1, 1, 100}).size(), 2u);
  ModuleString word;
  word.clear();
  const double n = 900;
  word.push('C', {&n, 1});
  EXPECT_EQ(apply_homomorphism(g, word, {0, 1, 10'000}).size(), 901u);
}

std::string plant_error_of(const std::string& text, int steps = 1) {
  return input_error_of([&] { derive_text(text, steps); });
}

TEST(Cpfg, UnsupportedConstructsAreRefusedWhereWritten) {
  EXPECT_EQ(plant_error_of("axiom: A(1)\nA(x) : {while (1) {x = x;}} --> A(x)\n", 0), "no error");
  EXPECT_EQ(plant_error_of("#define F(x) x\naxiom: F(1,2)\n"), "plant.l:2:8: macro 'F' expects 1 arguments, got 2");
  EXPECT_EQ(plant_error_of("#ignore: +-F\naxiom: A\n"),
            "plant.l:1:1: '#ignore:' is ABOP's way of printing the statement; write 'ignore:' without the '#'");
  EXPECT_EQ(plant_error_of("axiom: A\nA --> B ?(3, 0.5) C $\n"),
            "plant.l:2:9: '?(3, ...)' calls L-system 3, but the file has no 'lsystem: 3' (it has 0)");
  EXPECT_EQ(plant_error_of("lsystem: 1\naxiom: A(4)\nA(n) --> ?(n, 1) B $\n"),
            "plant.l:3:10: '?(4, ...)' calls L-system 4 while deriving step 1, but the file has no 'lsystem: 4' (rule "
            "at 3:1)");
  EXPECT_EQ(plant_error_of("lsystem: 1\naxiom: A(3.7)\nA(n) --> ?(n, 1) B $\n"),  // the label's fraction dropped
            "plant.l:3:10: '?(3.7, ...)' calls L-system 3 while deriving step 1, but the file has no 'lsystem: 3' (rule "
            "at 3:1)");
  EXPECT_EQ(
      plant_error_of("axiom: A\nA --> B(\"x\")\n"),
      "plant.l:2:9: a string parameter is only read first in @L(\"label\"), @S(\"command\") and @I(\"object\", s)");
  EXPECT_EQ(plant_error_of("axiom: A ?E(1)\n"),
            "plant.l:1:10: '?E' communicates with an environment process, which is not supported (CPFG manual 6.9)");
  EXPECT_EQ(plant_error_of("axiom: A\nA[B] --> C\n"), "plant.l:2:2: a bracket cannot be in a predecessor");
  EXPECT_EQ(plant_error_of("axiom: A\nA --> F @PS(1, 1) @PC(1, 0, 0) @PD(1, 4, 4)\n"),
            "plant.l:2:9: '@P' (@PS, @PC, @PD: a bicubic patch from turtle positions, CPFG manual 6.7.2) is not "
            "supported; draw the surface from a '.s' file with '~id' (a 'surface:' line of the view file)");
}

// '=' in a right context (cpfg's generate.c) skips to the end of the current branch.
TEST(Cpfg, EqualsInARightContextSkipsTheRestOfTheBranch) {
  EXPECT_EQ(derive_text("axiom: A[BC]D\nA > [B=]D --> X\n", 1), "X[BC]D");
  EXPECT_EQ(derive_text("axiom: A[C][BE]F\nA > [=][B=]F --> X\n", 1), "X[C][BE]F");
  EXPECT_EQ(derive_text("axiom: A[BC]D\nA > [C=]D --> X\n", 1), "A[BC]D");
  EXPECT_EQ(plant_error_of("axiom: A\nA > B=(x) --> X\n"),
            "plant.l:2:6: '=' (the rest of the branch) takes no parameters");
}

// A strict predecessor of several modules (CPFG manual 3.1) replaces them all, with the right
// context after its last module; in a homomorphism it applies to the derived word and, as cpfg
// rewrites its successor buffer, within the successors of a deeper recursion.
TEST(Cpfg, PredecessorOfSeveralModules) {
  EXPECT_EQ(derive_text("axiom: A(1)B(2)C\nA(x)B(y) --> D(x+y)\n", 1), "D(3)C");
  EXPECT_EQ(derive_text("axiom: A B C A B\nA B > C --> X\nB --> Y\n", 1), "XCAY");
  EXPECT_EQ(derive_text("axiom: A(1)B(2)\nA(x)B(y) : x > y --> Z\n", 1), "A(1)B(2)");
  const Grammar g = parse_plant("axiom: A B A\nhomomorphism\nA B --> F(2)\n");
  const ModuleString drawn = apply_homomorphism(g, derive(g, {0, 1, 100}), {0, 1, 100});
  ASSERT_EQ(drawn.size(), 2u);
  EXPECT_EQ(drawn.symbols[0], 'F');
  EXPECT_EQ(drawn.symbols[1], 'A');
  // Within a successor (vlab's HilbertPanels: L --> Sl Tl, Sl --> ...), its parameters bound,
  // not across the successor's end, and a tail the rule does not take left to the next module.
  auto homomorphism = [](const std::string& text) {
    const Grammar h = parse_plant(text);
    return text_of(apply_homomorphism(h, derive(h, {0, 1, 100}), {0, 1, 100}));
  };
  EXPECT_EQ(homomorphism("axiom: A\nhomomorphism\nmaximum depth: 2\nA --> F B(1)C(2)\nB(x)C(y) --> G(x+y)\n"), "FG(3)");
  EXPECT_EQ(homomorphism("axiom: A C\nhomomorphism\nmaximum depth: 3\nA --> F B\nB C --> G\n"), "FBC");
  EXPECT_EQ(homomorphism("axiom: A\nhomomorphism\nmaximum depth: 3\nA --> F B C D\nC D --> E\nB C --> G\n"), "FGD");
  EXPECT_EQ(homomorphism("axiom: A\nhomomorphism\nmaximum depth: 1\nA --> F B(1)C(2)\nB(x)C(y) --> G(x+y)\n"),
            "FB(1)C(2)");  // at the depth limit nothing more is rewritten
}

// Arrays (CPFG manual 2.2.2): row-major initialisers, "[i][j]" and "[i, j]", assignment in
// blocks, indices checked.
TEST(Cpfg, Arrays) {
  const std::string arrays = "define: {\n  array a[2][3] = {1, 2, 3,\n\n 4, 5, 6};\n  array b[2];\n}\n";
  EXPECT_EQ(derive_text(arrays + "Start: {b[1] = a[1][2] + a[0, 1];}\naxiom: A(b[1]) A(b[0])\n", 0), "A(8)A(0)");
  EXPECT_EQ(derive_text(arrays + "axiom: A(0)\nA(i) : {b[i] = b[i] + a[i][i];} * --> A(b[i] * 10 + i)\n", 1), "A(10)");
  EXPECT_EQ(plant_error_of(arrays + "axiom: A(a[2][0])\n"), "plant.l:7:12: array index 2 is outside 0 ... 1");
  EXPECT_EQ(plant_error_of(arrays + "axiom: A(1)\nA(x) --> A(a[0][x + 2])\n"),
            "plant.l:8:17: array index 3 is outside 0 ... 2 while deriving step 1 (rule at 8:1)");
  EXPECT_EQ(plant_error_of("define: { array c[2] = {1, 2, 3}; }\naxiom: A\n"),
            "plant.l:1:31: more values than the 2 elements of 'c'");
  EXPECT_EQ(plant_error_of("define: { array c[0]; }\naxiom: A\n"),
            "plant.l:1:19: expected an integer in [1, 1000000], got 0");
  EXPECT_EQ(plant_error_of("define: { array c[2]; }\naxiom: A(c)\n"),
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
  // A name defined as nothing, cpp's flag: defined, and it expands to nothing.
  EXPECT_EQ(derive_text("#define TALL\n" + conditional, 0), "F(2)");
  EXPECT_EQ(derive_text("#define NOTHING \naxiom: F NOTHING G\n", 0), "FG");
  EXPECT_EQ(derive_text(conditional, 0), "F(1)");
  EXPECT_EQ(derive_text("#ifndef TALL\n#ifdef TALL\naxiom: A\n#endif\naxiom: B\n#endif\n", 0), "B");
  EXPECT_EQ(derive_text("#define GROW(x) \\\n  (x) + 1\n#define M 2 \\\\\n + 2\naxiom: A(GROW(M))\n", 0), "A(5)");
  EXPECT_EQ(derive_text("axiom: F # F ! F\n", 0), "F#F!F");
  EXPECT_EQ(plant_error_of("axiom: A\n  #ifdef X\naxiom: A\n"),
            "plant.l:2:3: #ifdef or #ifndef is never closed (expected #endif)");
  EXPECT_EQ(plant_error_of("axiom: A\n#else\n"), "plant.l:2:1: '#else' without #ifdef or #ifndef");
}

// What cpp (which cpfg runs) reads as comments and what stays modules; an axiom's unclosed
// polygon brace, closed by a rule, does not join the next line; a '%' in the axiom cuts as one a
// rule wrote (cpfg cuts any it finds); a label is a 9-digit number at most.
TEST(Cpfg, CommentsCutsPolygonsAndLabels) {
  EXPECT_EQ(derive_text("axiom: A\nA --> FF// twice\n", 1), "FF");
  EXPECT_EQ(derive_text("axiom: A\nA --> F/////F\n", 1), "F/////F");
  EXPECT_EQ(derive_text("axiom: F{.+F.A\nA --> F.}\n", 1), "F{.+F.F.}");
  EXPECT_EQ(derive_text("axiom: F[+A%FF]F\nA --> AF\n", 2), "F[+AFF]F");
  EXPECT_EQ(derive_text("lsystem: 123456789\naxiom: A\n", 0), "A");
  EXPECT_EQ(plant_error_of("lsystem: 1000000001\naxiom: A\n"),
            "plant.l:1:10: expected a label of at most 9 digits (a call names it as a number)");
}

// The scene's inline grammar is a file's lines, one an element: a #define, text or number, and
// an #ifdef go on into the elements after them.
TEST(Cpfg, InlineLinesShareTheirDefinesAndConditions) {
  const auto inline_text = [](const std::vector<std::string>& lines) {
    std::vector<GrammarText> texts;
    for (size_t k = 0; k < lines.size(); ++k)
      texts.push_back({"s.json: /lsystem/productions/" + std::to_string(k), lines[k], true});
    return text_of(derive(parse_grammar(texts, {}), {1, 1, 100}));
  };
  EXPECT_EQ(inline_text({"axiom: A(1)", "#define TWIG F(l)[+F(l)]", "A(l) --> TWIG A(l)"}), "F(1)[+F(1)]A(1)");
  EXPECT_EQ(inline_text({"axiom: A(1)", "#ifdef TALL", "A(l) --> F(l) A(l)", "#else", "A(l) --> B", "#endif"}), "B");
  EXPECT_EQ(input_error_of([&] { inline_text({"axiom: A(1)", "#ifdef TALL", "A(l) --> B"}); }),
            "s.json: /lsystem/productions/1, column 1: #ifdef or #ifndef is never closed (expected #endif)");
}

// A chain of conditionals is as long as it needs (a recursion per '?' overflowed the stack at
// 60,000); conditionals nested in then-sides stop at the nesting limit, as parentheses do.
TEST(Cpfg, ConditionalChainsAndNesting) {
  std::string chain = "axiom: A(";
  for (int k = 0; k < 100000; ++k) chain += "0?1:";
  EXPECT_EQ(derive_text(chain + "7)\n", 0), "A(7)");
  std::string nested = "axiom: A(";
  for (int k = 0; k < 300; ++k) nested += "1?";
  nested += "1";
  for (int k = 0; k < 300; ++k) nested += ":0";
  EXPECT_NE(plant_error_of(nested + ")\n", 0).find("expression too deeply nested"), std::string::npos);
}

// What a grammar may grow to: a module's parameters count against lsystem.max_modules (4 a
// module), and the text #includes and macros expand to is 64 MiB at most.
TEST(Cpfg, ParametersAndExpandedTextAreBounded) {
  std::string many = "axiom: A\nA --> AA B(";
  for (int k = 0; k < 100; ++k) many += k ? ",1" : "1";
  const Grammar g = parse_plant(many + ")\n");
  EXPECT_EQ(input_error_of([&] { derive(g, {10, 1, 10000}); }),
            "plant.l: derivation step 9 of 10 reached 40100 parameters, more than 4 x lsystem.max_modules = 10000 "
            "(lower lsystem.iterations or raise lsystem.max_modules)");
  // Rules that recurse to their maximum depth and erase what they made grow nothing the module
  // cap sees: 2^40 rule applications, stopped after 8 x max_modules modules begun.
  const Grammar recursing = parse_plant(
      "derivation length: 1\naxiom: F A(40)\nhomomorphism\nmaximum depth: 100\n"
      "A(n) : n > 0 --> A(n-1)A(n-1)\nA(n) : n == 0 --> *\n");
  EXPECT_EQ(input_error_of([&] { apply_homomorphism(recursing, derive(recursing, {1, 1, 1000}), {1, 1, 1000}); }),
            "plant.l: the homomorphism applied more than 8 x lsystem.max_modules = 8000 rules and modules (its rules "
            "recurse too far: lower its 'maximum depth:', or raise lsystem.max_modules)");
  // A macro argument used 5,000 times is stopped as the line grows, not after (it took 1.9 GB).
  std::string uses_of_x = "#define D(x)";
  for (int k = 0; k < 5000; ++k) uses_of_x += " x";
  EXPECT_NE(plant_error_of(uses_of_x + "\naxiom: F(1) A(D(D(1)))\n", 0).find("a line grows past 1 MiB"), std::string::npos);
  EXPECT_NE(plant_error_of("axiom: F" + std::string(size_t(1) << 21, 'F') + "\n", 0).find("plant.l:1:1: a line longer than 1 MiB"),
            std::string::npos);
  // 16 macros each twice the one before, each use a line of half a megabyte.
  std::string doubling = "#define M0 FFFFFFFFFFFFFFFF\n";
  for (int k = 1; k < 16; ++k)
    doubling += "#define M" + std::to_string(k) + " M" + std::to_string(k - 1) + " M" + std::to_string(k - 1) + "\n";
  std::string uses;
  for (int k = 0; k < 200; ++k) uses += "A --> M15\n";
  EXPECT_NE(plant_error_of(doubling + "axiom: A\n" + uses, 0)
                .find(": the grammar grows past 64 MiB with its #includes and "
                      "macros expanded"),
            std::string::npos);
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

// Sub-L-systems (CPFG manual 7.2): the modules between '?(label, s)' and its '$' are rewritten
// by L-system `label`'s productions in the same steps as the rest (its own derivation length
// and axiom are not used); the first L-system in the file is the one derived.
const std::string kSubLsystems =
    "Lsystem: 1\nderivation length: 2\naxiom: A B(1)\n"
    "A --> F ?(2, 2) B(1) $ A\nB(x) --> B(x+1)\nendlsystem\n"
    "some notes after the end\n"
    "Lsystem: 2\nderivation length: 99\naxiom: B(7)\nB(x) --> C(x) B(x*10)\n"
    "homomorphism\nC(x) --> F(x)\nendlsystem\n";

TEST(Cpfg, SubLsystemsRewriteTheModulesTheyAreCalledFor) {
  EXPECT_EQ(derive_text(kSubLsystems, 1), "F?(2,2)B(1)$AB(2)");
  EXPECT_EQ(derive_text(kSubLsystems, 2), "F?(2,2)C(1)B(10)$F?(2,2)B(1)$AB(3)");
  // Each L-system's homomorphism draws its own modules: C is drawn only inside a call of 2.
  const Grammar g = parse_plant(kSubLsystems + "");
  ModuleString word;
  word.clear();
  const double one = 1, call[2] = {2, 1};
  word.push('C', {&one, 1});
  word.push('?', call);
  word.push('C', {&one, 1});
  word.push('$');
  const ModuleString drawn = apply_homomorphism(g, word, {0, 1, 100});
  EXPECT_EQ(std::string(drawn.symbols.begin(), drawn.symbols.end()), "C?F$");
  // A sub-L-system's control blocks would need variables per call.
  EXPECT_EQ(plant_error_of("lsystem: 1\naxiom: A\nA --> ?(2) B $\nendlsystem\nlsystem: 2\nStart: {x = 1;}\n"),
            "plant.l:6:1: a sub-L-system's 'start:' block is not supported (cpfg gives each call of a sub-L-system its "
            "own copy of the variables, CPFG manual 7.2)");
}

// Contexts run across calls with the current L-system's ignore: list ('?' and '$' are modules).
TEST(Cpfg, ContextsOfASubLsystemUseItsOwnIgnoreList) {
  const std::string sub = "lsystem: 2\naxiom: B\nX < B --> D\nendlsystem\n";
  EXPECT_EQ(derive_text("lsystem: 1\naxiom: X ?(2) B $\nendlsystem\n" + sub, 1), "X?(2)B$");
  EXPECT_EQ(derive_text("lsystem: 1\naxiom: X ?(2) B $\nendlsystem\nlsystem: 2\nignore: ?\naxiom: B\n"
                        "X < B --> D\nendlsystem\n", 1),
            "X?(2)D$");
}

// The turtle scales lengths, widths and surfaces by a call's s until its '$' (cpfg's interpret.c).
TEST(Cpfg, CallsScaleTheTurtle) {
  const Grammar g = parse_plant(
      "lsystem: 1\naxiom: !(1) F(1) ?(2, 0.5) F(2) [ !(2) F(2) ] $ F(1)\nendlsystem\n"
      "lsystem: 2\naxiom: F\nendlsystem\n");
  TurtleSettings turtle;
  turtle.calls = g.calls;
  const Skeleton k = interpret(derive(g, {0, 1, 100}), turtle);
  ASSERT_EQ(k.segment_end.size(), 4u);
  EXPECT_DOUBLE_EQ(k.segment_end[1].y(), 2.0);  // F(2) at half scale
  EXPECT_DOUBLE_EQ(k.segment_end[2].y(), 3.0);
  EXPECT_DOUBLE_EQ(k.segment_end[3].y(), 3.0);  // after '$': F(1) at full scale from y = 2
  EXPECT_DOUBLE_EQ(k.segment_width[1], 0.5);
  EXPECT_DOUBLE_EQ(k.segment_width[2], 1.0);    // !(2) at half scale
  EXPECT_DOUBLE_EQ(k.segment_width[3], 1.0);
}

// Ring L-systems (CPFG manual 3.1.1): the string's ends are adjacent for contexts.
TEST(Cpfg, RingLsystemsWrapContextsAroundTheString) {
  EXPECT_EQ(derive_text("ring lsystem\nAxiom: A B C\nC < A --> X\nC > A --> Y\n", 1), "XBY");
  EXPECT_EQ(derive_text("Axiom: A B C\nC < A --> X\nC > A --> Y\n", 1), "ABC");
  EXPECT_EQ(derive_text("ring lsystem\nAxiom: A C [B]\nC < A --> Z\n", 1), "ZC[B]");  // past the branch at the end
  // Everything ignored: the search stops after a turn instead of circling.
  EXPECT_EQ(derive_text("ring lsystem\nignore: AB\nAxiom: A B\nC < A --> X\nA > C --> Y\n", 1), "AB");
}

// Brackets in ignore: and consider: (cpfg's RconDiff): a skipped '[' is entered and a skipped
// ']' passed by right contexts; left contexts always follow brackets.
TEST(Cpfg, IgnoredBracketsChangeRightContexts) {
  EXPECT_EQ(derive_text("axiom: A[B]C\nA > B --> X\n", 1), "A[B]C");
  EXPECT_EQ(derive_text("ignore: [\naxiom: A[B]C\nA > B --> X\n", 1), "X[B]C");
  EXPECT_EQ(derive_text("ignore: [\naxiom: A[B]C\nB > C --> X\n", 1), "A[B]C");
  EXPECT_EQ(derive_text("ignore: ]\naxiom: [A]B\nA > B --> X\n", 1), "[X]B");
  EXPECT_EQ(derive_text("consider: AB\naxiom: A[C]B\nA > B --> X\n", 1), "X[C]B");
  EXPECT_EQ(derive_text("consider: AB\naxiom: A[B]C\nA > B --> X\n", 1), "X[B]C");
  EXPECT_EQ(derive_text("consider: AB[]\naxiom: A[B]C\nA > B --> X\n", 1), "A[B]C");
  EXPECT_EQ(derive_text("ignore: [\naxiom: B[A]\nB < A --> X\n", 1), "B[X]");
  EXPECT_EQ(derive_text("ignore: [\naxiom: A[B]\nA > [B] --> X\n", 1), "X[B]");  // a pattern's '[' still enters
}

// @L("format", values) labels (CPFG manual 6.10): the string is read past; the parameter holds
// its number in the file and the turtle draws nothing.
TEST(Cpfg, LabelsTakeAStringAndDrawNothing) {
  EXPECT_EQ(derive_text("axiom: F @L(\"age %.f\", 3) @L(\"a \\\"b\\\"\") @S(\"ls\")\n", 0), "F@L(0,3)@L(1)@S(2)");
  const Grammar g = parse_plant("axiom: F @L(\"x\", 3) F\n");
  const Skeleton k = interpret(derive(g, {0, 1, 100}), {});
  EXPECT_EQ(k.segment_end.size(), 2u);
  EXPECT_TRUE(k.leaf_segment.empty());
  EXPECT_EQ(plant_error_of("axiom: @L(\"open)\n"), "plant.l:1:11: the string is never closed (expected '\"')");
}

// A column counts characters, so a comment or label in UTF-8 before the fault moves it by its
// characters, not by their bytes.
TEST(Cpfg, ColumnsCountCharacters) {
  EXPECT_EQ(plant_error_of("axiom: /* \xC3\xA9t\xC3\xA9 */ F(1/)\n"), "plant.l:1:22: expected a number, a name or '(', got ')'");
  EXPECT_EQ(plant_error_of("axiom: @L(\"\xE2\x86\x92\") F(1/)\n"), "plant.l:1:20: expected a number, a name or '(', got ')'");
  EXPECT_EQ(plant_error_of("/* \xC3\xA9\n\xC3\xA9 */ axiom: F(1/)\n"), "plant.l:2:17: expected a number, a name or '(', got ')'");
}

// curveX/curveY/curveZ/curveGAL (CPFG manual 5.5) read the view file's curves by arc length.
TEST(Cpfg, CurveFunctions) {
  ViewCurve line;
  line.control = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 1, 0}, {0, 2, 0}, {0, 3, 0}, {0, 3, 0}, {0, 3, 0}};
  line.arc = {0.0, 1.0 / 3, 2.0 / 3, 1.0};
  line.length = 3;
  const Grammar g = parse_grammar({{"plant.l", "Start: {L = curveGAL(1);}\naxiom: A(L, curveY(1, 1), curveX(1, 0.5), curveZ(1, 2))\n", false}},
                                  {}, std::nullopt, {}, {line});
  const ModuleString word = derive(g, {0, 1, 100});
  ASSERT_EQ(word.params_of(0).size(), 4u);
  EXPECT_EQ(word.params_of(0)[0], 3.0);
  EXPECT_DOUBLE_EQ(word.params_of(0)[1], 3.0);
  EXPECT_EQ(word.params_of(0)[2], 0.0);
  EXPECT_EQ(word.params_of(0)[3], 0.0);
  try {
    parse_grammar({{"plant.l", "axiom: A(curveY(2, 0))\n", false}}, {}, std::nullopt, {}, {line});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "plant.l:1:10: curveY expects a constant number 1 ... 1 (the view file's 'curve:' lines)");
  }
}

// Homomorphism rules match contexts in the word being drawn; a module a homomorphism rule
// produces takes the contexts of the module it comes from (CPFG manual 4.3.2).
TEST(Cpfg, HomomorphismContextsAreTheDerivedWords) {
  const Grammar g = parse_plant(
      "derivation length: 0\naxiom: F P(1,2) F P(1,5) [Q] F\nignore: Q\n"
      "homomorphism\nF > P(x,y) : y > 3 --> f\nP(x,y) < F --> G(x)\n");
  const ModuleString word = derive(g, {0, 1, 100});
  EXPECT_EQ(text_of(apply_homomorphism(g, word, {0, 1, 100})), "FP(1,2)fP(1,5)[Q]G(1)");
  const Grammar deep = parse_plant(
      "axiom: F P(1,2) F P(1,5)\nhomomorphism\nmaximum depth: 2\n"
      "F --> G P(0,0)\nG > P(x,y) : y > 3 --> f\n");
  EXPECT_EQ(text_of(apply_homomorphism(deep, derive(deep, {0, 1, 100}), {0, 1, 100})),
            "GP(0,0)P(1,2)fP(0,0)P(1,5)");
}

// "seed:" after "homomorphism" seeds its draws alone (CPFG manual 4.3.3): the same drawing
// whatever the derivation's seed, which it leaves as it is.
TEST(Cpfg, HomomorphismSeedKeysOnlyTheHomomorphism) {
  const std::string text = "axiom: A\nhomomorphism\nseed: 5\nA --> F(ran(1000))\n";
  const Grammar g = parse_plant(text);
  EXPECT_EQ(g.seed, 0u);
  const ModuleString word = derive(g, {0, 1, 100});
  EXPECT_EQ(apply_homomorphism(g, word, {0, 1, 100}).params, apply_homomorphism(g, word, {0, 2, 100}).params);
  const Grammar unseeded = parse_plant("axiom: A\nhomomorphism\nA --> F(ran(1000))\n");
  EXPECT_NE(apply_homomorphism(unseeded, word, {0, 1, 100}).params, apply_homomorphism(unseeded, word, {0, 2, 100}).params);
  EXPECT_EQ(plant_error_of("axiom: A\ndecomposition\nseed: 5\n"),
            "plant.l:3:1: a decomposition draws with the productions' random numbers: 'seed:' belongs before "
            "'decomposition' (CPFG manual 4.4)");
}

// With "seed:" an L-system is stochastic as cpfg's (generate.c, FindApplProductions and
// SelectProd): every applicable production is drawn from, one without a probability weighing
// 1, and when every weight is 0 the first applies. Without it the first applicable rule without
// a probability applies, unless one with a probability comes first.
TEST(Cpfg, SeedMakesEveryApplicableProductionACandidate) {
  const std::string rules = "axiom: " + std::string(100, 'A') + "\nA --> B : 1\nA --> C\n";
  const std::string seeded = derive_text("seed: 3\n" + rules, 1);
  const auto count = [](const std::string& word, char c) { return std::count(word.begin(), word.end(), c); };
  EXPECT_EQ(count(seeded, 'B') + count(seeded, 'C'), 100);
  EXPECT_GT(count(seeded, 'B'), 30);  // 50 expected; a seed gives under 30 with a chance of 4e-5
  EXPECT_GT(count(seeded, 'C'), 30);
  EXPECT_EQ(derive_text(rules, 1), std::string(100, 'B'));
  // A lone applicable rule applies, with or without its probability.
  EXPECT_EQ(derive_text("seed: 3\naxiom: A\nA --> C\n", 1), "C");
  EXPECT_EQ(derive_text("seed: 3\naxiom: AA\nA --> B : 0\nA --> C : 0\n", 1), "BB");
  EXPECT_EQ(derive_text("axiom: AA\nA --> B : 0\nA --> C : 0\n", 1), "AA");
}

// A parameter is a 32-bit float in the string, as cpfg keeps it (generate.c, AppendParameter):
// 0.1 summed ten times reaches 1.0000001 and stops t < 1 at ten steps (doubles make eleven).
TEST(Cpfg, ParametersAreKeptAsFloats) {
  const std::string word = derive_text("axiom: A(0)\nA(t) : t < 1 --> F A(t+0.1)\n", 30);
  EXPECT_EQ(std::count(word.begin(), word.end(), 'F'), 10) << word;
  const ModuleString one = derive(parse_plant("axiom: A(0.1)\n"), {0, 1, 100});
  EXPECT_EQ(one.params_of(0)[0], double(0.1f));
  EXPECT_EQ(plant_error_of("axiom: A\nA --> B(1e39)\n"),
            "plant.l:2:9: the value 1e+39 is past a module parameter's range: a parameter is a 32-bit float, as in "
            "cpfg, at most 3.4e38 in magnitude while deriving step 1 (rule at 2:1)");
}

// cpfg decomposes what a step writes, never the axiom (generate.c, ApplyProd), and runs End:
// in its last step: at derivation length 0 neither happens.
TEST(Cpfg, TheAxiomIsNotDecomposedAndEndRunsInTheLastStep) {
  const std::string rules = "axiom: A\nA --> F\ndecomposition\nA --> GGG\n";
  EXPECT_EQ(derive_text(rules, 1), "F");
  EXPECT_EQ(derive_text(rules, 0), "A");
  const std::string blocks = "Start: {x = 1;}\nEnd: {x = 5;}\naxiom: A\nA --> B\n";
  std::vector<double> variables;
  derive(parse_plant(blocks), {0, 1, 100}, {}, &variables);
  EXPECT_EQ(variables.at(1), 1.0);
  derive(parse_plant(blocks), {1, 1, 100}, {}, &variables);
  EXPECT_EQ(variables.at(1), 5.0);
}

// cpp pastes a #define's body as text: one of several operands means what cpp makes of it where
// it stands (2+3 in N*2 is 2+3*2); one operand is a constant the scene may replace.
TEST(Cpfg, DefinesOfSeveralOperandsArePastedAsText) {
  EXPECT_EQ(derive_text("#define N 2+3\naxiom: B(N*2)\n", 0), "B(8)");
  EXPECT_EQ(derive_text("#define N 2\n#define M N+1\naxiom: B(M*10)\n", 0), "B(12)");
  EXPECT_EQ(derive_text("#define N (2+3)\naxiom: B(N*2)\n", 0), "B(10)");
  EXPECT_EQ(derive_text("#define N -sqrt(4)\naxiom: B(N*2)\n", 0), "B(-4)");
  const Grammar replaced = parse_grammar({{"plant.l", "#define N 2+3\naxiom: B(N*2)\n", false}}, {{"N", 4}});
  EXPECT_EQ(text_of(derive(replaced, {0, 1, 100})), "B(8)");
}

// cpfg reads '<>' as '!=' (lsys_input.l).
TEST(Cpfg, LessGreaterIsNotEqual) {
  EXPECT_EQ(derive_text("axiom: A(1)A(2)\nA(x) : x <> 2 --> B\n", 1), "BA(2)");
  EXPECT_EQ(derive_text("axiom: A(1)A(2)\nA(x) : x<>1 && x < 3 --> B\n", 1), "A(1)B");
}

// fopen(name, "r") and fscan (CPFG manual 5.4) read a data file beside the grammar, as C's
// fscanf reads numbers; writing files is refused.
TEST(Cpfg, FscanReadsADataFileBesideTheGrammar) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("treeanim_test_cpfg_fscan-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "lengths.txt") << "first: 3, 4\n5\n  6.5e0\n";
  const std::string grammar = (dir / "plant.l").string();
  const auto grow = [&](const std::string& text, int steps) {
    return text_of(derive(parse_grammar({{grammar, text, false}}, {}), {steps, 1, 100}));
  };
  const std::string reader =
      "Start: {fp = fopen(\"lengths.txt\", \"r\"); n = fscan(fp, \"first: %f,%lf\", &a, &b);}\n"
      "derivation length: 4\naxiom: C(a + b, n) A\n"
      "A : {k = fscan(fp, \"%f\", &x);} k == 1 --> B(x) A\nA : {k = fscan(fp, \"%f\", &x);} * --> E(k, x)\n"
      "End: {fclose(fp);}\n";
  EXPECT_EQ(grow(reader, 2), "C(7,2)B(5)B(6)A");
  EXPECT_EQ(grow(reader, 3), "C(7,2)B(5)B(6)E(-1,0)");  // the end of the file: -1, x keeps its value
  // %i takes C's prefixes, %d does not.
  std::ofstream(dir / "integers.txt") << "0x10 010 010\n";
  EXPECT_EQ(grow("Start: {fp = fopen(\"integers.txt\", \"r\"); n = fscan(fp, \"%i %i %d\", &a, &b, &c);}\n"
                 "axiom: A(a, b, c)\n", 0),
            "A(16,8,10)");
  const auto refused = [&](const std::string& text) {
    try {
      parse_grammar({{grammar, text, false}}, {});
    } catch (const InputError& e) {
      return std::string(e.what()).substr(grammar.size());
    }
    return std::string("no error");
  };
  EXPECT_EQ(refused("Start: {fp = fopen(\"out.txt\", \"w\");}\naxiom: A\n"),
            ":1:31: fopen(..., \"w\") writes a file, which is not supported: a grammar must not write files on a "
            "render farm (CPFG manual 5.4; fopen(name, \"r\") reads a data file beside the grammar)");
  EXPECT_EQ(refused("Start: {fp = fopen(\"../secret\", \"r\");}\naxiom: A\n"),
            ":1:20: fopen(\"../secret\") names a file outside the grammar's folder: a grammar reads only files beside "
            "it (a relative path without '..')");
  EXPECT_EQ(refused("Start: {fp = fopen(\"lengths.txt\", \"r\"); fprintf(fp, \"%f\", 1);}\naxiom: A\n"),
            ":1:41: fprintf writes to a file, which is not supported: a grammar must not write files on a render "
            "farm (CPFG manual 5.4; printf computes its values and prints nothing)");
  EXPECT_EQ(refused("Start: {fp = fopen(\"lengths.txt\", \"r\"); n = fscan(fp, \"%s\", &a);}\naxiom: A\n"),
            ":1:55: fscan: '%s' reads no number (fscan reads %f, %e, %g, %d or %i: every variable is a number)");
  EXPECT_EQ(refused("Start: {fp = fopen(\"missing.txt\", \"r\");}\naxiom: A\n").substr(0, 30),
            ":1:20: fopen cannot read '" + dir.string().substr(0, 4));
  std::filesystem::remove_all(dir);
}

TEST(Cpfg, EndlessLoopStopsWithItsPlace) {
  const Grammar g = parse_plant("axiom: A(1)\nA(x) : {while (1) {x = x;}} --> A(x)\n");
  try {
    derive(g, {1, 1, 100});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("plant.l:2:"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("a loop ran more than 10000000 times"), std::string::npos) << e.what();
  }
}

// Loops each under their own limit, in rules applied to a doubling word, stop at the turns a
// derivation takes in all (here 10^6 for 10^9): 1000 turns a module, 2^10 modules at the last step.
TEST(Cpfg, LoopsTogetherStopAtTheDerivationsBudget) {
  const Grammar g = parse_plant("axiom: A\nA : {i = 0; while (i < 1000) {i = i + 1;}} 1 --> AA\n");
  DerivationSettings settings{11, 1, 100000};
  settings.max_loop_turns = 1'000'000;
  EXPECT_EQ(derive(g, {10, 1, 100000}).size(), 1024u);  // 1023 x 1000 turns: within the default budget
  try {
    derive(g, settings);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("plant.l:2:"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("ran past the turns it may take in all"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace treeanim
