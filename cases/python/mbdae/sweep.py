"""Parameter sweeps: one task per run, one result file per run, one table of all runs.

Where things run: the caller checks every parameter path and metric column against the scene,
takes the folder's lock, expands the grid, reuses the runs already finished in `out` (files
verified), submits one task per remaining run (to threads of this process by default, or to
Dask) and writes every file; each task applies its overrides to the scene, runs it, computes
the metrics and returns its row and its columns. See docs/python.md."""
import asyncio
import itertools
import json
import os
import socket
import sys
import time
import uuid
from pathlib import Path

import numpy as np

from . import metrics as _metrics
from .errors import SceneError
from .sweep_backends import backend
from .sweep_checks import (RUN_OPTIONS, check_metrics, check_options, check_parameters, check_sensitivities,
                           check_workers, metric_fingerprint, plain, run_key, scene_key)
from .sweep_files import (FolderLock, SweepOutputError, finished_row, read_h5, read_h5_sensitivities, read_json,
                          record, write_json)
from .sweep_table import make_table, read_run, read_sweep, runs_dataset  # noqa: F401 -- re-exported

__all__ = ["sweep", "expand", "run_one", "read_run", "read_sweep", "runs_dataset", "RUN_OPTIONS",
           "SweepOutputError"]


def expand(params):
    """The runs of a sweep: a dict of lists is a grid (the first key varies slowest), a list of
    dicts is taken as it is. Each run is a dict {path or run option: value}."""
    if isinstance(params, dict):
        keys = list(params)
        values = [list(np.atleast_1d(params[k])) if not isinstance(params[k], (list, tuple)) else list(params[k])
                  for k in keys]
        return [dict(zip(keys, combo)) for combo in itertools.product(*values)]
    return [dict(p) for p in params]


def compute_metrics(result, metrics, row):
    """The metrics of `result` into `row`; a metric that raises is NaN and the row's status
    `metric_failed` (never `ok` over a missing value)."""
    failed = []
    for name, f in metrics.items():
        try:
            row[name] = float(f(result)) if result.rows else float("nan")
        except Exception as e:  # noqa: BLE001 -- recorded in the row
            row[name] = float("nan")
            failed.append(f"metric {name}: {type(e).__name__}: {e}")
    row["status"] = row.get("run_status", row.get("status", ""))
    if failed:
        row["status"] = "metric_failed"
        row["message"] = "; ".join(([row["run_message"]] if row.get("run_message") else []) + failed)
    else:
        row["message"] = row.get("run_message", "")
    return row


def run_one(scene, run, options, metrics):
    """The task: one run with its overrides and options; never raises for a bad or failing run
    (the row says what happened). Returns {"row", "columns": {name: array}, "units", "summary",
    "sensitivities": None or {"columns": {name: array}, "units"}}."""
    cpu0, wall0 = time.thread_time(), time.perf_counter()
    row = {"status": "", "message": "", "worker": f"{socket.gethostname()}:{os.getpid()}"}
    overrides = [(k, v) for k, v in run.items() if k not in RUN_OPTIONS]
    opts = dict(options, **{k: plain(v) for k, v in run.items() if k in RUN_OPTIONS})
    result = None
    try:
        # The row holds a failure's message: not on stderr, where threads' lines name no run.
        result = scene.with_params(overrides).run(raise_on_failure=False, report_failures=False, **opts)
    except (SceneError, ValueError) as e:  # a bad override or run option
        row.update(status="invalid", message=str(e))
    except Exception as e:  # noqa: BLE001 -- recorded in the table, the sweep goes on
        row.update(status="error", message=f"{type(e).__name__}: {e}")
    if result is not None:
        row.update(run_status=result.status, run_message=result.message, solver_cpu_s=result.cpu_seconds(),
                   rows=result.rows)
        compute_metrics(result, metrics, row)
    row["cpu_s"] = time.thread_time() - cpu0
    row["wall_s"] = time.perf_counter() - wall0
    if result is None:
        return {"row": row, "columns": None, "units": None, "summary": None, "sensitivities": None}
    return {"row": row, "columns": {n: np.array(a) for n, a in result.columns.items()}, "units": list(result.units),
            "summary": result._summary_json, "sensitivities": _sensitivity_payload(result)}


def _sensitivity_payload(result):
    """The run's sensitivities for its file ({"columns": {name: array}, "units"}), or None."""
    if not result._sens_names:
        return None
    return {"columns": {n: np.array(a) for n, a in zip(result._sens_names, result._sens_arrays)},
            "units": list(result._sens_units)}


def _stored_result(out, row):
    """A Result rebuilt from a run's stored file (to compute changed metrics without running),
    with its sensitivities; None if the run asked for sensitivities its file does not hold (a
    file of an earlier version): the run is then computed again."""
    from .result import Result
    df, _, summary = read_h5(out / row["file"])
    units = df.attrs.get("units", {})
    names = [df.index.name or "t", *df.columns]
    arrays = [df.index.to_numpy(), *(df[c].to_numpy() for c in df.columns)]
    sens = read_h5_sensitivities(out / row["file"])
    if sens is None and "sensitivities" in summary:
        return None
    sensitivity = ((), (), ()) if sens is None else (
        ["t", *sens.columns], [sens.attrs["units"].get(n, "") for n in ["t", *sens.columns]],
        [sens.index.to_numpy(), *(sens[c].to_numpy() for c in sens.columns)])
    return Result(row.get("run_status", row["status"]), row.get("run_message", ""), names, arrays,
                  [units.get(n, "") for n in names], json.dumps(summary), sensitivity=sensitivity)


def _refresh_metrics(out, row, metrics, defs):
    """A reused run whose metrics were defined otherwise: recomputed from its stored samples and
    its row rewritten (never returned stale). None when the stored run cannot give its metrics
    what the run gave them (its sensitivities): it is run again."""
    if row.get("metric_defs") == defs:
        return row
    stored = _stored_result(out, row) if row.get("file") else None
    if row.get("file") and stored is None:
        return None
    for name in set(row.get("metric_defs") or {}) - set(defs):
        row.pop(name, None)
    if stored is not None:
        compute_metrics(stored, metrics, row)
    else:
        row.update({name: float("nan") for name in metrics})
    row["metric_defs"] = defs
    write_json(out / "runs" / f"{row['key']}.json", row)
    return row


def _reused_rows(out, manifest, metrics, defs):
    """({key: row} of the folder's finished runs, with their metrics brought up to date, and how
    many broken runs were removed); the others run again."""
    rows, broken = {}, 0
    for i, e in enumerate(manifest["runs"]):
        row, problem = finished_row(out, e["key"])
        if row is not None:
            row = _refresh_metrics(out, row, metrics, defs)
            problem = "" if row is not None else "its file holds no sensitivities for the changed metrics"
        else:
            broken += bool(problem)
        if row is not None:
            rows[e["key"]] = row
        elif problem:
            print(f"mbdae sweep: run {i}: {problem}; it runs again", file=sys.stderr)
    return rows, broken


def _manifest(out, scene, runs, keys, options, defs, extend):
    """OUT/sweep.json: the folder's runs. A folder holding another sweep (other runs) is refused
    unless `extend`; then its runs are kept and the new ones added after them."""
    path = out / "sweep.json"
    old = read_json(path) if path.exists() else None
    entries = [{"key": k, "params": {p: plain(v) for p, v in r.items()}} for k, r in zip(keys, runs)]
    if isinstance(old, dict) and old.get("runs"):
        old_keys = [e["key"] for e in old["runs"]]
        if set(old_keys) != set(keys):
            if not extend:
                new = sorted({p for r in runs for p in r})
                was = sorted({p for e in old["runs"] for p in e["params"]})
                what = (f"parameters {', '.join(was) or '(none)'}" if was != new else
                        "other values, or another scene or options")
                raise ValueError(f"{out}: holds another sweep ({len(old_keys)} runs, {what}); pass extend=True "
                                 f"(--extend) to add these runs to it, or sweep into another folder")
            known = set(old_keys)
            entries = old["runs"] + [e for e in entries if e["key"] not in known and not known.add(e["key"])]
    manifest = {"scene": str(scene.file), "runs": entries, "options": {k: plain(v) for k, v in options.items()},
                "metrics": defs}
    write_json(path, manifest)
    return manifest


def _units(scene, runs, metrics):
    """{table column: unit}: the run's own columns, the parameters' and the metrics'."""
    column_units = dict(scene.output_columns())
    param_units = {p["path"]: p["unit"] for p in scene.parameters()}
    units = {"cpu_s": "s", "solver_cpu_s": "s", "wall_s": "s", "rows": "1",
             "rtol": "1", "atol": param_units.get("analysis.dynamics.atol", "m"), "output_step": "s"}
    for r in runs:
        for p in r:
            if p not in RUN_OPTIONS:
                units.setdefault(p, param_units.get(p, ""))
    units.update({n: _metrics.unit_of(f, column_units) for n, f in metrics.items()})
    return units


class _Bar:
    """The progress bar (tqdm) on stderr."""

    def __init__(self, total, skipped, enabled):
        self.bar, self.failed = None, 0
        if enabled:
            try:
                from tqdm import tqdm
            except ImportError:
                raise ImportError("sweep progress bars need tqdm (Debian: python3-tqdm); progress=False runs "
                                  "without one") from None
            self.bar = tqdm(total=total, initial=skipped, desc="sweep", unit="run", file=sys.stderr,
                            mininterval=0.5 if sys.stderr.isatty() else 30, dynamic_ncols=True)
            self.bar.set_postfix_str(f"{skipped} done before, 0 not ok", refresh=False)
            self.skipped = skipped

    def update(self, status):
        if self.bar is not None:
            self.failed += status != "ok"
            self.bar.set_postfix_str(f"{self.skipped} done before, {self.failed} not ok", refresh=False)
            self.bar.update(1)

    def close(self):
        if self.bar is not None:
            self.bar.close()


def sweep(scene, params, out, client=None, metrics=None, options=None, workers=None, progress=True, retries=1,
          extend=False, worker_timeout=60.0):
    """Runs `scene` once per parameter set and returns the table of all runs (a pandas
    DataFrame with units in table.attrs["units"], also written to OUT/runs.csv).

    params: a grid {path: [values]} or a list of {path: value}; paths are scene parameters
      (forces.suspension.damping, bodies.chassis.points.bp1.2; scene.parameters() lists them) or
      run options (rtol, atol, formulation, output_step, analysis, sensitivities).
    out: the folder (OUT/runs/KEY.h5 each run's samples, KEY.json its row, OUT/runs.csv,
      OUT/sweep.json). Runs finished there with the same inputs are reused (files verified);
      a folder holding other runs is refused unless extend=True (the runs are added).
    client: None or "threads" (threads of this process, `workers` of them, default one per
      core), "processes" (a Dask LocalCluster of `workers` processes), a distributed.Client or a
      scheduler address ("tcp://host:8786").
    metrics: {column name: function(Result) -> float} (see mbdae.metrics).
    options: run options for every run (rtol=..., formulation=...).
    retries: Dask retries of a task that raised; worker_timeout: seconds without any Dask
      worker after which the unfinished runs are recorded `lost` and the sweep ends.
    Before the first run every parameter path, option and metric column is checked (SceneError /
    ValueError with suggestions). A run that is invalid or fails is a row with its status and
    message; the sweep goes on. A folder that cannot be written raises SweepOutputError (an
    OSError) and keeps the runs finished before whole."""
    runs, options, metrics = expand(params), dict(options or {}), dict(metrics or {})
    check_options(options)
    workers = check_workers(workers, client)
    if workers is not None and client not in (None, "threads", "processes"):
        raise ValueError("workers applies to local runs (client None, 'threads' or 'processes'), not to a given "
                         "Dask cluster (its workers are started with it)")
    if not (isinstance(worker_timeout, (int, float)) and worker_timeout > 0):
        raise ValueError(f"worker_timeout expects seconds > 0, got {worker_timeout!r}")
    check_parameters(scene, runs)
    check_metrics(scene, metrics)
    check_sensitivities(scene, runs, options)
    if not isinstance(out, (str, os.PathLike)) or not str(out):
        raise TypeError(f"out expects the sweep's folder (a non-empty str or path), got {type(out).__name__} {out!r}")
    out = Path(out)
    try:
        (out / "runs").mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise SweepOutputError(e.errno, f"{out}: cannot create the sweep folder: {e.strerror}") from None
    lock = FolderLock(out)
    try:
        return _sweep_locked(scene, runs, out, client, metrics, options, workers, progress, retries, extend,
                             worker_timeout)
    finally:
        lock.release()


def _sweep_locked(scene, runs, out, client, metrics, options, workers, progress, retries, extend, worker_timeout):
    keys = [run_key(scene_key(scene), r, options) for r in runs]
    defs = {n: metric_fingerprint(f) for n, f in metrics.items()}
    try:
        manifest = _manifest(out, scene, runs, keys, options, defs, extend)
        rows, broken = _reused_rows(out, manifest, metrics, defs)
    except OSError as e:
        raise SweepOutputError(e.errno, f"{out}: cannot write the sweep's files: {e.strerror or e}; nothing "
                               f"was run") from None
    params = {e["key"]: e["params"] for e in manifest["runs"]}  # (a key listed twice runs once)
    todo = [k for k in dict.fromkeys(e["key"] for e in manifest["runs"]) if k not in rows]
    skipped = len(params) - len(todo)
    bar = _Bar(len(params), skipped, progress)
    try:
        if todo:
            _execute(scene, todo, params, out, client, metrics, options, workers, retries, worker_timeout, defs,
                     rows, bar)
    finally:
        bar.close()
    units = _units(scene, [e["params"] for e in manifest["runs"]], metrics)
    try:
        table = make_table(out, manifest, rows, list(metrics), units)
    except OSError as e:
        raise SweepOutputError(e.errno, f"{out}/runs.csv: cannot be written: {e.strerror or e}; every run is "
                               f"finished and kept in {out}/runs (start the sweep again to write the table)") from None
    table.attrs["skipped"] = skipped
    table.attrs["rerun_broken"] = broken
    return table


def _execute(scene, todo, params, out, client, metrics, options, workers, retries, worker_timeout, defs, rows, bar):
    """Submits the runs `todo` (keys), records each as it finishes; a write error stops the sweep
    (SweepOutputError) with every run recorded before it whole."""
    index = {k: i for i, k in enumerate(params)}
    bk = backend(client, workers, retries)
    token = uuid.uuid4().hex[:8]
    futures = {bk.submit(run_one, scene, params[k], options, metrics, key=f"mbdae-run-{index[k]}-{token}"): k
               for k in todo}
    pending, clean = set(futures), False
    try:
        while pending:
            done, pending = bk.wait(pending, 0.5)
            for fut in done:
                k = futures[fut]
                try:
                    payload = bk.result(fut, worker_timeout)
                except (TimeoutError, asyncio.TimeoutError):  # the same class from Python 3.11 on
                    payload = {"row": {"status": "lost", "message": (
                        f"the finished run's result was not fetched within {worker_timeout:g} s ({bk.name}): its "
                        "worker died after finishing; the run is repeated by the next sweep into this folder")}}
                except Exception as e:  # noqa: BLE001 -- a worker lost too often, a task error
                    payload = {"row": {"status": "lost", "message": f"{type(e).__name__}: {e}"}}
                rows[k] = _record(out, index[k], k, params[k], payload, defs)
                bar.update(rows[k]["status"])
            if pending and bk.no_workers_for() > worker_timeout:
                message = (f"no Dask worker for {worker_timeout:g} s ({bk.name}): every worker died or none "
                           "connected; the run is repeated by the next sweep into this folder")
                for fut in pending:
                    rows[futures[fut]] = _record(out, index[futures[fut]], futures[fut], params[futures[fut]],
                                                 {"row": {"status": "lost", "message": message}}, defs)
                bk.cancel(pending)
                print(f"mbdae sweep: {message}", file=sys.stderr)
                pending = set()
        clean = True
    finally:
        bk.close(cancel=not clean)


def _record(out, i, key, run, payload, defs):
    try:
        return record(out, i, key, run, payload, defs)
    except OSError as e:
        done = sum(1 for _ in (out / "runs").glob("*.json"))
        raise SweepOutputError(e.errno, f"{out}: cannot write run {i}'s files: {e.strerror or e}; the sweep "
                               f"stopped, {done} finished runs are kept whole in {out}/runs (start the same "
                               f"sweep again to resume)") from None
