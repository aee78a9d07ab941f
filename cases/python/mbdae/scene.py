"""Scene: a scene file loaded by the C++ loader, parameter overrides by path, and run()."""
import json
import math
import os
import reprlib
import shutil
import tempfile
import weakref

from . import _core
from .errors import SceneError, SolveError
from .result import Result


def _scene_errors(call, *args):
    """Calls into _core, turning its scene errors into mbdae.SceneError."""
    try:
        return call(*args)
    except _core.SceneErrorLines as e:
        raise SceneError(e.args[0]) from None


class _TemporaryFolder:
    """The folder of run(animation=True) without `out`: a new temporary folder, removed by
    remove() (when its Result is collected, or at exit)."""

    def __init__(self):
        self.path = tempfile.mkdtemp(prefix="mbdae_animation_")

    def remove(self):
        shutil.rmtree(self.path, ignore_errors=True)


def yaml_value(value):
    """A Python value as the YAML text set_parameter takes: numbers exactly (repr round-trips),
    lists and dicts as flow YAML (JSON), strings as they are (already YAML text)."""
    if isinstance(value, str):
        return value
    if isinstance(value, bool):
        return "true" if value else "false"
    if hasattr(value, "item") and not isinstance(value, (list, tuple, dict)):  # numpy scalars
        value = value.item()
    if isinstance(value, float):
        if not math.isfinite(value):
            return {math.inf: ".inf", -math.inf: "-.inf"}.get(value, ".nan")
        return repr(value)
    if isinstance(value, int):
        return str(value)
    return json.dumps(value, default=lambda v: v.item() if hasattr(v, "item") else v.tolist())


class Scene:
    """A scene (model and analyses) ready to run. Build one with mbdae.load(path),
    Scene.from_yaml(text) or Scene.from_dict(d). Scenes pickle (for Dask) as their source text and
    overrides and are re-read on the other side; the model file a scene names is read there from
    the same path."""

    def __init__(self, core, path, text, overrides=()):
        self._core = core
        self._path = path        # for messages and to find the model file
        self._text = text        # None: re-read from path when unpickled
        self.overrides = list(overrides)  # (path, yaml text) applied in order

    # ---- Building ---------------------------------------------------------------------------
    @classmethod
    def from_file(cls, path):
        return cls(_scene_errors(_core.load_scene, str(path)), os.path.abspath(path), None)

    @classmethod
    def from_yaml(cls, text, path="<string>.yaml"):
        """A scene from YAML text; `path` names it in messages and its folder is where a
        `model:` file is looked for (default: the current folder)."""
        return cls(_scene_errors(_core.load_scene_text, text, str(path)), str(path), text)

    @classmethod
    def from_dict(cls, d, path="<dict>.yaml"):
        """A scene from a dict with the YAML file's structure (written as indented JSON, which is
        YAML, so messages name the line of that text)."""
        return cls.from_yaml(json.dumps(d, indent=1, default=lambda v: v.item() if hasattr(v, "item") else v.tolist()),
                             path)

    # ---- Overrides --------------------------------------------------------------------------
    def set(self, path, value):
        """Overrides one parameter by path (forces.suspension.damping, analysis.dynamics.t_end,
        bodies.wheel.mass, gravity, ...) with the scene file's own validation: a bad value raises
        SceneError naming the file, line and field. Returns the scene."""
        text = yaml_value(value)
        _scene_errors(_core.set_parameter, self._core, path, text)
        self.overrides.append((path, text))
        return self

    def with_params(self, params):
        """A copy with every {path: value} override applied in order; this scene is unchanged."""
        items = params.items() if hasattr(params, "items") else params
        overrides = [(p, yaml_value(v)) for p, v in items]
        core = _scene_errors(_core.with_parameters, self._core, overrides)
        return Scene(core, self._path, self._text, self.overrides + overrides)

    def copy(self):
        return Scene(self._core.copy(), self._path, self._text, self.overrides)

    # ---- Running ----------------------------------------------------------------------------
    def run_options(self, rtol=None, atol=None, formulation=None, output_step=None, analysis=None, sensitivities=None):
        """RunOptions with the command line's range checks (`mbdae run --rtol ...`, cases/field_ranges.h):
        a value out of range raises ValueError naming the option, as the CLI's message does."""
        opt = _core.RunOptions()
        if rtol is not None:
            opt.rtol = _number("rtol", rtol)
        if atol is not None:
            opt.atol = _number("atol", atol)
        if output_step is not None:
            opt.output_step = _number("output_step", output_step)
        if formulation is not None:
            opt.formulation = str(formulation)
        if sensitivities is not None:
            opt.sensitivities = _paths("sensitivities", sensitivities)
        errors = _core.option_errors(self._core, opt)
        if errors:
            raise ValueError("\n".join(errors))
        if analysis is not None:
            opt.analysis = self._analysis_index(analysis)
        return opt

    def run(self, rtol=None, atol=None, formulation=None, output_step=None, analysis=None, out=None,
            raise_on_failure=True, animation=None, animation_rate=None, error_estimate=None, error_target=None,
            error_sensors=None, error_warnings=True, sensitivities=None, report_failures=True):
        """Runs the analyses (the CLI's `mbdae run`): tolerances, output step and formulation
        override the scene's when given; `analysis` (an index or a step type such as "dynamics")
        stops after that step; `out` also writes results.csv and summary.json there. `animation`
        (a folder, or True for `out` or a new temporary folder, removed with the Result or at
        exit) also writes the run as a ParaView time series (animation.pvd, docs/animation.md)
        that Result.animation() draws as a video;
        `animation_rate` sets its frames per second of simulated time. `error_estimate=True` adds
        the global error estimate (summary["error_estimate"], docs/formulation.md);
        `error_target=E` picks rtol and atol so that the estimated error of `error_sensors` (a list
        of names; default every output sensor, E then relative to each one's scale) is at most E
        (summary["error_target"]; status "accuracy_not_met" when it cannot); error_warnings=False
        keeps the estimate's warnings (over 10 rtol) off stderr. `sensitivities` (a parameter path
        as a str, or a list or tuple of them, as `set` takes them; other types are a TypeError)
        also integrates d(sensor)/d(parameter) of every output sensor (Result.sensitivities,
        docs/sensitivities.md). report_failures=False keeps a failure's one-line message (and a
        stop of the sensitivities) off stderr: the Result holds it. Returns a Result; a failed
        solve raises SolveError carrying the partial Result (or returns it, with
        raise_on_failure=False). The GIL is released while solving."""
        opt = self.run_options(rtol, atol, formulation, output_step, analysis, sensitivities)
        if out is not None:
            opt.out_dir = str(out)
        temporary = None
        if animation is True:
            temporary = None if out is not None else _TemporaryFolder()
            animation = out if out is not None else temporary.path
        if animation:
            opt.animation_dir = str(animation)
        try:
            if animation_rate is not None:
                opt.animation_rate = _positive("animation_rate", animation_rate)
            self._error_options(opt, error_estimate, error_target, error_sensors)
            if not isinstance(error_warnings, bool):
                raise ValueError(f"error_warnings expects True or False, got {error_warnings!r}")
            opt.error_warnings = error_warnings
            if not isinstance(report_failures, bool):
                raise ValueError(f"report_failures expects True or False, got {report_failures!r}")
            opt.report_failures = report_failures
            result = Result._from_core(_scene_errors(_core.run, self._core, opt))
        except BaseException:
            if temporary:
                temporary.remove()
            raise
        result.animation_dir = opt.animation_dir or None
        if temporary:  # removed with the Result (or at exit), not left behind in the temp folder
            weakref.finalize(result, temporary.remove)
        if opt.analysis >= 0 and len(result.summary.get("steps", [])) > opt.analysis + 1:
            raise NotImplementedError("run(analysis=...): this build's mbdae::run ignores RunOptions::analysis")
        if raise_on_failure and not result.ok:
            raise SolveError(result)
        return result

    def _error_options(self, opt, error_estimate, error_target, error_sensors):
        if error_estimate is not None:
            if not isinstance(error_estimate, bool):
                raise ValueError(f"error_estimate expects True or False, got {error_estimate!r}")
            opt.error_estimate = error_estimate
        if error_target is not None:
            opt.error_target = _positive("error_target", error_target)
        if error_sensors is not None:
            if isinstance(error_sensors, str):
                error_sensors = [error_sensors]
            names = list(error_sensors)
            if not names or not all(isinstance(n, str) and n for n in names):
                raise ValueError(f"error_sensors expects a list of sensor names, got {error_sensors!r}")
            if error_target is None:
                raise ValueError("error_sensors needs error_target")
            bad = _core.check_error_sensors(self._core, names)
            if bad:
                raise ValueError("; ".join(bad))
            opt.error_sensors = names

    def _analysis_index(self, analysis):
        types = self._core.step_types
        if isinstance(analysis, str):
            if analysis not in types:
                raise ValueError(f"analysis '{analysis}': the scene's steps are {', '.join(types)}")
            return len(types) - 1 - types[::-1].index(analysis)
        if not 0 <= int(analysis) < len(types):
            raise ValueError(f"analysis {analysis}: the scene has steps 0 to {len(types) - 1} ({', '.join(types)})")
        return int(analysis)

    @property
    def file(self):
        return self._core.file

    @property
    def steps(self):
        """The analysis steps' types, in order."""
        return list(self._core.step_types)

    def __repr__(self):
        extra = f", {len(self.overrides)} overrides" if self.overrides else ""
        return f"<mbdae.Scene {self.file}: {', '.join(self.steps)}{extra}>"

    def __reduce__(self):
        return (_rebuild, (self._path, self._text, self.overrides))

    # ---- Inspection -------------------------------------------------------------------------
    def parameters(self):
        """Every parameter path of the scene (and its model file) with its current value (YAML
        text) and unit, from the resolver set() uses: [{"path", "value", "unit", "file", "line"}].
        The same list as `mbdae params SCENE`."""
        return [dict(p) for p in _scene_errors(_core.parameters, self._core)]

    def output_columns(self):
        """[(name, unit)] of the columns a run writes ("t", then the output sensors), without
        running (the model is built)."""
        return [tuple(c) for c in _scene_errors(_core.output_columns, self._core)]

    def _repr_html_(self):
        from html import escape
        cols = ", ".join(f"{escape(n)} [{escape(u)}]" for n, u in self.output_columns())
        over = "".join(f"<li>{escape(p)} = {escape(v)}</li>" for p, v in self.overrides)
        return (f"<p><b>mbdae.Scene</b> {escape(str(self.file))}<br>steps: {escape(', '.join(self.steps))}<br>"
                f"columns: {cols}</p>" + (f"<p>overrides:</p><ul>{over}</ul>" if over else ""))


def _rebuild(path, text, overrides):
    scene = Scene.from_file(path) if text is None else Scene.from_yaml(text, path)
    if not overrides:
        return scene
    return Scene(_scene_errors(_core.with_parameters, scene._core, list(overrides)), path, text, overrides)


def _paths(name, value):
    """Parameter paths for option `name`: one path (a str) or a list or tuple of them. Anything else
    (a dict, a set, bytes, an iterator) is a TypeError, not read as its keys, in some order or
    byte by byte; an empty path or one that UTF-8 cannot encode (a lone surrogate) is a ValueError."""
    items = [value] if isinstance(value, str) else value
    if not isinstance(items, (list, tuple)):
        raise TypeError(f"{name} expects a parameter path or a list of them (a str, or a list or tuple of str), "
                        f"got {_given(value)}")
    for p in items:
        if not isinstance(p, str):
            raise TypeError(f"{name} expects parameter paths (non-empty strings), got {_given(p)} in {_given(value)}")
        if not p:
            raise ValueError(f"{name} expects parameter paths (non-empty strings), got {p!r}")
        try:
            p.encode("utf-8")
        except UnicodeEncodeError as e:
            raise ValueError(f"{name}: the path {p!r} cannot be encoded as UTF-8 ({e.reason})") from None
    return list(items)


def _given(value):
    """What a caller passed, for a message: its type and a shortened repr ("bytes b'gravity.2'")."""
    return f"{type(value).__name__} {reprlib.repr(value)}"


def _number(name, value):
    """A finite number for option `name`; 0 (which RunOptions reads as "not given") is refused here,
    the ranges are the CLI's (checked by _core.option_errors)."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: expected a number, got {value!r}") from None
    if v == 0 or not math.isfinite(v):
        raise ValueError(f"{name}: must be a positive finite number, got {value!r}")
    return v


def _positive(name, value, upper=math.inf):
    v = float(value)
    if not (v > 0) or v > upper or math.isinf(v):
        raise ValueError(f"{name} expects a number in (0, {upper:g}], got {value!r}")
    return v


def load(path):
    """Reads a scene file (and the model file it names); a bad file raises SceneError."""
    return Scene.from_file(path)
