// Expressions of a user-defined manufactured motion (expression_motion.hpp):
// a formula in the reference coordinates and time, read once, evaluated on any
// scalar the manufactured solutions use (double and the jets of jet.hpp), so
// that F, dF/dX, v, a and the body force follow by automatic differentiation
// as for a motion written in C++ (manufactured.hpp).
//
// Grammar (usual precedence; ^ binds tightest and to the right, and its
// exponent must be a constant):
//   sum     = product { ("+" | "-") product }
//   product = unary { ("*" | "/") unary }
//   unary   = "-" unary | power
//   power   = primary [ "^" unary ]
//   primary = number | name | function "(" sum ")" | "(" sum ")"
// Names: the coordinates and time the caller gives (X, Y, t or R, Z, t), pi,
// and the caller's parameters; functions sin, cos, tan, exp, log, sqrt. A
// part without a coordinate or time is folded to its value when read.
#pragma once

#include <array>
#include <cctype>
#include <cmath>
#include <cstddef>
#include <map>
#include <new>
#include <numbers>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace mpmvv::mms {

// A formula that cannot be read: what is wrong and at which character (from 1).
class ExpressionError : public std::runtime_error {
 public:
  ExpressionError(const std::string& what, std::size_t column)
      : std::runtime_error(what + " at character " + std::to_string(column)) {}
};

// The formula as a program for a stack: each operation pushes a value or
// replaces the top one or two.
class Expression {
 public:
  static constexpr int kVariables = 3;  // the two coordinates and time, in that order
  static constexpr int kMaxDepth = 32;

  Expression() = default;

  // Reads `text`; `variables` are the three names of the coordinates and time.
  Expression(const std::string& text, const std::array<std::string, kVariables>& variables,
             const std::map<std::string, double>& parameters)
      : text_(text), variables_(variables), parameters_(parameters) {
    skip();
    if (at_end()) throw ExpressionError("empty formula", 1);
    sum();
    if (!at_end()) throw ExpressionError(std::string("unexpected '") + text_[position_] + "'", position_ + 1);
    int depth = 0;
    for (const Operation& o : program_) {
      depth += o.op <= Op::variable ? 1 : o.op <= Op::divide ? -1 : 0;
      if (depth > kMaxDepth) throw ExpressionError("formula nested too deeply", 1);
    }
    text_.clear();
  }

  // Whether a name is taken by the formulas themselves (pi and the functions),
  // so that a parameter may not have it.
  static bool reserved(const std::string& name) { return name == "pi" || functions().count(name) > 0; }

  // Whether the formula reads variable k (0, 1: the coordinates; 2: time).
  bool reads(int k) const {
    for (const Operation& o : program_)
      if (o.op == Op::variable && o.index == k) return true;
    return false;
  }

  // The formula's value at the coordinates a, b and time t.
  // The stack is raw storage, each slot constructed when pushed: a jet zeroes
  // its derivatives when constructed, and zeroing the whole stack at every
  // call cost more than the formula.
  template <class S>
  S operator()(const S& a, const S& b, const S& t) const {
    static_assert(std::is_trivially_destructible_v<S>);
    alignas(S) unsigned char storage[kMaxDepth * sizeof(S)];
    S* stack = reinterpret_cast<S*>(storage);
    int top = -1;
    for (const Operation& o : program_) {
      switch (o.op) {
        case Op::constant: new (&stack[++top]) S(o.value); break;
        case Op::variable: new (&stack[++top]) S(o.index == 0 ? a : o.index == 1 ? b : t); break;
        case Op::add: stack[top - 1] = stack[top - 1] + stack[top]; --top; break;
        case Op::subtract: stack[top - 1] = stack[top - 1] - stack[top]; --top; break;
        case Op::multiply: stack[top - 1] = stack[top - 1] * stack[top]; --top; break;
        case Op::divide: stack[top - 1] = stack[top - 1] / stack[top]; --top; break;
        default: stack[top] = apply(o, stack[top]); break;
      }
    }
    return stack[0];
  }

 private:
  enum class Op { constant, variable, add, subtract, multiply, divide, negate, power, sin, cos, tan, exp, log, sqrt };
  struct Operation {
    Op op;
    double value = 0.0;  // constant: the value; power: the exponent
    int index = 0;       // variable: which
  };

  static const std::map<std::string, Op>& functions() {
    static const std::map<std::string, Op> table = {{"sin", Op::sin}, {"cos", Op::cos}, {"tan", Op::tan},
                                                    {"exp", Op::exp}, {"log", Op::log}, {"sqrt", Op::sqrt}};
    return table;
  }

  template <class S>
  static S apply(const Operation& o, const S& x) {
    using std::cos, std::exp, std::log, std::pow, std::sin, std::sqrt;
    switch (o.op) {
      case Op::negate: return -x;
      case Op::power: return o.value == 2.0 ? x * x : pow(x, o.value);
      case Op::sin: return sin(x);
      case Op::cos: return cos(x);
      case Op::tan: return sin(x) / cos(x);
      case Op::exp: return exp(x);
      case Op::log: return log(x);
      default: return sqrt(x);
    }
  }
  static double apply(Op op, double x, double y) {
    switch (op) {
      case Op::add: return x + y;
      case Op::subtract: return x - y;
      case Op::multiply: return x * y;
      default: return x / y;
    }
  }

  bool at_end() const { return position_ >= text_.size(); }
  char peek() const { return at_end() ? '\0' : text_[position_]; }
  void skip() {
    while (!at_end() && std::isspace(static_cast<unsigned char>(text_[position_]))) ++position_;
  }
  bool take(char c) {
    if (peek() != c) return false;
    ++position_;
    skip();
    return true;
  }

  // A folded constant must be a number: `why` names what made it none, at `column` (from 1).
  static double folded(double value, const std::string& why, std::size_t column) {
    if (!std::isfinite(value)) throw ExpressionError(why, column);
    return value;
  }
  static constexpr const char* kNotFinite = "a constant part is not a finite number";

  // Pushes a binary operation, folding it when both operands are constants.
  void binary(Op op, std::size_t left_start, std::size_t column) {
    const std::size_t n = program_.size();
    if (n >= 2 && program_[n - 1].op == Op::constant && program_[n - 2].op == Op::constant &&
        left_start == n - 2) {
      program_[n - 2].value = folded(apply(op, program_[n - 2].value, program_[n - 1].value), kNotFinite, column);
      program_.pop_back();
      return;
    }
    program_.push_back({op});
  }
  void unary(const Operation& o, std::size_t start, const std::string& why, std::size_t column) {
    if (program_.size() == start + 1 && program_.back().op == Op::constant) {
      program_.back().value = folded(apply(o, program_.back().value), why, column);
      return;
    }
    program_.push_back(o);
  }

  // operand { (first | second) operand }, left to right: the sum of products
  // and the product of factors.
  void chain(void (Expression::*operand)(), char first, Op first_op, char second, Op second_op) {
    const std::size_t start = program_.size();
    (this->*operand)();
    for (;;) {
      const std::size_t column = position_ + 1;
      const Op op = take(first) ? first_op : take(second) ? second_op : Op::constant;
      if (op == Op::constant) return;
      (this->*operand)();
      binary(op, start, column);
    }
  }
  void sum() { chain(&Expression::product, '+', Op::add, '-', Op::subtract); }
  void product() { chain(&Expression::factor, '*', Op::multiply, '/', Op::divide); }
  void factor() {
    const std::size_t start = program_.size(), minus = position_ + 1;
    if (take('-')) {
      factor();
      unary({Op::negate}, start, kNotFinite, minus);
      return;
    }
    primary();
    const std::size_t column = position_;
    if (take('^')) {
      const std::size_t exponent_start = program_.size();
      factor();
      if (program_.size() != exponent_start + 1 || program_.back().op != Op::constant)
        throw ExpressionError("an exponent must be a constant", column + 1);
      const double p = program_.back().value;
      program_.pop_back();
      unary({Op::power, p}, start, kNotFinite, column + 1);
    }
  }
  void primary() {
    const std::size_t column = position_ + 1;
    if (take('(')) {
      sum();
      if (!take(')')) throw ExpressionError("missing ')'", position_ + 1);
      return;
    }
    const char c = peek();
    if (std::isdigit(static_cast<unsigned char>(c)) || c == '.') {
      std::size_t used = 0;
      double value = 0.0;
      try {
        value = std::stod(text_.substr(position_), &used);
      } catch (const std::exception&) {
        throw ExpressionError("a number cannot be read", column);
      }
      position_ += used;
      skip();
      program_.push_back({Op::constant, value});
      return;
    }
    if (!(std::isalpha(static_cast<unsigned char>(c)) || c == '_'))
      throw ExpressionError(at_end() ? "the formula ends too soon" : std::string("unexpected '") + c + "'", column);
    std::string name;
    while (!at_end() && (std::isalnum(static_cast<unsigned char>(peek())) || peek() == '_')) name += text_[position_++];
    skip();
    if (const auto f = functions().find(name); f != functions().end()) {
      if (!take('(')) throw ExpressionError("'" + name + "' needs its argument in parentheses", position_ + 1);
      const std::size_t start = program_.size();
      sum();
      if (!take(')')) throw ExpressionError("missing ')'", position_ + 1);
      unary({f->second}, start, "'" + name + "' of a constant that is out of its domain", column);
      return;
    }
    for (int k = 0; k < kVariables; ++k)
      if (name == variables_[std::size_t(k)]) {
        program_.push_back({Op::variable, 0.0, k});
        return;
      }
    if (name == "pi") {
      program_.push_back({Op::constant, std::numbers::pi});
      return;
    }
    if (const auto p = parameters_.find(name); p != parameters_.end()) {
      program_.push_back({Op::constant, p->second});
      return;
    }
    throw ExpressionError("unknown name '" + name + "' (the coordinates " + variables_[0] + ", " + variables_[1] +
                              ", time " + variables_[2] + ", pi, a parameter, or sin cos tan exp log sqrt)",
                          column);
  }

  std::string text_;
  std::size_t position_ = 0;
  std::array<std::string, kVariables> variables_;
  std::map<std::string, double> parameters_;
  std::vector<Operation> program_;
};

}  // namespace mpmvv::mms
