"""Parameter sweeps on Dask: one task per run, one result file per run, one table of all runs.

Where things run: the client (the caller's process) expands the grid, skips the runs already
done in `out`, submits one task per remaining run and writes every file; each task (on a Dask
worker, this machine's LocalCluster by default) re-reads the scene, applies its overrides, runs
it, computes the metrics and sends back its row and its columns. See docs/python.md."""
import contextlib
import hashlib
import itertools
import json
import os
import socket
import sys
import time
import uuid
from pathlib import Path

import numpy as np

from .errors import SceneError

# Sweep keys that are run options (as scene.run's arguments), not scene parameter paths.
RUN_OPTIONS = ("rtol", "atol", "formulation", "output_step", "analysis")
# Statuses of runs that did not complete for reasons outside the run (a lost worker, a task
# error): a later sweep into the same folder runs them again.
RETRY_STATUSES = ("lost",)


def expand(params):
    """The runs of a sweep: a dict of lists is a grid (the first key varies slowest), a list of
    dicts is taken as it is. Each run is a dict {path or run option: value}."""
    if isinstance(params, dict):
        keys = list(params)
        values = [list(np.atleast_1d(params[k])) if not isinstance(params[k], (list, tuple)) else list(params[k])
                  for k in keys]
        return [dict(zip(keys, combo)) for combo in itertools.product(*values)]
    return [dict(p) for p in params]


def _plain(v):
    return v.item() if hasattr(v, "item") else v


def run_key(scene, run, options):
    """A hash naming a run's inputs (scene source and overrides, parameters, options): a folder's
    finished run is reused only by a run with the same key."""
    text = scene._text if scene._text is not None else Path(scene._path).read_text()
    blob = json.dumps([scene._path, text, scene.overrides, {k: _plain(v) for k, v in run.items()},
                       {k: _plain(v) for k, v in sorted(options.items())}], default=str)
    return hashlib.sha1(blob.encode()).hexdigest()[:16]


def run_one(scene, run, options, metrics):
    """The task: one run with its overrides and options; never raises for a bad or failing run
    (the row says what happened). Returns {"row": ..., "columns": {name: array}, "summary": json}."""
    cpu0, wall0 = time.thread_time(), time.perf_counter()
    row = {"status": "", "message": "", "worker": f"{socket.gethostname()}:{os.getpid()}"}
    overrides = [(k, v) for k, v in run.items() if k not in RUN_OPTIONS]
    opts = dict(options, **{k: _plain(v) for k, v in run.items() if k in RUN_OPTIONS})
    result = None
    try:
        result = scene.with_params(overrides).run(raise_on_failure=False, **opts)
    except SceneError as e:
        row.update(status="invalid", message=str(e))
    except ValueError as e:  # a bad run option
        row.update(status="invalid", message=str(e))
    except Exception as e:  # noqa: BLE001 -- recorded in the table, the sweep goes on
        row.update(status="error", message=f"{type(e).__name__}: {e}")
    row["cpu_s"] = time.thread_time() - cpu0
    row["wall_s"] = time.perf_counter() - wall0
    if result is None:
        return {"row": row, "columns": None, "summary": None}
    row.update(status=result.status, message=result.message, solver_cpu_s=result.cpu_seconds(), rows=result.rows)
    for name, f in (metrics or {}).items():
        try:
            row[name] = float(f(result)) if result.rows else float("nan")
        except Exception as e:  # noqa: BLE001
            row[name] = float("nan")
            row["message"] = (row["message"] + "; " if row["message"] else "") + f"metric {name}: {type(e).__name__}: {e}"
    return {"row": row, "columns": {n: np.array(a) for n, a in result.columns.items()}, "summary": result._summary_json}


# ---- Files --------------------------------------------------------------------------------------
def _run_name(i):
    return f"run_{i:05d}"


def _write_run_file(path, columns, params, summary):
    """One run's samples as HDF5 (pandas.read_hdf(path)), its parameters and summary.json as
    attributes; written to a temporary name and renamed, so a file present is complete."""
    import pandas as pd
    tmp = path.with_suffix(".tmp")
    with pd.HDFStore(tmp, mode="w") as store:
        store.put("results", pd.DataFrame(columns), format="fixed")
        attrs = store.get_storer("results").attrs
        attrs.params = json.dumps(params, default=str)
        attrs.summary = summary or "{}"
    os.replace(tmp, path)


def _write_json(path, obj):
    tmp = path.with_suffix(".tmp")
    tmp.write_text(json.dumps(obj, default=str))
    os.replace(tmp, path)


def _done_runs(runs_dir, keys):
    """{index: row} of the runs finished in an earlier sweep with the same inputs."""
    done = {}
    for i, key in enumerate(keys):
        p = runs_dir / (_run_name(i) + ".json")
        if p.exists():
            row = json.loads(p.read_text())
            if row.get("key") == key and row.get("status") not in RETRY_STATUSES:
                done[i] = row
    return done


def _record(out, i, key, run, payload):
    """Writes run i's result file (if it has samples) then its row: the row is the mark of a
    finished run."""
    row = {"run": i, **{k: _plain(v) for k, v in run.items()}, **payload["row"], "key": key, "file": ""}
    if payload.get("columns"):
        name = Path("runs") / (_run_name(i) + ".h5")
        _write_run_file(out / name, payload["columns"], {k: _plain(v) for k, v in run.items()}, payload["summary"])
        row["file"] = str(name)
    _write_json(out / "runs" / (_run_name(i) + ".json"), row)
    return row


def _table(out, rows, param_names, metric_names):
    import pandas as pd
    first = ["run", *param_names, "status", "message", "cpu_s", "solver_cpu_s", "wall_s", "rows", *metric_names]
    df = pd.DataFrame(sorted(rows, key=lambda r: r["run"]))
    for c in first:
        if c not in df.columns:
            df[c] = np.nan
    df = df[first + [c for c in df.columns if c not in first]]
    tmp = out / "runs.csv.tmp"
    df.to_csv(tmp, index=False)
    os.replace(tmp, out / "runs.csv")
    return df


# ---- Dask -----------------------------------------------------------------------------------------
@contextlib.contextmanager
def dask_client(client=None, workers=None):
    """A distributed.Client: the one given, one connected to a scheduler address, or (None) a
    LocalCluster of `workers` worker processes (default: one per core), one thread each."""
    from distributed import Client, LocalCluster
    if isinstance(client, Client):
        yield client
        return
    if isinstance(client, str):
        with Client(client) as c:
            yield c
        return
    if client is not None:
        raise TypeError(f"client: expected None, a distributed.Client or a scheduler address, got {client!r}")
    n = workers or os.cpu_count() or 1
    with LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            Client(cluster) as c:
        yield c


class _Progress:
    """A text progress bar on stderr (redrawn in place on a terminal, every 10 % otherwise)."""

    def __init__(self, total, skipped, enabled):
        self.total, self.done, self.failed, self.skipped = total, skipped, 0, skipped
        self.enabled, self.tty = enabled, sys.stderr.isatty()
        self.start, self.last_tenth = time.perf_counter(), -1
        self.draw()

    def update(self, status):
        self.done += 1
        self.failed += status != "ok"
        self.draw()

    def draw(self):
        if not self.enabled:
            return
        frac = self.done / self.total if self.total else 1.0
        tenth = int(frac * 10)
        if not self.tty and tenth == self.last_tenth and self.done < self.total:
            return
        self.last_tenth = tenth
        bar = "#" * int(frac * 30) + "." * (30 - int(frac * 30))
        line = (f"sweep [{bar}] {self.done}/{self.total} runs ({self.skipped} done before, {self.failed} not ok) "
                f"{time.perf_counter() - self.start:.0f} s")
        sys.stderr.write(("\r" + line) if self.tty else (line + "\n"))
        if self.tty and self.done >= self.total:
            sys.stderr.write("\n")
        sys.stderr.flush()


def sweep(scene, params, out, client=None, metrics=None, options=None, workers=None, progress=True, retries=1):
    """Runs `scene` once per parameter set, one Dask task each, and returns the table of all runs
    (a pandas DataFrame, also written to OUT/runs.csv).

    params: a grid {path: [values]} or a list of {path: value}; paths are scene parameters
      (forces.suspension.damping) or run options (rtol, atol, formulation, output_step, analysis).
    out: the folder: OUT/runs/run_NNNNN.h5 (each run's samples, pandas.read_hdf) and .json (its
      row), OUT/runs.csv. Runs already finished there with the same inputs are not run again.
    client: None (a LocalCluster of `workers` processes, default one per core), a
      distributed.Client, or a scheduler address ("tcp://host:8786").
    metrics: {column name: function(Result) -> float} (see mbdae.metrics), computed by the task.
    options: run options for every run (rtol=..., formulation=...).
    retries: Dask retries of a task that raised (a worker that died is retried by the scheduler
      up to distributed.scheduler.allowed-failures times).
    A run that is invalid or fails is a row with its status and message; the sweep goes on."""
    from distributed import as_completed
    runs, options, metrics = expand(params), dict(options or {}), dict(metrics or {})
    out = Path(out)
    (out / "runs").mkdir(parents=True, exist_ok=True)
    keys = [run_key(scene, run, options) for run in runs]
    rows = _done_runs(out / "runs", keys)
    todo = [i for i in range(len(runs)) if i not in rows]
    bar = _Progress(len(runs), len(rows), progress)
    if todo:
        with dask_client(client, workers) as c:
            token = uuid.uuid4().hex[:8]
            futures = {c.submit(run_one, scene, runs[i], options, metrics, key=f"mbdae-run-{i}-{token}",
                                pure=False, retries=retries): i for i in todo}
            for fut in as_completed(futures):
                i = futures[fut]
                try:
                    payload = fut.result()
                except Exception as e:  # noqa: BLE001 -- a worker lost too often, a task error
                    payload = {"row": {"status": "lost", "message": f"{type(e).__name__}: {e}"}}
                rows[i] = _record(out, i, keys[i], runs[i], payload)
                bar.update(rows[i]["status"])
                fut.release()
    param_names = list(dict.fromkeys(k for run in runs for k in run))
    table = _table(out, rows.values(), param_names, list(metrics))
    table.attrs["skipped"] = len(runs) - len(todo)
    return table


def read_run(out, run):
    """(DataFrame of run `run`'s samples, its parameters, its summary dict) from a sweep folder."""
    import pandas as pd
    path = Path(out) / "runs" / (_run_name(run) + ".h5")
    with pd.HDFStore(path, mode="r") as store:
        attrs = store.get_storer("results").attrs
        return store["results"], json.loads(attrs.params), json.loads(attrs.summary)
