#include "core/expression.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>

namespace mbdae {
namespace {

const char* const kFunctions1[] = {"sin", "cos", "tan", "asin", "acos", "atan",
                                   "sqrt", "abs", "exp", "log"};
const char* const kFunctions2[] = {"atan2", "min", "max"};

struct Parser {
  const std::string& s;
  const std::function<int(const std::string&)>& lookup;
  size_t pos = 0;
  std::vector<Expression::Instr> code;

  void skip() {
    while (pos < s.size() && std::isspace(static_cast<unsigned char>(s[pos]))) ++pos;
  }
  [[noreturn]] void fail(const std::string& m) {
    throw ExpressionError(m + " at position " + std::to_string(pos + 1) + " of '" + s + "'",
                          static_cast<int>(pos));
  }
  bool accept(char c) {
    skip();
    if (pos < s.size() && s[pos] == c) {
      ++pos;
      return true;
    }
    return false;
  }
  void expect(char c) {
    if (!accept(c)) fail(std::string("expected '") + c + "'");
  }
  void emit(Expression::Op op, double v = 0, int i = 0) { code.push_back({op, v, i}); }

  void expr() {
    term();
    for (;;) {
      if (accept('+')) { term(); emit(Expression::Op::kAdd); }
      else if (accept('-')) { term(); emit(Expression::Op::kSub); }
      else return;
    }
  }
  void term() {
    unary();
    for (;;) {
      if (accept('*')) { unary(); emit(Expression::Op::kMul); }
      else if (accept('/')) { unary(); emit(Expression::Op::kDiv); }
      else return;
    }
  }
  void unary() {
    if (accept('-')) { unary(); emit(Expression::Op::kNeg); return; }
    if (accept('+')) { unary(); return; }
    power();
  }
  void power() {
    atom();
    if (accept('^')) { unary(); emit(Expression::Op::kPow); }
  }
  void atom() {
    skip();
    if (pos >= s.size()) fail("unexpected end");
    if (accept('(')) { expr(); expect(')'); return; }
    const char c = s[pos];
    if (std::isdigit(static_cast<unsigned char>(c)) || c == '.') {
      char* end = nullptr;
      const double v = std::strtod(s.c_str() + pos, &end);
      if (end == s.c_str() + pos) fail("bad number");
      pos = end - s.c_str();
      emit(Expression::Op::kConst, v);
      return;
    }
    if (!(std::isalpha(static_cast<unsigned char>(c)) || c == '_')) fail("unexpected character");
    const size_t start = pos;
    while (pos < s.size() && (std::isalnum(static_cast<unsigned char>(s[pos])) || s[pos] == '_' ||
                              s[pos] == '.'))
      ++pos;
    const std::string name = s.substr(start, pos - start);
    if (accept('(')) {
      for (int f = 0; f < 10; ++f)
        if (name == kFunctions1[f]) {
          expr();
          expect(')');
          emit(Expression::Op::kCall1, 0, f);
          return;
        }
      for (int f = 0; f < 3; ++f)
        if (name == kFunctions2[f]) {
          expr();
          expect(',');
          expr();
          expect(')');
          emit(Expression::Op::kCall2, 0, f);
          return;
        }
      pos = start;
      fail("unknown function '" + name + "'");
    }
    if (name == "pi") { emit(Expression::Op::kConst, M_PI); return; }
    const int index = lookup(name);
    if (index < 0) {
      pos = start;
      fail("unknown name '" + name + "'");
    }
    emit(Expression::Op::kVar, 0, index);
  }
};

double call1(int f, double x) {
  switch (f) {
    case 0: return std::sin(x);
    case 1: return std::cos(x);
    case 2: return std::tan(x);
    case 3: return std::asin(x);
    case 4: return std::acos(x);
    case 5: return std::atan(x);
    case 6: return std::sqrt(x);
    case 7: return std::fabs(x);
    case 8: return std::exp(x);
    default: return std::log(x);
  }
}
double call2(int f, double x, double y) {
  switch (f) {
    case 0: return std::atan2(x, y);
    case 1: return std::fmin(x, y);
    default: return std::fmax(x, y);
  }
}
}  // namespace

Expression Expression::compile(const std::string& text,
                               const std::function<int(const std::string&)>& lookup) {
  Parser p{text, lookup};
  p.expr();
  p.skip();
  if (p.pos != text.size()) p.fail("unexpected text");
  // evaluate() works on a fixed stack of 64 values: refuse deeper expressions here.
  int depth = 0, max_depth = 0;
  for (const Instr& in : p.code) {
    switch (in.op) {
      case Op::kConst:
      case Op::kVar: ++depth; break;
      case Op::kNeg:
      case Op::kCall1: break;
      default: --depth; break;
    }
    max_depth = std::max(max_depth, depth);
  }
  if (max_depth > 64)
    throw ExpressionError("expression nested too deeply (needs " + std::to_string(max_depth) +
                              " operand slots, at most 64) in '" + text + "'",
                          0);
  Expression e;
  e.code = std::move(p.code);
  e.source = text;
  return e;
}

double Expression::evaluate(const double* vars) const {
  double stack[64];
  int top = 0;
  for (const Instr& in : code) {
    switch (in.op) {
      case Op::kConst: stack[top++] = in.value; break;
      case Op::kVar: stack[top++] = vars[in.index]; break;
      case Op::kNeg: stack[top - 1] = -stack[top - 1]; break;
      case Op::kCall1: stack[top - 1] = call1(in.index, stack[top - 1]); break;
      case Op::kCall2: --top; stack[top - 1] = call2(in.index, stack[top - 1], stack[top]); break;
      case Op::kAdd: --top; stack[top - 1] += stack[top]; break;
      case Op::kSub: --top; stack[top - 1] -= stack[top]; break;
      case Op::kMul: --top; stack[top - 1] *= stack[top]; break;
      case Op::kDiv: --top; stack[top - 1] /= stack[top]; break;
      case Op::kPow: --top; stack[top - 1] = std::pow(stack[top - 1], stack[top]); break;
    }
  }
  return top > 0 ? stack[top - 1] : 0.0;
}

}  // namespace mbdae
