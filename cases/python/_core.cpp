// mbdae._core: the pybind11 bindings of the public API (cases/mbdae.h), kept thin. The Python
// package around it (cases/python/mbdae/) adds the pandas / numpy views, the exceptions with
// their fields, and the Dask sweeps.
#include <atomic>
#include <chrono>
#include <cmath>
#include <future>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "cases/scene/analysis_types.h"
#include "cases/output/animation_sink.h"
#include "cases/run/error_target.h"
#include "cases/mbdae.h"
#include "cases/output/sinks.h"
#include "core/output.h"
#include "core/errors.h"

namespace py = pybind11;

namespace {

// The API's RunOptions plus the folder that run(out=) writes results.csv and summary.json to
// (through the CLI's sinks, cases/output/sinks.h) and the folder of run(animation=) (an AnimationSink,
// cases/output/animation_sink.h).
struct PyRunOptions : mbdae::RunOptions {
  std::string out_dir, animation_dir;
  double animation_rate = 0;  // frames per second of simulated time (0: the scene's)
  mbdae::ErrorControl error;  // run(error_estimate=, error_target=, error_sensors=) (cases/run/error_target.h)
};

// mbdae::run with the CLI's sinks (open_sinks, cases/output/sinks.h: the same folder lock) when an
// output folder is given, and the animation sink; with an error estimate or target as asked
// (fresh writers for every try of a target). As the CLI, the scene's system is checked before a
// folder is touched (a refused scene leaves it as it was).
mbdae::Result run_with_sinks(const mbdae::Scene& scene, const PyRunOptions& options) {
  if (!options.out_dir.empty() || !options.animation_dir.empty()) mbdae::check_runnable(scene, options);
  const mbdae::OutputRequest request{options.out_dir, options.animation_dir, options.animation_rate,
                                     !options.sensitivities.empty()};
  mbdae::RunSinks out = mbdae::open_sinks(scene, request);
  int tries = 0;
  const mbdae::SinkFactory make_sinks = [&] {
    if (tries++ > 0) mbdae::renew_sinks(scene, request, out);
    return out.list;
  };
  return mbdae::run_controlled(scene, options, mbdae::error_control(scene, options.error), make_sinks,
                               options.out_dir.empty() ? "" : options.out_dir + "/summary.json");
}

// The checks `mbdae run` makes on its options (ValueError naming the option), before anything runs.
void check_options(const mbdae::Scene& scene, const PyRunOptions& options) {
  std::vector<std::string> bad = mbdae::run_option_errors(scene, options);
  if (!(options.animation_rate >= 0) || !std::isfinite(options.animation_rate))
    bad.push_back("animation_rate: must be a positive number of frames per second, got " +
                  std::to_string(options.animation_rate));
  if (bad.empty()) return;
  std::string text;
  for (const auto& m : bad) text += (text.empty() ? "" : "\n") + m;
  throw py::value_error(text);
}

// A column of a Result as a read-only numpy array over the Result's own memory (no copy): the
// array keeps the Python Result object (and so the C++ Result) alive.
py::array column_view(py::object owner, const mbdae::Result& r, size_t k) {
  if (k >= r.data.size()) throw py::index_error("column index out of range");
  const std::vector<double>& col = r.data[k];
  py::array_t<double> a({static_cast<py::ssize_t>(col.size())}, {static_cast<py::ssize_t>(sizeof(double))},
                        col.data(), owner);
  py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return std::move(a);
}

// The main thread's id, read once when the module is imported. Not a function-local static:
// its initializer calls into Python, which may hand the GIL to another thread that then waits on
// the static's guard while holding the GIL (a deadlock seen with two sweep threads).
unsigned long g_main_thread_id = 0;
unsigned long main_thread_id() { return g_main_thread_id; }

const char* step_type_name(mbdae::AnalysisStep::Type t) { return mbdae::analysis_type(t).name.c_str(); }

// Runs on a private copy of the scene (another Python thread may change the caller's Scene) with
// the GIL released, so runs in Python threads proceed in parallel. In the main thread the run goes
// to a helper thread while this one checks for Ctrl-C every 50 ms: a signal stops the run at its
// next step (RunOptions::stop) and is raised (KeyboardInterrupt) once the run has ended.
std::shared_ptr<mbdae::Result> run_released(const mbdae::Scene& scene, PyRunOptions options) {
  check_options(scene, options);
  const mbdae::Scene copy = scene;
  const bool main_thread = PyThread_get_thread_ident() == main_thread_id();
  if (!main_thread) {
    py::gil_scoped_release release;
    return std::make_shared<mbdae::Result>(run_with_sinks(copy, options));
  }
  std::atomic<bool> stop{false};
  options.stop = &stop;
  auto job = std::async(std::launch::async, [&] { return std::make_shared<mbdae::Result>(run_with_sinks(copy, options)); });
  bool interrupted = false;
  while (true) {
    {
      py::gil_scoped_release release;
      if (job.wait_for(std::chrono::milliseconds(50)) == std::future_status::ready) break;
    }
    if (!interrupted && PyErr_CheckSignals() != 0) {
      interrupted = true;  // the error stays set; the run ends at its next step
      stop = true;
    }
  }
  auto result = job.get();
  if (interrupted) throw py::error_already_set();
  return result;
}

void bind_scene(py::module_& m) {
  py::class_<mbdae::Scene>(m, "Scene")
      .def("copy", [](const mbdae::Scene& s) { return mbdae::Scene(s); })
      .def_readonly("file", &mbdae::Scene::file)
      .def_property_readonly("columns", [](const mbdae::Scene& s) { return s.columns; })
      .def_property_readonly("step_types", [](const mbdae::Scene& s) {
        std::vector<std::string> types;
        for (const auto& step : s.steps) types.push_back(step_type_name(step.type));
        return types;
      });
  m.def("load_scene", &mbdae::load_scene, py::arg("path"));
  m.def("load_scene_text", &mbdae::load_scene_text, py::arg("text"), py::arg("path"));
  m.def("set_parameter", &mbdae::set_parameter, py::arg("scene"), py::arg("path"), py::arg("yaml_value"));
  m.def("with_parameters", &mbdae::with_parameters, py::arg("scene"), py::arg("overrides"));
  m.def("formulations", &mbdae::formulations);
  // Scene.parameters() and Scene.output_columns() (docs/python.md).
  m.def("parameters", [](const mbdae::Scene& scene) {
    std::vector<py::dict> out;
    for (const auto& p : mbdae::parameters(scene))
      out.push_back(py::dict(py::arg("path") = p.path, py::arg("value") = p.value, py::arg("unit") = p.unit,
                             py::arg("file") = p.file, py::arg("line") = p.line));
    return out;
  }, py::arg("scene"));
  m.def("output_columns", &mbdae::output_columns, py::arg("scene"));
}

void bind_run(py::module_& m) {
  py::class_<mbdae::RunOptions>(m, "RunOptionsBase");
  py::class_<PyRunOptions, mbdae::RunOptions>(m, "RunOptions")
      .def(py::init<>())
      .def_readwrite("rtol", &mbdae::RunOptions::rtol)
      .def_readwrite("atol", &mbdae::RunOptions::atol)
      .def_readwrite("output_step", &mbdae::RunOptions::output_step)
      .def_readwrite("formulation", &mbdae::RunOptions::formulation)
      .def_readwrite("sensitivities", &mbdae::RunOptions::sensitivities)
      .def_readwrite("analysis", &mbdae::RunOptions::analysis)
      .def_readwrite("verbose", &mbdae::RunOptions::verbose)
      .def_readwrite("progress", &mbdae::RunOptions::progress)
      .def_readwrite("report_failures", &mbdae::RunOptions::report_failures)
      .def_readwrite("out_dir", &PyRunOptions::out_dir)
      .def_readwrite("animation_dir", &PyRunOptions::animation_dir)
      .def_readwrite("animation_rate", &PyRunOptions::animation_rate)
      .def_property("error_estimate", [](const PyRunOptions& o) { return o.error.estimate; },
                    [](PyRunOptions& o, bool v) { o.error.estimate = v; })
      .def_property("error_target", [](const PyRunOptions& o) { return o.error.target; },
                    [](PyRunOptions& o, double v) { o.error.target = v; })
      .def_property("error_warnings", [](const PyRunOptions& o) { return o.error.warnings; },
                    [](PyRunOptions& o, bool v) { o.error.warnings = v; })
      .def_property("error_sensors", [](const PyRunOptions& o) { return o.error.sensors; },
                    [](PyRunOptions& o, std::vector<std::string> v) { o.error.sensors = std::move(v); });
  m.def("check_error_sensors", [](const mbdae::Scene& s, const std::vector<std::string>& names) {
    return mbdae::check_error_sensors(s, names, "error_sensors");
  });
  py::class_<mbdae::Result, std::shared_ptr<mbdae::Result>>(m, "Result")
      .def_readonly("status", &mbdae::Result::status)
      .def_readonly("message", &mbdae::Result::message)
      .def_readonly("exit_code", &mbdae::Result::exit_code)
      .def_readonly("names", &mbdae::Result::columns)
      .def_readonly("units", &mbdae::Result::units)
      .def_readonly("q", &mbdae::Result::q)
      .def_property_readonly("rows", &mbdae::Result::rows)
      .def_property_readonly("summary_json", [](const mbdae::Result& r) { return r.summary.dump(); })
      .def("column", [](py::object self, size_t k) { return column_view(self, self.cast<const mbdae::Result&>(), k); })
      .def_readonly("sensitivity_names", &mbdae::Result::sensitivity_columns)
      .def_readonly("sensitivity_units", &mbdae::Result::sensitivity_units)
      .def("sensitivity_column", [](const mbdae::Result& r, size_t k) {
        if (k >= r.sensitivities.size()) throw py::index_error("sensitivity column index out of range");
        return py::array_t<double>(r.sensitivities[k].size(), r.sensitivities[k].data());  // a copy
      });
  m.def("run", &run_released, py::arg("scene"), py::arg("options"));
  m.def("option_errors", [](const mbdae::Scene& scene, const PyRunOptions& options) {
    return mbdae::run_option_errors(scene, options);
  }, py::arg("scene"), py::arg("options"));
}

}  // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() = "mbdae's C++ API (cases/mbdae.h); use the mbdae package, not this module";
  m.attr("__version__") = MBDAE_PY_VERSION;  // project(mbdae VERSION ...), cases/python/CMakeLists.txt
  // Scene and model errors as one exception carrying the CLI's lines (file:line: field 'x': ...);
  // the package turns them into mbdae.SceneError with the fields parsed.
  g_main_thread_id = py::module_::import("threading").attr("main_thread")().attr("ident").cast<unsigned long>();
  static py::exception<mbdae::SceneError> scene_error(m, "SceneErrorLines", PyExc_ValueError);
  py::register_exception_translator([](std::exception_ptr p) {
    auto raise = [](const std::vector<std::string>& lines) { PyErr_SetObject(scene_error.ptr(), py::cast(lines).ptr()); };
    try {
      if (p) std::rethrow_exception(p);
    } catch (const mbdae::SceneError& e) {
      raise(e.messages);
    } catch (const mbdae::ModelError& e) {
      raise({e.what()});
    } catch (const mbdae::OutputError& e) {  // a folder in use, a file that cannot be written
      PyErr_SetString(PyExc_OSError, e.what());
    }
  });
  bind_scene(m);
  bind_run(m);
}
