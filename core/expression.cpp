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
  int nesting = 0;  // parentheses, calls and signs open at `pos`
  std::vector<Expression::Instr> code;

  // Bounds the recursion: every nested parenthesis, call or sign is one level.
  struct Level {
    Parser& p;
    explicit Level(Parser& parser) : p(parser) {
      if (++p.nesting > Expression::kMaxNesting)
        p.fail("expression nested too deeply (more than " + std::to_string(Expression::kMaxNesting) +
               " parentheses, function calls or signs inside each other)");
    }
    ~Level() { --p.nesting; }
  };

  void skip() {
    while (pos < s.size() && std::isspace(static_cast<unsigned char>(s[pos]))) ++pos;
  }
  [[noreturn]] void fail(const std::string& m) {
    // Long sources are shortened in the message (a 20000-character expression is not shown).
    const std::string shown = s.size() > 80 ? s.substr(0, 77) + "..." : s;
    throw ExpressionError(m + " at position " + std::to_string(pos + 1) + " of '" + shown + "'",
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
    if (accept('-')) { Level l(*this); unary(); emit(Expression::Op::kNeg); return; }
    if (accept('+')) { Level l(*this); unary(); return; }
    power();
  }
  void power() {
    atom();
    if (accept('^')) { unary(); emit(Expression::Op::kPow); }
  }
  void atom() {
    skip();
    if (pos >= s.size()) fail("unexpected end");
    if (accept('(')) { Level l(*this); expr(); expect(')'); return; }
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
      Level l(*this);
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

// Derivatives of the functions, d f(x)/dx and the partials of the two-argument ones.
double dcall1(int f, double x, double fx) {
  switch (f) {
    case 0: return std::cos(x);
    case 1: return -std::sin(x);
    case 2: return 1.0 + fx * fx;
    case 3: return 1.0 / std::sqrt(1.0 - x * x);
    case 4: return -1.0 / std::sqrt(1.0 - x * x);
    case 5: return 1.0 / (1.0 + x * x);
    case 6: return 0.5 / fx;
    case 7: return x < 0 ? -1.0 : 1.0;
    case 8: return fx;
    default: return 1.0 / x;
  }
}
void dcall2(int f, double x, double y, double& dx, double& dy) {
  switch (f) {
    case 0: {  // atan2(x, y) = angle of (y, x)
      const double r2 = x * x + y * y;
      dx = y / r2;
      dy = -x / r2;
      return;
    }
    case 1: dx = x <= y ? 1.0 : 0.0; dy = 1.0 - dx; return;
    default: dx = x >= y ? 1.0 : 0.0; dy = 1.0 - dx; return;
  }
}

// One forward-mode pass: value and derivative with respect to variable `var` (dual numbers on
// the evaluation stack); the derivative is added to `out`, the value returned.
double derivative_pass(const std::vector<Expression::Instr>& code, const double* vars, int var,
                       double& out) {
  using Op = Expression::Op;
  double v[Expression::kMaxStack], d[Expression::kMaxStack];
  int top = 0;
  for (const Expression::Instr& in : code) {
    if (in.op == Op::kConst || in.op == Op::kVar) {
      v[top] = in.op == Op::kConst ? in.value : vars[in.index];
      d[top++] = in.op == Op::kVar && in.index == var ? 1.0 : 0.0;
      continue;
    }
    if (in.op == Op::kNeg) { v[top - 1] = -v[top - 1]; d[top - 1] = -d[top - 1]; continue; }
    if (in.op == Op::kCall1) {
      const double x = v[top - 1], fx = call1(in.index, x);
      d[top - 1] = d[top - 1] == 0 ? 0.0 : dcall1(in.index, x, fx) * d[top - 1];
      v[top - 1] = fx;
      continue;
    }
    --top;
    const double a = v[top - 1], b = v[top], da = d[top - 1], db = d[top];
    double& r = v[top - 1];
    double& dr = d[top - 1];
    switch (in.op) {
      case Op::kAdd: r = a + b; dr = da + db; break;
      case Op::kSub: r = a - b; dr = da - db; break;
      case Op::kMul: r = a * b; dr = da * b + a * db; break;
      case Op::kDiv: r = a / b; dr = (da - r * db) / b; break;
      case Op::kPow:
        r = std::pow(a, b);
        // d(a^b) = b a^(b-1) da + a^b ln(a) db; each term only where its factor moves.
        dr = (da != 0 ? b * std::pow(a, b - 1) * da : 0.0) + (db != 0 ? r * std::log(a) * db : 0.0);
        break;
      case Op::kCall2: {
        double dx = 0, dy = 0;
        dcall2(in.index, a, b, dx, dy);
        r = call2(in.index, a, b);
        dr = dx * da + dy * db;
        break;
      }
      default: break;
    }
  }
  out += top > 0 ? d[top - 1] : 0.0;
  return top > 0 ? v[top - 1] : 0.0;
}
}  // namespace

Expression Expression::compile(const std::string& text,
                               const std::function<int(const std::string&)>& lookup) {
  Parser p{text, lookup, 0, 0, {}};
  p.expr();
  p.skip();
  if (p.pos != text.size()) p.fail("unexpected text");
  // evaluate() works on a fixed stack of kMaxStack values: refuse deeper expressions here.
  int depth = 0, max_depth = 0;
  Expression e;
  for (const Instr& in : p.code) {
    switch (in.op) {
      case Op::kConst: ++depth; break;
      case Op::kVar: ++depth; e.variables.push_back(in.index); break;
      case Op::kNeg:
      case Op::kCall1: break;
      default: --depth; break;
    }
    max_depth = std::max(max_depth, depth);
  }
  if (max_depth > kMaxStack)
    throw ExpressionError("expression nested too deeply (needs " + std::to_string(max_depth) +
                              " operand slots, at most " + std::to_string(kMaxStack) + ") in '" +
                              (text.size() > 80 ? text.substr(0, 77) + "..." : text) + "'",
                          0);
  std::sort(e.variables.begin(), e.variables.end());
  e.variables.erase(std::unique(e.variables.begin(), e.variables.end()), e.variables.end());
  e.code = std::move(p.code);
  e.source = text;
  return e;
}

double Expression::evaluate(const double* vars) const {
  double stack[kMaxStack];
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

double Expression::gradient(const double* vars, double* grad) const {
  double value = 0;
  for (int var : variables) value = derivative_pass(code, vars, var, grad[var]);
  return variables.empty() ? evaluate(vars) : value;
}

bool Expression::is_reserved(const std::string& name) {
  if (name == "pi" || name == "t") return true;
  for (const char* f : kFunctions1)
    if (name == f) return true;
  for (const char* f : kFunctions2)
    if (name == f) return true;
  return false;
}

std::string Expression::reserved_list() {
  std::string s = "pi, t";
  for (const char* f : kFunctions1) s += std::string(", ") + f;
  for (const char* f : kFunctions2) s += std::string(", ") + f;
  return s;
}

}  // namespace mbdae
