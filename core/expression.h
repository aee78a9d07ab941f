// A small arithmetic expression language for derived outputs and state-dependent loads, e.g.
// "asin(axis_z)", "atan2(axis_x, axis_y) * 180 / pi" or "T0 * (1 - w / w0)". Grammar (recursive
// descent, at most kMaxNesting levels of parentheses, calls and signs deep):
//   expr := term (('+'|'-') term)*      term := unary (('*'|'/') unary)*
//   unary := '-' unary | power          power := atom ('^' unary)?
//   atom := number | name | name '(' expr (',' expr)* ')' | '(' expr ')'
// Functions: sin cos tan asin acos atan atan2 sqrt abs exp log min max. Constant: pi.
// Compiled once to postfix code, evaluated without allocation. gradient() differentiates the
// compiled code exactly (forward mode: each instruction's derivative rule, no step size); the
// choice of this hand-written parser over muparser is explained in docs/scene-format.md.
#pragma once

#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace mbdae {

struct ExpressionError : std::runtime_error {
  int position;
  ExpressionError(const std::string& m, int pos) : std::runtime_error(m), position(pos) {}
};

struct Expression {
  enum class Op { kConst, kVar, kAdd, kSub, kMul, kDiv, kPow, kNeg, kCall1, kCall2 };
  struct Instr {
    Op op;
    double value = 0;
    int index = 0;  // variable index or function id
  };
  static constexpr int kMaxNesting = 200;  // parentheses, calls and signs inside each other
  static constexpr int kMaxStack = 64;     // evaluation stack entries
  std::vector<Instr> code;
  std::vector<int> variables;  // the variable indices the code reads, each once, ascending
  std::string source;

  // Resolves names to variable indices (returns -1 for an unknown name).
  static Expression compile(const std::string& text,
                            const std::function<int(const std::string&)>& lookup);
  double evaluate(const double* variables) const;
  // Value, and d(value)/d(variables[i]) added to grad[i] for every i in `variables` (other
  // entries untouched). Where a function is not differentiable (abs at 0, min/max at a tie) the
  // derivative of the branch taken is used.
  double gradient(const double* variables, double* grad) const;
  bool empty() const { return code.empty(); }

  // Names with a meaning of their own in expressions (pi, t for time, the function names):
  // sensors and parameters must not be called so.
  static bool is_reserved(const std::string& name);
  static std::string reserved_list();
};

}  // namespace mbdae
