"""What a sweep checks before its first run (every parameter path and every metric's columns,
against the scene, with "did you mean" suggestions) and how it names what defines a run and a
metric (the hashes resume is keyed by)."""
import difflib
import hashlib
import json
import numbers
import os
from pathlib import Path

import numpy as np

from ._core import formulations
from .errors import SceneError

# Sweep keys that are run options (as scene.run's arguments), not scene parameter paths.
RUN_OPTIONS = ("rtol", "atol", "formulation", "output_step", "analysis", "sensitivities")


def plain(v):
    """numpy scalars as Python numbers (for JSON and hashing)."""
    return v.item() if hasattr(v, "item") and not isinstance(v, np.ndarray) else v


def suggestion(name, candidates):
    """" (did you mean 'x'?)" for the closest candidate, or ""."""
    close = difflib.get_close_matches(name, list(candidates), n=1, cutoff=0.6)
    if not close:
        return ""
    return " (did you mean " + " or ".join(f"'{c}'" for c in close) + "?)"


def _unknown_path(error):
    """True if a SceneError says the path itself is wrong (no such item or field), not its value."""
    return any(("unknown parameter" in e["message"] or "unknown field" in e["message"]
                or "has no fields to set" in e["message"] or "no item" in e["message"]) for e in error.errors)


def check_parameters(scene, runs):
    """Every parameter path of `runs` resolves in the scene (the resolver of scene.set): a path
    listed by scene.parameters(), or one the scene accepts (an optional field not written in the
    file). Raises SceneError naming the path, with suggestions, before anything runs. A value the
    scene rejects is not an error here: that run becomes an `invalid` row."""
    first = {}
    for run in runs:
        for k, v in run.items():
            if k not in RUN_OPTIONS:
                first.setdefault(k, v)
    if not first:
        return
    known = [p["path"] for p in scene.parameters()]
    for path, value in first.items():
        if path in known:
            continue
        try:
            scene.with_params({path: value})
        except SceneError as e:
            if _unknown_path(e):
                lines = [f"{scene.file}: field '{path}': unknown parameter path{suggestion(path, known)}; "
                         f"`mbdae params {scene.file}` or scene.parameters() lists them"]
                raise SceneError(lines + [f"  {line}" for line in e.lines]) from None


def check_options(options):
    unknown = [k for k in options if k not in RUN_OPTIONS]
    if unknown:
        raise ValueError(f"options: unknown run option '{unknown[0]}'{suggestion(unknown[0], RUN_OPTIONS)} "
                         f"(run options: {', '.join(RUN_OPTIONS)})")


def check_sensitivities(scene, runs, options):
    """The sensitivities of `options` and of every run whose grid entry sets `sensitivities` or
    `formulation`, checked as scene.run checks them (with the run's formulation: index3 refuses
    them) before the first run: a bad type is a TypeError, a bad path or combination a ValueError,
    naming the grid entry. A formulation that is no registered one is left to its run (an
    `invalid` row, as any bad value)."""
    if "sensitivities" in options:
        scene.run_options(sensitivities=options["sensitivities"], formulation=_known(options.get("formulation")))
    seen = set()
    for i, run in enumerate(runs):
        if "sensitivities" not in run and "formulation" not in run:
            continue
        merged = {**options, **{k: plain(v) for k, v in run.items() if k in ("sensitivities", "formulation")}}
        asked = {k: merged[k] for k in ("sensitivities", "formulation") if k in merged}
        if asked.get("sensitivities") is None or repr(asked) in seen:
            continue
        seen.add(repr(asked))
        try:
            scene.run_options(sensitivities=asked["sensitivities"], formulation=_known(asked.get("formulation")))
        except (TypeError, ValueError) as e:
            given = ", ".join(f"{k}={v!r}" for k, v in asked.items())
            raise type(e)(f"params: run {i} ({given}): {e}") from None


def _known(formulation):
    """`formulation` if it is a registered one, else None (its run refuses it)."""
    return formulation if isinstance(formulation, str) and formulation in formulations() else None


def check_metrics(scene, metrics):
    """Every column a metric reads (its `columns` attribute; mbdae.metrics sets it) is an output
    column of the scene; every metric is callable. Raises ValueError before the first run."""
    columns = [c for c, _ in scene.output_columns()]
    for name, f in metrics.items():
        if not callable(f):
            raise ValueError(f"metric '{name}': expected a function Result -> float, got {f!r}")
        for c in getattr(f, "columns", ()):
            if c not in columns:
                raise ValueError(f"metric '{name}' ({getattr(f, '__name__', f)}): the scene has no output column "
                                 f"'{c}'{suggestion(c, columns)} (columns: {', '.join(columns)})")


def check_workers(workers, client=None):
    """A local worker count: a whole number from 1 to 1024 threads, or to 4 per core for
    processes (each a Python interpreter of its own)."""
    if workers is None:
        return None
    if isinstance(workers, bool) or not isinstance(workers, numbers.Integral) or workers < 1:
        raise ValueError(f"workers expects a whole number >= 1 (local workers), got {workers!r}")
    limit = 4 * (os.cpu_count() or 1) if client == "processes" else 1024
    if workers > limit:
        raise ValueError(f"workers: {workers} is more than {limit} local "
                         f"{'processes (4 per core)' if client == 'processes' else 'threads'}")
    return int(workers)


# ---- Keys ---------------------------------------------------------------------------------------
def _sha(blob):
    return hashlib.sha256(blob.encode() if isinstance(blob, str) else blob).hexdigest()


def scene_key(scene):
    """A hash of the scene's source: its text (or the file's) and its overrides."""
    text = scene._text if scene._text is not None else Path(scene._path).read_text()
    return _sha(json.dumps([text, scene.overrides]))[:16]


def run_key(scene_hash, run, options):
    """A hash naming a run's inputs (scene source and overrides, parameters, options): a folder's
    finished run is reused only by a run with the same key."""
    blob = json.dumps([scene_hash, sorted((k, plain(v)) for k, v in run.items()),
                       sorted((k, plain(v)) for k, v in options.items())], default=str)
    return _sha(blob)[:16]


def _value_blob(v, depth=0):
    """A stable text for a value a metric closes over (arrays and Results by their bytes)."""
    if depth > 3:
        return repr(type(v))
    if isinstance(v, np.ndarray):
        return "array:" + _sha(np.ascontiguousarray(v).tobytes())
    if hasattr(v, "_arrays") and hasattr(v, "names"):  # an mbdae.Result
        return "result:" + _sha("".join(_value_blob(a, depth + 1) for a in v._arrays) + repr(v.names))
    if callable(v) and hasattr(v, "__code__"):
        return metric_fingerprint(v, depth + 1)
    if isinstance(v, (list, tuple)):
        return "[" + ",".join(_value_blob(x, depth + 1) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ",".join(f"{k!r}:{_value_blob(x, depth + 1)}" for k, x in sorted(v.items(), key=repr)) + "}"
    return repr(v)


def _code_blob(code):
    consts = [(_code_blob(c) if hasattr(c, "co_code") else repr(c)) for c in code.co_consts]
    return json.dumps([code.co_code.hex(), consts, list(code.co_names), list(code.co_varnames)])


def metric_fingerprint(f, depth=0):
    """What defines a metric: its spec for mbdae.metrics (peak_deviation:wheel_z), otherwise its
    code, constants, defaults and the values it closes over. Globals it reads are not part of it:
    after changing one, rename the metric or sweep into a new folder."""
    spec = getattr(f, "spec", None)
    if spec:
        return spec
    code = getattr(f, "__code__", None)
    if code is None:
        return "object:" + _sha(_value_blob(f.__dict__ if hasattr(f, "__dict__") else repr(f), depth))[:16]
    cells = [_value_blob(c.cell_contents, depth) for c in (f.__closure__ or ())]
    blob = json.dumps([_code_blob(code), _value_blob(f.__defaults__, depth), cells])
    return f"code:{getattr(f, '__qualname__', '?')}:" + _sha(blob)[:16]
