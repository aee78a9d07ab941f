// Scaling of mbdae with the size of the IFToMM A02 N four-bar mechanism, or (--chain, --tree)
// of a serial chain or binary tree of the same rods, 0.05 s released at rest (docs/scaling.md).
//
//   iftomm_scaling [N ...]           default N = 10 100 1000 10000
//   iftomm_scaling --markdown [N ...]  the same, as the markdown table of docs/scaling.md
//   iftomm_scaling --chain [N ...], --tree [N ...]  the chain or the tree instead of the four-bar
//
// Each N is run in a fresh process (this program re-executes itself with --one N), so that the
// peak resident memory (getrusage ru_maxrss) is that of the one size. The model is built in code
// (formulation/model.h structs, the geometry of verification/iftomm/scenes/A02_*.yaml: 2N+1
// slender rods of 1 m and 1 kg, every pin a spatial revolute about z, N revolute loop cuts), the
// initial state theta = pi/2 with the rate theta' = -1 rad/s of crank 0 given as a scene's
// initial_velocities gives it (solve_initial_velocities), and a fixed simulation run:
// 0.5 s (before the first singular configuration at 0.72 s), rtol 1e-6, atol 1e-9, Newton
// convergence coefficient 0.33 (IDA's default), no output samples but the end.
//
// Timings (CPU time of the process, clock_gettime(CLOCK_PROCESS_CPUTIME_ID)):
//   setup      build_system, the consistent projection of the guess and the redundancy analysis
//              (SPQR rank-revealing QR of Phi_q^T, twice where cut point rows are re-expressed in a
//              body frame: choose_independent_equations), each timed separately, as run() does it;
//   residual   each DaeProblem::residual call, by a DaeProblem wrapper around Index3Dae;
//   jacobian   each DaeProblem::jacobian call (assembly of dF/dy + cj dF/dy'), the same way;
//   KLU        the factorizations happen inside IDA's linear solver (core/klu_linear_solver.cpp,
//              mbdae's KluSolver): IDA's count of linear setups and of fresh factorizations is
//              reported, and the cost of one is measured on the Newton matrix of the final state
//              with a separate KluSolver (fresh klu_factor once, then the refactorization with the
//              same pivot order that KluSolver::factor does), averaged over several calls; the
//              time not spent in residuals and Jacobians ("rest": the factorizations and solves
//              inside IDA, IDA's own vector work) is given per step as well.
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <string>
#include <vector>

#include "core/ida_driver.h"
#include "core/klu_solver.h"
#include "formulation/augmented_solver.h"
#include "formulation/index3_dae.h"
#include "formulation/initial_velocities.h"
#include "formulation/mechanics.h"
#include "formulation/redundancy.h"
#include "formulation/system.h"

namespace {

using namespace mbdae;

constexpr double kPi = 3.14159265358979323846;

double cpu_now() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

// A slender rod of 1 m and 1 kg along its x axis, with the named point at its far end.
BodySpec slender_rod(const std::string& name, const std::string& end) {
  BodySpec b;
  b.name = name;
  b.mass = 1;
  b.com = Vec3(0.5, 0, 0);
  b.inertia = Vec3(0, 1.0 / 12, 1.0 / 12).asDiagonal();
  b.points[end] = Vec3(1, 0, 0);
  return b;
}

// A02 N four-bar with all cranks at `theta` (couplers horizontal).
Model four_bar(int n, double theta) {
  Model m;
  m.name = "A02_n_four_bar_N" + std::to_string(n);
  m.gravity = Vec3(0, -9.81, 0);
  auto revolute = [&](const std::string& name, const std::string& parent, const std::string& child,
                      const std::string& coordinate, double value) {
    JointSpec j;
    j.name = name;
    j.parent = parent;
    j.child = child;
    ElementaryJoint e;
    e.rotation = true;
    e.axis = 2;
    e.coordinate = coordinate;
    j.chain.push_back(e);
    CoordinateSpec c;
    c.name = coordinate;
    c.initial = value;
    m.coordinates[coordinate] = c;
    return j;
  };
  for (int i = 0; i <= n; ++i) {
    m.bodies.push_back(slender_rod("crank" + std::to_string(i), "tip"));
    JointSpec j = revolute("pivot" + std::to_string(i), kGround, "crank" + std::to_string(i), "th" + std::to_string(i), theta);
    j.anchor = Vec3(i, 0, 0);
    m.joints.push_back(j);
  }
  for (int i = 1; i <= n; ++i) {
    m.bodies.push_back(slender_rod("coupler" + std::to_string(i), "end"));
    JointSpec j = revolute("pin" + std::to_string(i), "crank" + std::to_string(i - 1), "coupler" + std::to_string(i),
                           "c" + std::to_string(i), -theta);
    j.anchor_point = "tip";
    m.joints.push_back(j);
    CutSpec c;
    c.name = "close" + std::to_string(i);
    c.type = CutSpec::Type::kRevolute;
    c.body1 = "coupler" + std::to_string(i);
    c.point1 = "end";
    c.body2 = "crank" + std::to_string(i);
    c.point2 = "tip";
    c.axis1 = c.axis2 = Vec3::UnitZ();
    m.cuts.push_back(c);
  }
  return m;
}

// A revolute joint about z from parent (its point `at`, or the ground origin) to child.
JointSpec revolute_about_z(Model& m, const std::string& parent, const std::string& at, const std::string& child,
                           double angle) {
  JointSpec j;
  j.name = "pin_" + child;
  j.parent = parent;
  j.child = child;
  if (!at.empty()) j.anchor_point = at;
  ElementaryJoint e;
  e.rotation = true;
  e.axis = 2;
  e.coordinate = "th_" + child;
  j.chain.push_back(e);
  CoordinateSpec c;
  c.name = e.coordinate;
  c.initial = angle;
  m.coordinates[c.name] = c;
  return j;
}

// n rods, rod k pinned at the tip of rod parent(k) (parent -1: the ground origin) at the
// relative angle angle(k), released at rest.
template <class Parent, class Angle>
Model pinned_rods(const std::string& name, int n, Parent parent, Angle angle) {
  Model m;
  m.name = name + "_N" + std::to_string(n);
  m.gravity = Vec3(0, -9.81, 0);
  for (int k = 0; k < n; ++k) {
    const std::string rod = "rod" + std::to_string(k);
    m.bodies.push_back(slender_rod(rod, "tip"));
    const int p = parent(k);
    m.joints.push_back(revolute_about_z(m, p >= 0 ? "rod" + std::to_string(p) : kGround, p >= 0 ? "tip" : "", rod, angle(k)));
  }
  return m;
}

// Serial chain of n rods pinned end to end (first to ground), released from the horizontal.
Model serial_chain(int n) {
  return pinned_rods("chain", n, [](int k) { return k - 1; }, [](int) { return 0.0; });
}

// Binary tree of n rods: rod k hangs from the tip of rod (k-1)/2 (rod 0 from ground), the two
// children of a rod at +-0.3 rad relative to it, the root horizontal.
Model binary_tree(int n) {
  return pinned_rods("tree", n, [](int k) { return k ? (k - 1) / 2 : -1; },
                     [](int k) { return k ? (k % 2 ? 0.3 : -0.3) : 0.0; });
}

enum class Topology { kFourBar, kChain, kTree };
const char* topology_name(Topology t) { return t == Topology::kFourBar ? "fourbar" : t == Topology::kChain ? "chain" : "tree"; }

// Forwards to an Index3Dae, timing residual and Jacobian evaluations.
class TimedDae : public DaeProblem {
 public:
  explicit TimedDae(Index3Dae& d) : d_(d) {}
  int size() const override { return d_.size(); }
  const CscPattern& jacobian_pattern() override { return d_.jacobian_pattern(); }
  int residual(double t, const double* y, const double* yp, double* r) override {
    const double c0 = cpu_now();
    const int status = d_.residual(t, y, yp, r);
    residual_seconds += cpu_now() - c0;
    ++residuals;
    return status;
  }
  int jacobian(double t, double cj, const double* y, const double* yp, double* values) override {
    const double c0 = cpu_now();
    const int status = d_.jacobian(t, cj, y, yp, values);
    jacobian_seconds += cpu_now() - c0;
    ++jacobians;
    if (first_y.empty()) first_t = t, first_cj = cj, first_y.assign(y, y + size()), first_yp.assign(yp, yp + size());
    last_t = t, last_cj = cj;
    last_y.assign(y, y + size());
    last_yp.assign(yp, yp + size());
    return status;
  }
  void error_test_mask(double* id) const override { d_.error_test_mask(id); }
  void error_weights(double h, const double* y, double rtol, double atol, double* w) const override {
    d_.error_weights(h, y, rtol, atol, w);
  }
  std::string component_name(int i) const override { return d_.component_name(i); }
  int num_switches() const override { return d_.num_switches(); }
  void switches(double t, const double* y, double* g) override { d_.switches(t, y, g); }
  void restart(double t, double* y, double* yp, const int* roots) override { d_.restart(t, y, yp, roots); }
  double initial_step(double t, const double* y, const double* yp, double rtol, double atol) override {
    return d_.initial_step(t, y, yp, rtol, atol);
  }
  bool changes_mode(double t, const double* y, const int* roots) override { return d_.changes_mode(t, y, roots); }
  std::vector<double> breakpoints() const override { return d_.breakpoints(); }
  void set_segment(double t0, double t1) override { d_.set_segment(t0, t1); }
  void after_step(double t, const double* y) override { d_.after_step(t, y); }

  double residual_seconds = 0, jacobian_seconds = 0;
  long residuals = 0, jacobians = 0;
  double last_t = 0, last_cj = 0, first_t = 0, first_cj = 0;
  std::vector<double> last_y, last_yp, first_y, first_yp;

 private:
  Index3Dae& d_;
};

struct Result {
  int n = 0, topology = 0;
  long lu_nnz = 0;  // nonzeros of L + U of KLU's factorization of the Newton matrix
  double flops = 0;  // KLU's flop count of one factorization of it
  long bodies = 0, unknowns = 0, equations = 0, redundant = 0, jac_nnz = 0;
  double build_s = 0, project_s = 0, qr_s = 0, init_s = 0;
  long steps = 0, residuals = 0, jacobians = 0, setups = 0;
  double integrate_s = 0, residual_s = 0, jacobian_s = 0, klu_refactor_s = 0, klu_first_s = 0;
  double klu_solve_s = 0, rcond = 0;
  long fresh = 0, fresh_in_repeats = 0;
  double max_violation = 0, theta_end = 0, theta_ref = 0;
  long peak_kb = 0;
  bool ok = false;
};

Result run_one(int n, Topology topo) {
  Result res;
  res.n = n;
  res.topology = static_cast<int>(topo);
  const bool fb = topo == Topology::kFourBar;
  const double theta0 = kPi / 2, rate0 = -1.0, t_end = fb ? 0.5 : 0.05;

  double c0 = cpu_now();
  System sys = build_system(fb ? four_bar(n, theta0) : topo == Topology::kChain ? serial_chain(n) : binary_tree(n));
  res.build_s = cpu_now() - c0;
  res.bodies = sys.num_bodies();

  // As run(): regularized projection of the guess, then redundancy analysis and removal.
  std::vector<double> q = sys.q0;
  c0 = cpu_now();
  {
    AugmentedSolver projector(sys);
    projector.positions(q.data(), 0.0, 1e-12, 100, 1e-10);
  }
  res.project_s = cpu_now() - c0;
  c0 = cpu_now();
  EquationChoice choice = choose_independent_equations(sys, q.data(), 0.0);
  sys = std::move(choice.system);
  res.qr_s = cpu_now() - c0;
  res.redundant = static_cast<long>(choice.report.redundant.size());
  res.equations = sys.num_constraint_rows();

  // Initial velocities as a scene's initial_velocities gives them (formulation/initial_velocities.h):
  // the rate theta' = -1 rad/s of crank 0, the rest from the constraints (timed with the
  // consistent start). Index3Dae's velocity projection then makes them consistent to rounding.
  Index3Dae dae(sys, 1.0 / (1e-3 * 1e-3));  // run()'s automatic scale: mean mass / (1e-3 s)^2
  dae.state().modes = initial_modes(sys, q.data(), 0.0);
  res.unknowns = dae.size();
  res.jac_nnz = dae.jacobian_pattern().nnz();
  std::vector<double> y(dae.size(), 0.0), yp(dae.size(), 0.0);
  std::copy(q.begin(), q.end(), y.begin());
  c0 = cpu_now();
  if (fb) solve_initial_velocities(sys, y.data(), 0.0, {{sys.coordinate_index("th0"), rate0}}, y.data() + sys.nq());
  dae.state().output.accelerations = false;  // as run(): no acceleration sensor
  dae.consistent_initial_values(0.0, y, yp);
  res.init_s = cpu_now() - c0;

  TimedDae timed(dae);
  IdaOptions io;
  io.t0 = 0;
  io.t1 = t_end;
  io.rtol = 1e-6;
  io.atol = 1e-9;
  io.output_step = 0;
  io.nonlinear_convergence = 0.33;
  const IdaStats st = integrate(timed, io, y, yp, [](double, const double*, const double*) { return true; });
  res.ok = st.ok;
  res.steps = st.steps;
  res.residuals = timed.residuals;
  res.jacobians = timed.jacobians;
  res.setups = st.linear_setups;
  res.fresh = st.fresh_factorizations;
  res.integrate_s = st.cpu_seconds;
  res.residual_s = timed.residual_seconds;
  res.jacobian_s = timed.jacobian_seconds;
  res.max_violation = dae.state().statistics.max_position_violation;
  if (fb) res.theta_end = coordinate_value(sys, sys.coordinate_index("th0"), y.data());

  // Reference theta(0.5) of M theta'' = -C cos(theta) (RK4, h = 1e-5).
  if (fb) {
    const double big_m = (n + 1) / 3.0 + n, c = 9.81 * ((n + 1) / 2.0 + n);
    double th = theta0, w = rate0;
    const int steps = 50000;
    const double h = t_end / steps;
    auto acc = [&](double x) { return -c * std::cos(x) / big_m; };
    for (int k = 0; k < steps; ++k) {
      const double k1x = w, k1v = acc(th), k2x = w + 0.5 * h * k1v, k2v = acc(th + 0.5 * h * k1x);
      const double k3x = w + 0.5 * h * k2v, k3v = acc(th + 0.5 * h * k2x), k4x = w + h * k3v, k4v = acc(th + h * k3x);
      th += h / 6 * (k1x + 2 * k2x + 2 * k3x + k4x);
      w += h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
    }
    res.theta_ref = th;
  }

  // KLU with mbdae's KluSolver as IDA uses it (core/klu_linear_solver.cpp): symbolic analysis
  // once, a fresh klu_factor of the first Newton matrix of the run (its pivot order is the one
  // IDA keeps), then klu_refactor with that order on the Newton matrix of the last Jacobian
  // evaluation (KluSolver::factor). Averages over repeats.
  if (timed.jacobians > 0) {
    std::vector<double> values(res.jac_nnz), b(dae.size(), 1.0);
    dae.jacobian(timed.first_t, timed.first_cj, timed.first_y.data(), timed.first_yp.data(), values.data());
    KluSolver klu;
    klu.analyze(dae.jacobian_pattern());
    c0 = cpu_now();
    klu.factor(values.data());
    res.klu_first_s = cpu_now() - c0;
    dae.jacobian(timed.last_t, timed.last_cj, timed.last_y.data(), timed.last_yp.data(), values.data());
    res.lu_nnz = klu.factor_nnz();
    res.flops = klu.flops();
    const int reps = n >= 10000 ? 5 : n >= 1000 ? 20 : 200, fresh0 = klu.full_factorizations();
    c0 = cpu_now();
    for (int k = 0; k < reps; ++k) klu.factor(values.data());
    res.klu_refactor_s = (cpu_now() - c0) / reps;
    res.fresh_in_repeats = klu.full_factorizations() - fresh0;
    res.rcond = klu.rcond();
    c0 = cpu_now();
    for (int k = 0; k < reps; ++k) klu.solve(b.data());
    res.klu_solve_s = (cpu_now() - c0) / reps;
  }
  rusage ru;
  getrusage(RUSAGE_SELF, &ru);
  res.peak_kb = ru.ru_maxrss;
  return res;
}

void print_one(const Result& r) {
  std::printf(
      "RESULT topo=%d n=%d lu_nnz=%ld flops=%.6g bodies=%ld unknowns=%ld equations=%ld redundant=%ld jac_nnz=%ld build=%.6g project=%.6g qr=%.6g "
      "init=%.6g ok=%d steps=%ld residuals=%ld jacobians=%ld setups=%ld integrate=%.6g residual=%.6g "
      "jacobian=%.6g klu_first=%.6g klu_refactor=%.6g klu_solve=%.6g rcond=%.6g fresh=%ld fresh_rep=%ld "
      "violation=%.3g theta_end=%.12g theta_ref=%.12g peak_kb=%ld\n",
      r.topology, r.n, r.lu_nnz, r.flops, r.bodies, r.unknowns, r.equations, r.redundant, r.jac_nnz, r.build_s, r.project_s, r.qr_s, r.init_s,
      r.ok ? 1 : 0, r.steps, r.residuals, r.jacobians, r.setups, r.integrate_s, r.residual_s, r.jacobian_s,
      r.klu_first_s, r.klu_refactor_s, r.klu_solve_s, r.rcond, r.fresh, r.fresh_in_repeats, r.max_violation,
      r.theta_end, r.theta_ref, r.peak_kb);
  std::fflush(stdout);
}

bool parse(const std::string& line, Result& r) {
  int ok = 0;
  const int got = std::sscanf(
      line.c_str(),
      "RESULT topo=%d n=%d lu_nnz=%ld flops=%lf bodies=%ld unknowns=%ld equations=%ld redundant=%ld jac_nnz=%ld build=%lf project=%lf qr=%lf "
      "init=%lf ok=%d steps=%ld residuals=%ld jacobians=%ld setups=%ld integrate=%lf residual=%lf "
      "jacobian=%lf klu_first=%lf klu_refactor=%lf klu_solve=%lf rcond=%lf fresh=%ld fresh_rep=%ld "
      "violation=%lf theta_end=%lf theta_ref=%lf peak_kb=%ld",
      &r.topology, &r.n, &r.lu_nnz, &r.flops, &r.bodies, &r.unknowns, &r.equations, &r.redundant, &r.jac_nnz, &r.build_s, &r.project_s, &r.qr_s,
      &r.init_s, &ok, &r.steps, &r.residuals, &r.jacobians, &r.setups, &r.integrate_s, &r.residual_s,
      &r.jacobian_s, &r.klu_first_s, &r.klu_refactor_s, &r.klu_solve_s, &r.rcond, &r.fresh, &r.fresh_in_repeats,
      &r.max_violation, &r.theta_end, &r.theta_ref, &r.peak_kb);
  r.ok = ok != 0;
  return got == 31;
}

// Least-squares slope of log(y) against log(x).
double slope(const std::vector<double>& x, const std::vector<double>& y) {
  const size_t n = x.size();
  if (n < 2) return NAN;
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (size_t i = 0; i < n; ++i) {
    const double lx = std::log(x[i]), ly = std::log(y[i]);
    sx += lx, sy += ly, sxx += lx * lx, sxy += lx * ly;
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 4 && std::strcmp(argv[1], "--one") == 0) {
    print_one(run_one(std::atoi(argv[2]), static_cast<Topology>(std::atoi(argv[3]))));
    return 0;
  }
  bool markdown = false;
  Topology topo = Topology::kFourBar;
  std::vector<int> sizes;
  for (int k = 1; k < argc; ++k) {
    if (std::strcmp(argv[k], "--markdown") == 0) markdown = true;
    else if (std::strcmp(argv[k], "--chain") == 0) topo = Topology::kChain;
    else if (std::strcmp(argv[k], "--tree") == 0) topo = Topology::kTree;
    else if (std::atoi(argv[k]) > 0) sizes.push_back(std::atoi(argv[k]));
    else {
      std::fprintf(stderr, "usage: iftomm_scaling [--markdown] [--chain | --tree] [N ...]\n");
      return 1;
    }
  }
  if (sizes.empty()) sizes = {10, 100, 1000, 10000};

  std::vector<Result> results;
  for (int n : sizes) {
    // /proc/self/exe in the shell would be the shell: resolve our own path first.
    char self[4096];
    const ssize_t len = readlink("/proc/self/exe", self, sizeof self - 1);
    if (len <= 0) {
      std::fprintf(stderr, "cannot resolve /proc/self/exe\n");
      return 1;
    }
    self[len] = 0;
    FILE* p = popen(("'" + std::string(self) + "' --one " + std::to_string(n) + " " +
                     std::to_string(static_cast<int>(topo))).c_str(), "r");
    if (!p) return 1;
    char line[4096];
    Result r;
    bool got = false;
    while (std::fgets(line, sizeof line, p))
      if (std::strncmp(line, "RESULT", 6) == 0) got = parse(line, r);
    const int status = pclose(p);
    if (!got || status != 0) {
      std::fprintf(stderr, "iftomm_scaling: the run for N = %d failed\n", n);
      return 2;
    }
    if (!r.ok) {
      std::fprintf(stderr, "iftomm_scaling: the integration for N = %d failed\n", n);
      return 2;
    }
    const bool fb = topo == Topology::kFourBar;
    if (r.redundant != (fb ? 3L * n : 0L)) {
      std::fprintf(stderr, "iftomm_scaling: N = %d: %ld redundant equations, expected %d\n", n, r.redundant, fb ? 3 * n : 0);
      return 2;
    }
    if (fb && std::fabs(r.theta_end - r.theta_ref) > 1e-3) {  // a sanity check at rtol 1e-6
      std::fprintf(stderr, "iftomm_scaling: N = %d: theta(0.5) = %.9f, reference %.9f\n", n, r.theta_end, r.theta_ref);
      return 2;
    }
    results.push_back(r);
    if (!markdown)
      std::printf("%s N = %d done: %ld steps, %.3f s integration, setup QR %.3f s, nnz(L+U) %ld\n", topology_name(topo), n,
                  r.steps, r.integrate_s, r.qr_s, r.lu_nnz);
    std::fflush(stdout);
  }

  // Linear fill: nnz(L+U) per body may not double from one size to the next larger (at N^2 fill
  // it grows with N: docs/scaling.md, chains before the KLU analysis choice).
  for (size_t k = 1; k < results.size(); ++k) {
    const Result &a = results[k - 1], &b = results[k];
    if (a.n >= 100 && b.n > a.n && b.lu_nnz / double(b.bodies) > 2.0 * a.lu_nnz / double(a.bodies)) {
      std::fprintf(stderr, "iftomm_scaling: nnz(L+U) per body %.0f at N = %d, %.0f at N = %d: not linear\n",
                   a.lu_nnz / double(a.bodies), a.n, b.lu_nnz / double(b.bodies), b.n);
      return 2;
    }
  }

  std::vector<double> xs, per_step, per_res, per_jac, per_klu, per_fresh, qr, build, mem;
  for (const auto& r : results) {
    xs.push_back(r.n);
    per_step.push_back(r.integrate_s / r.steps);
    per_res.push_back(r.residual_s / r.residuals);
    per_jac.push_back(r.jacobian_s / r.jacobians);
    per_klu.push_back(r.klu_refactor_s);
    per_fresh.push_back(r.klu_first_s);
    qr.push_back(r.qr_s);
    build.push_back(r.build_s);
    mem.push_back(r.peak_kb);
  }
  auto fmt = [](const char* f, double v) {
    char b[64];
    std::snprintf(b, sizeof b, f, v);
    return std::string(b);
  };
  const std::vector<std::string> head = {
      "N", "bodies", "unknowns", "Jacobian nnz", "redundant", "build_system s", "projection s", "SPQR s",
      "steps", "residuals", "Jacobians", "KLU factorizations (fresh)", "CPU s", "ms/step", "ms/residual",
      "ms/Jacobian", "us/step/body", "nnz(L+U)", "KLU Mflop/factor", "ms/KLU refactor", "ms/KLU fresh factor", "ms/KLU solve", "KLU rcond", "rest ms/step",
      "peak RSS MB",
      "theta(0.5) error"};
  std::vector<std::vector<std::string>> rows;
  for (const auto& r : results) {
    const double rest = (r.integrate_s - r.residual_s - r.jacobian_s) / r.steps;
    rows.push_back({std::to_string(r.n), std::to_string(r.bodies), std::to_string(r.unknowns),
                    std::to_string(r.jac_nnz), std::to_string(r.redundant), fmt("%.3f", r.build_s),
                    fmt("%.3f", r.project_s), fmt("%.3f", r.qr_s), std::to_string(r.steps),
                    std::to_string(r.residuals), std::to_string(r.jacobians),
                    std::to_string(r.setups) + " (" + std::to_string(r.fresh) + ")",
                    fmt("%.3f", r.integrate_s), fmt("%.4g", 1e3 * r.integrate_s / r.steps),
                    fmt("%.4g", 1e3 * r.residual_s / r.residuals), fmt("%.4g", 1e3 * r.jacobian_s / r.jacobians),
                    fmt("%.3g", 1e6 * r.integrate_s / r.steps / r.bodies), std::to_string(r.lu_nnz),
                    fmt("%.3g", 1e-6 * r.flops), fmt("%.4g", 1e3 * r.klu_refactor_s), fmt("%.4g", 1e3 * r.klu_first_s),
                    fmt("%.4g", 1e3 * r.klu_solve_s), fmt("%.1e", r.rcond), fmt("%.4g", 1e3 * rest),
                    fmt("%.1f", r.peak_kb / 1024.0), fmt("%.1e", std::fabs(r.theta_end - r.theta_ref))});
  }
  if (markdown) {
    std::printf("|");
    for (const auto& h : head) std::printf(" %s |", h.c_str());
    std::printf("\n|");
    for (size_t k = 0; k < head.size(); ++k) std::printf("---:|");
    std::printf("\n");
    for (const auto& row : rows) {
      std::printf("|");
      for (const auto& c : row) std::printf(" %s |", c.c_str());
      std::printf("\n");
    }
  } else {
    std::vector<size_t> w(head.size());
    for (size_t k = 0; k < head.size(); ++k) {
      w[k] = head[k].size();
      for (const auto& row : rows) w[k] = std::max(w[k], row[k].size());
    }
    for (size_t k = 0; k < head.size(); ++k) std::printf("%*s  ", static_cast<int>(w[k]), head[k].c_str());
    std::printf("\n");
    for (const auto& row : rows) {
      for (size_t k = 0; k < head.size(); ++k) std::printf("%*s  ", static_cast<int>(w[k]), row[k].c_str());
      std::printf("\n");
    }
  }
  if (results.size() >= 2) {
    std::printf("\nFitted slopes of log(cost) against log(N), N = ");
    for (size_t k = 0; k < results.size(); ++k) std::printf("%s%d", k ? ", " : "", results[k].n);
    std::printf(":\n%s", markdown ? "\n" : "");
    const char* b = markdown ? "- " : "  ";
    std::printf("%sCPU time per step: %.3f\n", b, slope(xs, per_step));
    std::printf("%sper residual evaluation: %.3f\n", b, slope(xs, per_res));
    std::printf("%sper Jacobian evaluation: %.3f\n", b, slope(xs, per_jac));
    std::printf("%sper KLU refactorization: %.3f\n", b, slope(xs, per_klu));
    std::printf("%sper fresh KLU factorization: %.3f\n", b, slope(xs, per_fresh));
    std::printf("%ssetup: build_system %.3f, SPQR redundancy analysis %.3f\n", b, slope(xs, build), slope(xs, qr));
    std::printf("%speak memory: %.3f\n", b, slope(xs, mem));
  }
  return 0;
}
