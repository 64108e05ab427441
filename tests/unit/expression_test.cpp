// Expression parser and evaluator: grammar (precedence, associativity), every function against
// <cmath>, variables, the error messages a user sees for malformed text, and the queries the
// scene loader uses (uses(), is_constant()).
#include "expression/expression.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

namespace cosph {
namespace {

double eval(const std::string& text) { return Expression::parse(text, {}).evaluate({}); }

// The same text evaluated once with constants folded at parse time and once through variables,
// so that both the folder and the interpreter are exercised. `text` uses a, b, c.
void expect_both_ways(const std::string& text, double a, double b, double c, double expected) {
  SCOPED_TRACE(text);
  const Expression e = Expression::parse(text, {"a", "b", "c"});
  EXPECT_DOUBLE_EQ(e.evaluate({a, b, c}), expected);
  std::string folded = text;
  for (const auto& [name, value] : {std::pair{'a', a}, std::pair{'b', b}, std::pair{'c', c}}) {
    // Appended rather than "(" + ... + ")": GCC 12 at -O3 reports a false -Wrestrict for that.
    std::string literal = "(";
    literal.append(std::to_string(value)).append(")");
    for (std::size_t p = folded.find(name); p != std::string::npos; p = folded.find(name)) {
      folded.replace(p, 1, literal);
    }
  }
  const Expression f = Expression::parse(folded, {});
  EXPECT_TRUE(f.is_constant());
  EXPECT_DOUBLE_EQ(f.evaluate({}), expected);
}

// Parses `text`, which must fail, and returns the error.
ExpressionError error_of(const std::string& text, const std::vector<std::string>& variables = {}) {
  try {
    Expression::parse(text, variables);
  } catch (const ExpressionError& error) {
    return error;
  }
  ADD_FAILURE() << "no ExpressionError for \"" << text << "\"";
  return ExpressionError("", std::string::npos);
}

#define EXPECT_ERROR(text, expected_position, ...)                                 \
  do {                                                                             \
    const ExpressionError error_ = error_of(text);                                 \
    EXPECT_EQ(error_.position(), std::size_t{expected_position}) << error_.what(); \
    for (const char* fragment_ : {__VA_ARGS__}) {                                  \
      EXPECT_NE(std::string(error_.what()).find(fragment_), std::string::npos)     \
          << "message \"" << error_.what() << "\" lacks \"" << fragment_ << "\"";  \
    }                                                                              \
  } while (false)

TEST(Expression, Numbers) {
  EXPECT_EQ(eval("42"), 42.0);
  EXPECT_EQ(eval("  42  "), 42.0);
  EXPECT_EQ(eval("1e-4"), 1e-4);
  EXPECT_EQ(eval("1E+3"), 1000.0);
  EXPECT_EQ(eval("2.5e2"), 250.0);
  EXPECT_EQ(eval(".5"), 0.5);
  EXPECT_EQ(eval("2."), 2.0);
  EXPECT_EQ(eval("2.e1"), 20.0);
  EXPECT_EQ(eval("0.1"), 0.1);  // parsed exactly as the C++ literal
  EXPECT_EQ(eval("pi"), std::numbers::pi);
  EXPECT_EQ(eval("e"), std::numbers::e);
}

TEST(Expression, PrecedenceAndAssociativity) {
  expect_both_ways("a+b*c", 1, 2, 3, 7);
  expect_both_ways("(a+b)*c", 1, 2, 3, 9);
  expect_both_ways("a-b-c", 1, 2, 3, -4);
  expect_both_ways("a/b/c", 8, 4, 2, 1);
  expect_both_ways("a^b^c", 2, 3, 2, 512);
  expect_both_ways("-a^b", 2, 2, 0, -4);
  expect_both_ways("(-a)^b", 2, 2, 0, 4);
  expect_both_ways("a^-b", 2, 1, 0, 0.5);
  expect_both_ways("a^-b^c", 2, 1, 2, 0.5);  // 2^-(1^2)
  expect_both_ways("a*-b", 2, 3, 0, -6);
  expect_both_ways("--a", 2, 0, 0, 2);
  expect_both_ways("+a", 2, 0, 0, 2);
  expect_both_ways("-a*b", 2, 3, 0, -6);
  expect_both_ways("a-b*c^a", 2, 3, 2, 2 - 3 * 4);
  expect_both_ways("a*b^c", 2, 3, 2, 18);
  expect_both_ways("a^2", 1.1, 0, 0, 1.1 * 1.1);
  expect_both_ways("a^2^c", 1.1, 0, 3, std::pow(1.1, 8.0));
  // Comparisons bind looser than arithmetic; && binds tighter than || as in C.
  expect_both_ways("a+b<c", 1, 1, 3, 1);
  expect_both_ways("a+b<c", 1, 2, 3, 0);
  expect_both_ways("a<b==b<c", 1, 2, 3, 1);  // (1<2)==(2<3)
  expect_both_ways("a||b&&c", 1, 0, 0, 1);   // left-to-right would give 0
  expect_both_ways("a*b<=c-1", 1, 2, 3, 1);
  // The literal cases from the grammar's documentation.
  EXPECT_EQ(eval("-2^2"), -4.0);
  EXPECT_EQ(eval("2^3^2"), 512.0);
  EXPECT_EQ(eval("1-2-3"), -4.0);
  EXPECT_EQ(eval("8/4/2"), 1.0);
}

struct FunctionCase {
  std::string name;
  std::function<double(double)> reference;
  std::vector<double> arguments;
};

TEST(Expression, UnaryFunctionsMatchCmath) {
  const std::vector<double> anywhere = {-2.7, -1.0, -0.3, 0.0, 0.4, 1.0, 3.9};
  const std::vector<double> unit = {-1.0, -0.6, 0.0, 0.25, 1.0};
  const std::vector<double> positive = {1e-3, 0.5, 1.0, 2.0, 1e4};
  const std::vector<FunctionCase> cases = {
      {"sin", [](double v) { return std::sin(v); }, anywhere},
      {"cos", [](double v) { return std::cos(v); }, anywhere},
      {"tan", [](double v) { return std::tan(v); }, anywhere},
      {"asin", [](double v) { return std::asin(v); }, unit},
      {"acos", [](double v) { return std::acos(v); }, unit},
      {"atan", [](double v) { return std::atan(v); }, anywhere},
      {"sinh", [](double v) { return std::sinh(v); }, anywhere},
      {"cosh", [](double v) { return std::cosh(v); }, anywhere},
      {"tanh", [](double v) { return std::tanh(v); }, anywhere},
      {"exp", [](double v) { return std::exp(v); }, anywhere},
      {"log", [](double v) { return std::log(v); }, positive},
      {"log10", [](double v) { return std::log10(v); }, positive},
      {"sqrt", [](double v) { return std::sqrt(v); }, positive},
      {"abs", [](double v) { return std::abs(v); }, anywhere},
      {"erf", [](double v) { return std::erf(v); }, anywhere},
      {"erfc", [](double v) { return std::erfc(v); }, anywhere},
      {"floor", [](double v) { return std::floor(v); }, anywhere},
      {"ceil", [](double v) { return std::ceil(v); }, anywhere},
      {"heaviside", [](double v) { return v >= 0.0 ? 1.0 : 0.0; }, anywhere},
  };
  for (const FunctionCase& c : cases) {
    const Expression e = Expression::parse(c.name + "(x)", {"x"});
    for (double v : c.arguments) {
      SCOPED_TRACE(c.name + "(" + std::to_string(v) + ")");
      EXPECT_DOUBLE_EQ(e.evaluate({v}), c.reference(v));
      // Folded at parse time, through the same code path.
      EXPECT_EQ(eval(c.name + "(" + std::to_string(v) + ")"),
                e.evaluate({std::stod(std::to_string(v))}));
    }
  }
  EXPECT_EQ(eval("heaviside(-1e-300)"), 0.0);
  EXPECT_EQ(eval("heaviside(0)"), 1.0);
  EXPECT_EQ(eval("heaviside(-0)"), 1.0);  // -0 >= 0
}

TEST(Expression, MultiArgumentFunctions) {
  const Expression atan2 = Expression::parse("atan2(y, x)", {"x", "y"});
  for (double y : {-1.5, 0.0, 2.0}) {
    for (double x : {-0.5, 0.0, 3.0}) {
      EXPECT_DOUBLE_EQ(atan2.evaluate({x, y}), std::atan2(y, x)) << y << ", " << x;
    }
  }
  const Expression pow = Expression::parse("pow(x, y)", {"x", "y"});
  EXPECT_DOUBLE_EQ(pow.evaluate({2.0, 0.5}), std::pow(2.0, 0.5));
  EXPECT_DOUBLE_EQ(pow.evaluate({1.7, -3.2}), std::pow(1.7, -3.2));
  EXPECT_DOUBLE_EQ(pow.evaluate({-2.0, 3.0}), -8.0);
  EXPECT_EQ(eval("pow(2, 10)"), 1024.0);

  const Expression min = Expression::parse("min(x, y, 3)", {"x", "y"});
  const Expression max = Expression::parse("max(x, y, 3)", {"x", "y"});
  EXPECT_EQ(min.evaluate({5.0, 4.0}), 3.0);
  EXPECT_EQ(min.evaluate({-1.0, 4.0}), -1.0);
  EXPECT_EQ(min.evaluate({5.0, -2.0}), -2.0);
  EXPECT_EQ(max.evaluate({1.0, 2.0}), 3.0);
  EXPECT_EQ(max.evaluate({7.0, 2.0}), 7.0);
  EXPECT_EQ(max.evaluate({1.0, 9.0}), 9.0);
  EXPECT_EQ(eval("min(4, 2)"), 2.0);
  EXPECT_EQ(eval("max(4, 2)"), 4.0);
  EXPECT_EQ(eval("min(4)"), 4.0);
  EXPECT_EQ(eval("max(1, 5, 2, 8, 3)"), 8.0);
  // Nested calls and expressions as arguments.
  const Expression nested = Expression::parse("max(min(x, 1), -1) + pow(x, 2)", {"x"});
  EXPECT_EQ(nested.evaluate({3.0}), 1.0 + 9.0);
  EXPECT_EQ(nested.evaluate({-0.5}), -0.5 + 0.25);
}

TEST(Expression, VariablesInAnyOrder) {
  const std::string text = "x - 2*y + 10*z";
  const Expression xyz = Expression::parse(text, {"x", "y", "z"});
  const Expression zxy = Expression::parse(text, {"z", "x", "y"});
  const Expression tyzx = Expression::parse(text, {"t", "y", "z", "x"});
  EXPECT_EQ(xyz.evaluate({1.0, 2.0, 3.0}), 1.0 - 4.0 + 30.0);
  EXPECT_EQ(zxy.evaluate({3.0, 1.0, 2.0}), 1.0 - 4.0 + 30.0);
  EXPECT_EQ(tyzx.evaluate({99.0, 2.0, 3.0, 1.0}), 1.0 - 4.0 + 30.0);
  // Longer names, and names that start like a function or constant.
  const Expression long_names = Expression::parse("rho_0 * exp(-time/tau) + pi_x + e2",
                                                  {"time", "tau", "rho_0", "pi_x", "e2"});
  EXPECT_DOUBLE_EQ(long_names.evaluate({2.0, 4.0, 1000.0, 0.25, 0.5}),
                   1000.0 * std::exp(-0.5) + 0.75);
  // The values can come from any contiguous storage.
  const std::vector<double> values = {1.0, 2.0, 3.0};
  EXPECT_EQ(xyz.evaluate(values), 27.0);
}

TEST(Expression, RejectsBadVariableNames) {
  EXPECT_THROW(Expression::parse("1", {"x", "x"}), std::invalid_argument);
  EXPECT_THROW(Expression::parse("1", {"e"}), std::invalid_argument);
  EXPECT_THROW(Expression::parse("1", {"sin"}), std::invalid_argument);
  EXPECT_THROW(Expression::parse("1", {"2x"}), std::invalid_argument);
  EXPECT_THROW(Expression::parse("1", {""}), std::invalid_argument);
  EXPECT_NO_THROW(Expression::parse("1", {"_x1"}));
}

TEST(Expression, ComparisonsLogicAndIf) {
  const Expression lt = Expression::parse("x < y", {"x", "y"});
  const Expression le = Expression::parse("x <= y", {"x", "y"});
  const Expression gt = Expression::parse("x > y", {"x", "y"});
  const Expression ge = Expression::parse("x >= y", {"x", "y"});
  const Expression eq = Expression::parse("x == y", {"x", "y"});
  const Expression ne = Expression::parse("x != y", {"x", "y"});
  const Expression conj = Expression::parse("x && y", {"x", "y"});
  const Expression disj = Expression::parse("x || y", {"x", "y"});
  for (double x : {-1.0, 0.0, 2.0}) {
    for (double y : {-1.0, 0.0, 2.0}) {
      SCOPED_TRACE(std::to_string(x) + ", " + std::to_string(y));
      EXPECT_EQ(lt.evaluate({x, y}), x < y ? 1.0 : 0.0);
      EXPECT_EQ(le.evaluate({x, y}), x <= y ? 1.0 : 0.0);
      EXPECT_EQ(gt.evaluate({x, y}), x > y ? 1.0 : 0.0);
      EXPECT_EQ(ge.evaluate({x, y}), x >= y ? 1.0 : 0.0);
      EXPECT_EQ(eq.evaluate({x, y}), x == y ? 1.0 : 0.0);
      EXPECT_EQ(ne.evaluate({x, y}), x != y ? 1.0 : 0.0);
      EXPECT_EQ(conj.evaluate({x, y}), (x != 0.0 && y != 0.0) ? 1.0 : 0.0);
      EXPECT_EQ(disj.evaluate({x, y}), (x != 0.0 || y != 0.0) ? 1.0 : 0.0);
    }
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(lt.evaluate({nan, 1.0}), 0.0);
  EXPECT_EQ(ne.evaluate({nan, nan}), 1.0);

  // A disc of radius 0.5 around (1, 0): the typical use of if() in an initial condition.
  const Expression disc = Expression::parse("if((x-1)^2 + y^2 < 0.25, 1000, 1.2)", {"x", "y"});
  EXPECT_EQ(disc.evaluate({1.1, 0.2}), 1000.0);
  EXPECT_EQ(disc.evaluate({0.0, 0.0}), 1.2);
  const Expression band = Expression::parse("if(y > 0.4 && y < 0.6, 1, 0) * 2", {"y"});
  EXPECT_EQ(band.evaluate({0.5}), 2.0);
  EXPECT_EQ(band.evaluate({0.7}), 0.0);
  EXPECT_EQ(band.evaluate({0.3}), 0.0);
  const Expression nested = Expression::parse("if(x < 0, -1, if(x > 0, 1, 0))", {"x"});
  EXPECT_EQ(nested.evaluate({-3.0}), -1.0);
  EXPECT_EQ(nested.evaluate({0.0}), 0.0);
  EXPECT_EQ(nested.evaluate({3.0}), 1.0);
  // Both branches are evaluated; a NaN in the branch not taken does not leak.
  const Expression guarded = Expression::parse("if(x >= 0, sqrt(x), 0)", {"x"});
  EXPECT_EQ(guarded.evaluate({-4.0}), 0.0);
  EXPECT_EQ(guarded.evaluate({4.0}), 2.0);
}

TEST(Expression, SceneExamplesMatchHandWrittenCpp) {
  const Expression gaussian = Expression::parse("exp(-((x-1)^2 + y^2)/0.25)", {"x", "y", "z", "t"});
  for (double x : {-0.5, 0.9, 1.0, 1.3}) {
    for (double y : {-0.2, 0.0, 0.45}) {
      const double expected = std::exp(-((x - 1) * (x - 1) + y * y) / 0.25);
      EXPECT_DOUBLE_EQ(gaussian.evaluate({x, y, 0.0, 7.0}), expected) << x << ", " << y;
    }
  }
  EXPECT_EQ(gaussian.evaluate({1.0, 0.0, 0.0, 0.0}), 1.0);

  const Expression band = Expression::parse(
      "0.5*(erf((y-0.4)/sqrt(4*1e-4*t)) - erf((y-0.6)/sqrt(4*1e-4*t)))", {"x", "y", "z", "t"});
  for (double y : {0.3, 0.41, 0.5, 0.62}) {
    for (double t : {0.01, 1.0, 25.0}) {
      const double s = std::sqrt(4 * 1e-4 * t);
      const double expected = 0.5 * (std::erf((y - 0.4) / s) - std::erf((y - 0.6) / s));
      EXPECT_DOUBLE_EQ(band.evaluate({0.0, y, 0.0, t}), expected) << y << ", " << t;
    }
  }
  // At t = 0 the divisions give +-inf and erf(+-inf) = +-1: the sharp initial step.
  EXPECT_EQ(band.evaluate({0.0, 0.5, 0.0, 0.0}), 1.0);
  EXPECT_EQ(band.evaluate({0.0, 0.3, 0.0, 0.0}), 0.0);
  EXPECT_EQ(band.evaluate({0.0, 0.7, 0.0, 0.0}), 0.0);
}

TEST(Expression, UnknownIdentifierIsNamedWithPositionAndAlternatives) {
  const ExpressionError error = error_of("exp(-foo)", {"x", "y"});
  EXPECT_EQ(error.position(), 5u);
  const std::string message = error.what();
  for (const char* fragment : {"exp(-foo)", "'foo'", "position 5", "variables: x, y",
                               "constants: pi, e", "sin", "erfc", "heaviside"}) {
    EXPECT_NE(message.find(fragment), std::string::npos) << message << " lacks " << fragment;
  }
  EXPECT_EQ(message.find("did you mean"), std::string::npos) << message;

  const ExpressionError misspelt = error_of("2*sni(x)", {"x"});
  EXPECT_EQ(misspelt.position(), 2u);
  EXPECT_NE(std::string(misspelt.what()).find("did you mean 'sin'"), std::string::npos)
      << misspelt.what();
  // A variable that exists elsewhere but was not declared for this expression.
  EXPECT_EQ(error_of("x + t", {"x", "y"}).position(), 4u);
  EXPECT_NE(std::string(error_of("x", {}).what()).find("variables: (none)"), std::string::npos);
  // Names are case-sensitive.
  EXPECT_EQ(error_of("Sin(1)").position(), 0u);
}

TEST(Expression, UnbalancedParentheses) {
  EXPECT_ERROR("(1+2", 0, "'(' at position 0 is never closed");
  EXPECT_ERROR("2*((1+2)", 2, "'(' at position 2 is never closed");
  EXPECT_ERROR("sin(1", 3, "never closed");
  EXPECT_ERROR("1+2)", 3, "unmatched ')' at position 3");
  EXPECT_ERROR("(1+2))", 5, "unmatched ')'");
  EXPECT_ERROR("(1 2)", 3, "'2' at position 3", "')' to close '(' at position 0");
  EXPECT_ERROR("()", 1, "unexpected ')' at position 1");
  EXPECT_ERROR(")", 0, "unexpected ')'");
}

TEST(Expression, TrailingGarbageAndMissingOperands) {
  EXPECT_ERROR("1+2 3", 4, "expected an operator before '3' at position 4");
  EXPECT_ERROR("2x", 1, "'x' at position 1", "'*'");
  EXPECT_ERROR("2 pi", 2, "'pi'");
  EXPECT_ERROR("2(3)", 1, "'('");
  EXPECT_ERROR("1,2", 1, "','");
  EXPECT_ERROR("1+", 2, "end of the expression");
  EXPECT_ERROR("*2", 0, "unexpected '*' at position 0");
  EXPECT_ERROR("1 = 2", 2, "did you mean '=='");
  EXPECT_ERROR("1 & 2", 2, "did you mean '&&'");
  EXPECT_ERROR("2**3", 1, "'^'");
  EXPECT_ERROR("1 # 2", 2, "unexpected character '#' at position 2");
  EXPECT_ERROR("1 + \x01", 4, "byte 0x01");
  EXPECT_ERROR("sin", 0, "'sin'", "parentheses");
  EXPECT_ERROR("sin x", 0, "parentheses");
}

TEST(Expression, EmptyText) {
  EXPECT_ERROR("", 0, "empty");
  EXPECT_ERROR("   \t", 0, "empty");
}

TEST(Expression, WrongArgumentCount) {
  EXPECT_ERROR("sin(1, 2)", 0, "sin() at position 0 takes 1 argument, not 2");
  EXPECT_ERROR("1 + sin()", 4, "takes 1 argument, not 0");
  EXPECT_ERROR("atan2(1)", 0, "takes 2 arguments, not 1");
  EXPECT_ERROR("pow(1, 2, 3)", 0, "takes 2 arguments, not 3");
  EXPECT_ERROR("if(1, 2)", 0, "takes 3 arguments, not 2");
  EXPECT_ERROR("min()", 0, "at least 1");
  EXPECT_ERROR("max(1,)", 6, "unexpected ')'");
  EXPECT_ERROR("heaviside(1, 2)", 0, "heaviside()");
}

TEST(Expression, MalformedNumbers) {
  EXPECT_ERROR("1e", 0, "malformed number '1e' at position 0", "exponent");
  EXPECT_ERROR("2*1e+", 2, "'1e+'");
  EXPECT_ERROR("3 - 2.5E-x", 4, "'2.5E-'");
  EXPECT_ERROR("1.2.3", 0, "'1.2.3'");
  EXPECT_ERROR("1e999", 0, "double");
  EXPECT_ERROR(".", 0, "'.'");
}

TEST(Expression, NestingIsBounded) {
  // Deep parentheses would overflow the parser's own stack; deep right-nested operations the
  // evaluation stack. Both are reported, not crashed on.
  EXPECT_ERROR(std::string(1000, '(') + "1" + std::string(1000, ')'), 200,
               "nested too deeply at position 200");
  // The message quotes only the part of a long text around the problem.
  EXPECT_LT(std::string(error_of(std::string(1000, '(')).what()).size(), 200u);
  std::string deep = "x";
  for (int i = 0; i < 100; ++i) deep = "x+(" + deep + ")";
  const ExpressionError error = error_of(deep, {"x"});
  EXPECT_NE(std::string(error.what()).find("nested too deeply"), std::string::npos);
  // Moderate nesting is fine.
  std::string moderate = "x";
  for (int i = 0; i < 30; ++i) moderate = "x+(" + moderate + ")";
  EXPECT_EQ(Expression::parse(moderate, {"x"}).evaluate({1.0}), 31.0);
  // Long flat sums need only two stack slots.
  std::string flat = "x";
  for (int i = 0; i < 1000; ++i) flat += "+x";
  EXPECT_EQ(Expression::parse(flat, {"x"}).evaluate({1.0}), 1001.0);
}

TEST(Expression, UsesAndIsConstant) {
  const Expression e = Expression::parse("x + 0*y", {"x", "y", "z"});
  EXPECT_TRUE(e.uses("x"));
  EXPECT_TRUE(e.uses("y"));  // occurs, even though it cannot change the value
  EXPECT_FALSE(e.uses("z"));
  EXPECT_FALSE(e.uses("w"));
  EXPECT_FALSE(e.is_constant());
  EXPECT_EQ(e.text(), "x + 0*y");

  const Expression c = Expression::parse("2*pi*sin(pi/6) + e", {"x", "t"});
  EXPECT_TRUE(c.is_constant());
  EXPECT_FALSE(c.uses("x"));
  EXPECT_FALSE(c.uses("t"));
  EXPECT_DOUBLE_EQ(c.evaluate({123.0, 456.0}), 2 * std::numbers::pi * 0.5 + std::numbers::e);

  EXPECT_FALSE(Expression::parse("if(1, 2, t)", {"t"}).is_constant());
  EXPECT_TRUE(Expression::parse("if(1, 2, 3)", {"t"}).is_constant());

  const Expression zero;
  EXPECT_TRUE(zero.is_constant());
  EXPECT_EQ(zero.text(), "0");
  EXPECT_EQ(zero.evaluate({}), 0.0);
}

TEST(Expression, CopiesAreIndependentOfTheOriginal) {
  std::vector<Expression> expressions;
  {
    const Expression original = Expression::parse("x^2 + t", {"x", "t"});
    expressions.push_back(original);
    expressions.push_back(Expression::parse("erf(x)", {"x", "t"}));
  }
  expressions.reserve(100);  // moves the elements
  EXPECT_EQ(expressions[0].evaluate({3.0, 1.0}), 10.0);
  EXPECT_EQ(expressions[1].evaluate({0.5, 1.0}), std::erf(0.5));
  EXPECT_TRUE(expressions[0].uses("t"));
  EXPECT_EQ(expressions[0].text(), "x^2 + t");
}

}  // namespace
}  // namespace cosph
