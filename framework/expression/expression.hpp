// Math expressions written in scene files: initial fields, prescribed values and analytic
// reference solutions such as "exp(-((x-1)^2 + y^2)/0.25)". They are evaluated once per particle
// and time step, so parsing compiles the text to a flat postfix program that evaluate() runs on a
// small fixed-size stack without allocating or recursing.
//
// Grammar, loosest binding first (all binary operators left-associative except '^'):
//   ||            logical or, 1 or 0
//   &&            logical and, 1 or 0
//   == !=         equality, 1 or 0
//   < <= > >=     ordering, 1 or 0 (NaN compares false, as in C++)
//   + -           binary
//   * /
//   + -           unary; binds looser than '^' so that -2^2 = -4, as in mathematics
//   ^             power, right-associative: 2^3^2 = 2^9; the exponent may carry a sign: 2^-1
//   number (1, 2., .5, 1e-4), variable, pi, e, function(arguments), (expression)
// Functions: sin cos tan asin acos atan atan2(y,x) sinh cosh tanh exp log log10 sqrt abs erf
// erfc floor ceil min(a,b,...) max(a,b,...) pow(a,b) if(cond,a,b) heaviside(x). Truth values
// are "nonzero", NaN included; if() evaluates both branches, which is harmless because no
// floating-point operation here traps.
#pragma once

#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace cosph {

// The text of an expression is wrong. what() is a complete message for the user: it quotes the
// text and says what is wrong where; position() is the 0-based character offset of the problem,
// for callers that want to point at it.
class ExpressionError : public std::runtime_error {
 public:
  ExpressionError(const std::string& message, std::size_t position)
      : std::runtime_error(message), position_(position) {}
  std::size_t position() const { return position_; }

 private:
  std::size_t position_;
};

class Expression {
 public:
  // evaluate() keeps intermediate values in an array of this size on the C++ stack; parse()
  // rejects expressions that would need more. Only absurdly nested text comes near it.
  static constexpr std::size_t kMaxStackDepth = 64;

  // The constant 0, so that an Expression can be a default-constructed member.
  Expression();

  // Compiles `text`. `variables` are the names it may use, in the order evaluate() receives
  // their values. Throws ExpressionError for any mistake in the text, and std::invalid_argument
  // if a variable name is not an identifier, repeats, or is a constant or function name (the
  // list comes from code, not from the user).
  static Expression parse(const std::string& text, const std::vector<std::string>& variables);

  // values[i] is the value of variables[i]; values.size() must equal the number of variables
  // given to parse() (checked by assert only: this sits in per-particle loops).
  double evaluate(std::span<const double> values) const noexcept;
  double evaluate(std::initializer_list<double> values) const noexcept {
    return evaluate(std::span<const double>(values.begin(), values.size()));
  }

  const std::string& text() const { return text_; }
  const std::vector<std::string>& variables() const { return variables_; }
  // Whether `variable` occurs in the text (false for names that are not variables at all).
  bool uses(const std::string& variable) const;
  // No variable occurs, so the value can be computed once. Constant subexpressions are folded
  // at parse time; the whole program is then a single constant.
  bool is_constant() const;

  // One postfix instruction. Public only so that the implementation file can name it.
  enum class Op : std::uint8_t;
  struct Instruction {
    Op op;
    std::uint32_t operand;  // variable index, or argument count of min/max
    double value;           // the constant pushed by Op::kConstant
  };

 private:
  std::string text_;
  std::vector<std::string> variables_;
  std::vector<bool> used_;  // used_[i]: variables_[i] occurs in the text
  std::vector<Instruction> program_;
};

}  // namespace cosph
