// Derivation: module counts against independent recurrences, contexts (signal propagation),
// stochastic choice, decomposition, homomorphism, cut, the module cap, runtime errors.
#include <gtest/gtest.h>

#include <map>
#include <string>

#include "common/errors.h"
#include "lsystem/derive.h"
#include "lsystem/grammar.h"

namespace treeanim {
namespace {

Grammar parse_lsys(const std::string& text) { return parse_grammar({{"g.lsys", text, false}}, {}); }

ModuleString run(const std::string& text, int iterations, uint64_t seed = 1, size_t max_modules = 20'000'000) {
  return derive(parse_lsys(text), DerivationSettings{iterations, seed, max_modules});
}

std::string symbols(const ModuleString& word) { return std::string(word.symbols.begin(), word.symbols.end()); }

// Symbol counts after n steps of a context-free non-parametric L-system, by the linear
// recurrence count'(t) = sum_s count(s) * occurrences of t in successor(s): the expectation,
// computed without the parser or the deriver.
size_t expected_length(const std::string& axiom, const std::map<char, std::string>& rules, int steps) {
  std::map<char, size_t> count;
  for (char c : axiom) ++count[c];
  for (int step = 0; step < steps; ++step) {
    std::map<char, size_t> next;
    for (const auto& [symbol, n] : count) {
      const auto rule = rules.find(symbol);
      const std::string successor = rule == rules.end() ? std::string(1, symbol) : rule->second;
      for (char c : successor) next[c] += n;
    }
    count = next;
  }
  size_t total = 0;
  for (const auto& entry : count) total += entry.second;
  return total;
}

TEST(Derive, ClosedFormForAbop124a) {
  // F --> F[+F]F[-F]F: F_n = 5^n, and each rewritten F adds 6 other modules:
  // total_n = 5^n + 6 (5^n - 1) / 4.
  const Grammar g = parse_lsys("axiom: F\nF --> F[+F]F[-F]F\n");
  size_t five = 1;
  for (int n = 0; n <= 6; ++n) {
    EXPECT_EQ(derive(g, {n, 1, 20'000'000}).size(), five + 6 * (five - 1) / 4) << n;
    five *= 5;
  }
}

TEST(Derive, CountsPerStepForAbopBracketedGrammars) {
  struct Case {
    std::string axiom;
    std::map<char, std::string> rules;
  };
  const Case cases[] = {
      {"F", {{'F', "F[+F]F[-F][F]"}}},                                // 1.24b
      {"F", {{'F', "FF-[-F+F+F]+[+F-F-F]"}}},                         // 1.24c
      {"X", {{'X', "F[+X]F[-X]+X"}, {'F', "FF"}}},                    // 1.24d
      {"X", {{'X', "F[+X][-X]FX"}, {'F', "FF"}}},                     // 1.24e
      {"X", {{'X', "F-[[X]+X]+F[+FX]-X"}, {'F', "FF"}}},              // 1.24f
      {"A", {{'A', "[&FL!A]/////'[&FL!A]///////'[&FL!A]"}, {'F', "S/////F"}, {'S', "FL"},
             {'L', "['''^^{-f+f+f-|-f+f+f}]"}}},                      // 1.25
  };
  for (const Case& c : cases) {
    std::string text = "axiom: " + c.axiom + "\n";
    for (const auto& [symbol, successor] : c.rules) text += std::string(1, symbol) + " --> " + successor + "\n";
    const Grammar g = parse_lsys(text);
    for (int n = 0; n <= 5; ++n)
      EXPECT_EQ(derive(g, {n, 1, 20'000'000}).size(), expected_length(c.axiom, c.rules, n)) << text << n;
  }
}

TEST(Derive, ClosedFormForParametricAbop26) {
  // Fig. 2.6: each apex (A, B, C) becomes 2 apices and 6 other modules (! F [ & ] / or
  // ! F [ - $ ]): apices_n = 2^n, total_n = 2^n + 6 (2^n - 1).
  const Grammar g = parse_lsys(
      "#define r1 0.9\n#define r2 0.6\n#define a0 45\n#define a2 45\n#define d 137.5\n#define wr 0.707\n"
      "axiom: A(1,10)\n"
      "A(l,w) --> !(w)F(l)[&(a0)B(l*r2,w*wr)]/(d)A(l*r1,w*wr)\n"
      "B(l,w) --> !(w)F(l)[-(a2)$C(l*r2,w*wr)]C(l*r1,w*wr)\n"
      "C(l,w) --> !(w)F(l)[+(a2)$B(l*r2,w*wr)]B(l*r1,w*wr)\n");
  for (int n = 0; n <= 12; ++n) {
    const size_t apices = size_t{1} << n;
    EXPECT_EQ(derive(g, {n, 1, 20'000'000}).size(), apices + 6 * (apices - 1)) << n;
  }
  // The trunk's n-th internode has length r1^(n-1) (the first F after n steps is F(1)).
  const ModuleString word = derive(g, {3, 1, 1000});
  EXPECT_EQ(word.symbols[1], 'F');
  EXPECT_EQ(word.params_of(1)[0], 1.0);
  EXPECT_EQ(word.params_of(0)[0], 10.0);
}

TEST(Derive, ParametricValuesFollowTheProductions) {
  // Fig. 2.8's F(l) --> F(l*lr) and !(w) --> !(w*vr): after n steps l = 200 lr^n, w = vr^n.
  const ModuleString word = run("#define lr 1.109\n#define vr 1.732\naxiom: !(1)F(200)/(45)A\n"
                                "F(l) --> F(l*lr)\n!(w) --> !(w*vr)\n", 4);
  ASSERT_EQ(symbols(word), "!F/A");
  double l = 200, w = 1;  // each step's product kept as the string keeps it, a 32-bit float
  for (int n = 0; n < 4; ++n) {
    l = double(float(l * 1.109));
    w = double(float(w * 1.732));
  }
  EXPECT_EQ(word.params_of(0)[0], w);
  EXPECT_EQ(word.params_of(1)[0], l);
  EXPECT_EQ(word.params_of(2)[0], 45.0);
  EXPECT_TRUE(word.params_of(3).empty());
}

TEST(Derive, ConditionsPickTheFirstApplicableRule) {
  // A counts down; the first rule whose condition holds wins, in text order.
  const ModuleString word = run("axiom: A(3)\nA(n) : n > 0 --> F(n)A(n-1)\nA(n) : n == 0 --> X\nA(n) --> Y\n", 5);
  EXPECT_EQ(symbols(word), "FFFX");
  EXPECT_EQ(word.params_of(0)[0], 3.0);
  EXPECT_EQ(word.params_of(2)[0], 1.0);
}

// ABOP Fig. 1.31a: an acropetal signal b climbs the main axis and enters each branch,
// skipping branches to its left (left context climbs out of branches and skips complete ones).
TEST(Derive, AcropetalSignalWithLeftContext) {
  const Grammar g = parse_lsys("ignore: +-F\naxiom: Fb[+Fa]Fa[-Fa]Fa[+Fa]Fa\nb < a --> b\nb --> a\n");
  const std::string expected[] = {
      "Fb[+Fa]Fa[-Fa]Fa[+Fa]Fa", "Fa[+Fb]Fb[-Fa]Fa[+Fa]Fa", "Fa[+Fa]Fa[-Fb]Fb[+Fa]Fa",
      "Fa[+Fa]Fa[-Fa]Fa[+Fb]Fb", "Fa[+Fa]Fa[-Fa]Fa[+Fa]Fa"};
  for (int n = 0; n < 5; ++n) EXPECT_EQ(symbols(derive(g, {n, 1, 1000})), expected[n]) << n;
}

// ABOP Fig. 1.31b: a basipetal signal moves down the main axis; the right context skips the
// lateral branches, and a module at the end of a branch (before ']') has no right context.
// A left context steps over every earlier sibling branch and ignored symbol to the module
// below them (found once per step for the whole word, not walked again for each module).
TEST(Derive, LeftContextStepsOverSiblingBranches) {
  EXPECT_EQ(symbols(run("axiom: A[X][X]F[X][B[X]]\nignore: F\nA < X --> Z\n", 1)), "A[Z][Z]F[Z][B[X]]");
  EXPECT_EQ(symbols(run("axiom: A[X][X]F[X]\nA < X --> Z\n", 1)), "A[Z][Z]F[X]");
  EXPECT_EQ(symbols(run("axiom: X[X]A\nA < X --> Z\n", 1)), "X[X]A");  // nothing to the left
}

// A right context steps over lateral branches and ignored symbols, and stops at the end of
// its own branch (found once per step for the whole word, as the left walks are).
TEST(Derive, RightContextStepsOverBranchesToTheBranchEnd) {
  EXPECT_EQ(symbols(run("axiom: XF[X]XXB[XF]\nignore: F\nX > B --> Z\n", 1)), "XF[X]XZB[XF]");
  EXPECT_EQ(symbols(run("axiom: X[A]F[B]FB\nignore: F\nX > B --> Z\n", 1)), "Z[A]F[B]FB");
  EXPECT_EQ(symbols(run("axiom: XXXXB\nignore: X\nX > B --> Z\n", 1)), "ZZZZB");
}

TEST(Derive, BasipetalSignalWithRightContext) {
  const Grammar g = parse_lsys("ignore: +-F\naxiom: Fa[+Fa]Fa[-Fa]Fa[+Fa]Fb\na > b --> b\nb --> a\n");
  const std::string expected[] = {
      "Fa[+Fa]Fa[-Fa]Fa[+Fa]Fb", "Fa[+Fa]Fa[-Fa]Fb[+Fa]Fa", "Fa[+Fa]Fb[-Fa]Fa[+Fa]Fa",
      "Fb[+Fa]Fa[-Fa]Fa[+Fa]Fa", "Fa[+Fa]Fa[-Fa]Fa[+Fa]Fa"};
  for (int n = 0; n < 5; ++n) EXPECT_EQ(symbols(derive(g, {n, 1, 1000})), expected[n]) << n;
}

TEST(Derive, ContextsWithoutIgnoreSeeEveryModule) {
  // Without ignore:, the F between b and a hides the context.
  EXPECT_EQ(symbols(run("axiom: bFa\nb < a --> b\n", 1)), "bFa");
  EXPECT_EQ(symbols(run("axiom: bFa\nconsider: ab\nb < a --> b\n", 1)), "bFb");
}

TEST(Derive, ParametricContextsBindTheirFormals) {
  // Each B adds its left neighbour's value and its right neighbour's (across a branch).
  const ModuleString word =
      run("axiom: B(1)B(10)[B(5)]B(100)\nB(x) < B(y) > B(z) --> B(x+y+z)\n", 1);
  ASSERT_EQ(symbols(word), "BB[B]B");
  EXPECT_EQ(word.params_of(0)[0], 1.0);    // no left context
  EXPECT_EQ(word.params_of(1)[0], 111.0);  // 1 + 10 + 100 (the branch is skipped)
  EXPECT_EQ(word.params_of(3)[0], 5.0);    // B(5) ends its branch: no right context
  EXPECT_EQ(word.params_of(5)[0], 100.0);  // last module: no right context
}

TEST(Derive, RightContextWithBrackets) {
  // a > [b]c: the pattern enters the branch, then leaves it with ']'.
  EXPECT_EQ(symbols(run("axiom: a[bd]c\na > [b]c --> x\n", 1)), "x[bd]c");
  EXPECT_EQ(symbols(run("axiom: a[bd]e\na > [b]c --> x\n", 1)), "a[bd]e");
}

TEST(Derive, StochasticChoiceIsReproducibleAndSeedDependent) {
  const std::string text = "axiom: F\nF --> F[+F]F[-F]F : 0.33\nF --> F[+F]F : 0.33\nF --> F[-F]F : 0.34\n";
  const Grammar g = parse_lsys(text);
  const std::string a = symbols(derive(g, {5, 7, 20'000'000}));
  EXPECT_EQ(a, symbols(derive(g, {5, 7, 20'000'000})));
  int different = 0;
  for (uint64_t seed = 8; seed < 12; ++seed) different += symbols(derive(g, {5, seed, 20'000'000})) != a;
  EXPECT_EQ(different, 4);
}

TEST(Derive, StochasticFrequenciesFollowTheWeights) {
  // 4000 A's choose B with weight 1 and C with weight 3: C about 3000 (binomial sd 27).
  const std::string axiom(4000, 'A');
  const ModuleString word = run("axiom: " + axiom + "\nA --> B : 1\nA --> C : 3\n", 1, 3);
  const std::string s = symbols(word);
  const auto c = std::count(s.begin(), s.end(), 'C');
  EXPECT_EQ(std::count(s.begin(), s.end(), 'B') + c, 4000);
  EXPECT_NEAR(static_cast<double>(c), 3000.0, 150.0);
}

TEST(Derive, StochasticWeightsWhoseSumOverflowsKeepTheirRatios) {
  // Two weights of 1.5e308 sum to inf: the draw still picks each about half the time, and
  // exactly as weights of 1 do (a power-of-two scale changes no comparison).
  const std::string axiom(4000, 'A');
  const std::string huge = symbols(run("axiom: " + axiom + "\nA --> B : 1.5e308\nA --> C : 1.5e308\n", 1, 3));
  const auto c = std::count(huge.begin(), huge.end(), 'C');
  EXPECT_NEAR(static_cast<double>(c), 2000.0, 150.0);
  EXPECT_EQ(huge, symbols(run("axiom: " + axiom + "\nA --> B : 1\nA --> C : 1\n", 1, 3)));
}

TEST(Derive, StochasticDrawDependsOnPositionNotOnTheRestOfTheString) {
  // The draw of a module is keyed by (seed, step, position): appending modules after it
  // does not change the choice made for the first 100.
  const std::string rules = "\nA --> B : 1\nA --> C : 1\n";
  const std::string short_word = symbols(run("axiom: " + std::string(100, 'A') + rules, 1, 5));
  const std::string long_word = symbols(run("axiom: " + std::string(300, 'A') + rules, 1, 5));
  EXPECT_EQ(long_word.substr(0, 100), short_word);
}

TEST(Derive, DecompositionAfterEveryStepUpToMaximumDepth) {
  auto with_depth = [](const std::string& depth) {
    return "axiom: A\nA --> AB\ndecomposition\nmaximum depth: " + depth + "\nB --> CD\nC --> E\n";
  };
  const Grammar deep = parse_lsys(with_depth("2"));
  EXPECT_EQ(symbols(derive(deep, {1, 1, 1000})), "AED");
  EXPECT_EQ(symbols(derive(deep, {3, 1, 1000})), "AEDEDED");
  // Depth 1 leaves C of step 1 undecomposed; step 2 decomposes it (decomposition applies to
  // every module after each step): AB C D => A CD E D.
  EXPECT_EQ(symbols(derive(parse_lsys(with_depth("1")), {2, 1, 1000})), "ACDED");
}

TEST(Derive, HomomorphismOnlyForInterpretation) {
  const Grammar g = parse_lsys("axiom: A(2)\nA(x) --> A(x+1)\nF(l) --> G\nhomomorphism\nA(x) --> F(x*2)+\n");
  const DerivationSettings settings{2, 1, 1000};
  const ModuleString word = derive(g, settings);
  ASSERT_EQ(symbols(word), "A");  // the derivation never sees the homomorphism's F
  EXPECT_EQ(word.params_of(0)[0], 4.0);
  const ModuleString shown = apply_homomorphism(g, word, settings);
  ASSERT_EQ(symbols(shown), "F+");
  EXPECT_EQ(shown.params_of(0)[0], 8.0);
}

TEST(Derive, EmptySuccessorAndCut) {
  EXPECT_EQ(symbols(run("axiom: AXB\nX --> *\n", 1)), "AB");
  // '%' removes the rest of its branch, and of the string at the top level.
  EXPECT_EQ(symbols(run("axiom: F[FAF[F]F]FA\nA --> %\n", 1)), "F[F]F");
}

TEST(Derive, ModuleCapNamesStepAndCount) {
  try {
    run("axiom: F\nF --> FF\n", 30, 1, 1000);
    FAIL() << "expected the module cap";
  } catch (const InputError& error) {
    // 2^10 F would be 1024: the check after each successor stops at 501 F rewritten.
    EXPECT_STREQ(error.what(), "g.lsys: derivation step 10 of 30 reached 1002 modules, more than "
                               "lsystem.max_modules = 1000 (lower lsystem.iterations or raise lsystem.max_modules)");
  }
}

TEST(Derive, DivisionByZeroNamesTheOperatorStepAndRule) {
  try {
    run("axiom: A(3)\n\nA(x) --> A(x-1)F(10/(x-1))\n", 5);
    FAIL() << "expected a division by zero";
  } catch (const InputError& error) {
    EXPECT_STREQ(error.what(), "g.lsys:3:20: division by zero while deriving step 3 (rule at 3:1)");
  }
}

TEST(Derive, NegativeProbabilityIsAnError) {
  try {
    run("axiom: A(1)\nA(x) --> B : x - 2\nA(x) --> C : 1\n", 1);
    FAIL() << "expected an error";
  } catch (const InputError& error) {
    EXPECT_STREQ(error.what(), "g.lsys:2:14: expected a probability >= 0, got -1 while deriving step 1 (rule at 2:1)");
  }
}

}  // namespace
}  // namespace treeanim
