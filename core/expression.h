// A small arithmetic expression language for derived outputs, e.g. "asin(axis_z)" or
// "atan2(axis_x, axis_y) * 180 / pi". Grammar (recursive descent):
//   expr := term (('+'|'-') term)*      term := unary (('*'|'/') unary)*
//   unary := '-' unary | power          power := atom ('^' unary)?
//   atom := number | name | name '(' expr (',' expr)* ')' | '(' expr ')'
// Functions: sin cos tan asin acos atan atan2 sqrt abs exp log min max. Constant: pi.
// Hand-written (about 150 lines) because no Debian package offers a small embeddable one
// with source positions in its errors; compiled once to postfix code, evaluated without
// allocation.
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
  std::vector<Instr> code;
  std::string source;

  // Resolves names to variable indices (returns -1 for an unknown name).
  static Expression compile(const std::string& text,
                            const std::function<int(const std::string&)>& lookup);
  double evaluate(const double* variables) const;
  bool empty() const { return code.empty(); }
};

}  // namespace mbdae
