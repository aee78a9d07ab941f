"""The shell forms of mbdae.sweep and mbdae.work_precision:

    python3 -m mbdae sweep SCENE --param forces.suspension.damping=700:2800:8 \\
        --param forces.tyre.stiffness=1e5,2e5,4e5 --out DIR [--workers N] [--processes]
        [--scheduler tcp://HOST:8786] [--extend]
    python3 -m mbdae params SCENE    (the parameter paths, as `mbdae params`)

--param PATH=A:B:N is N values evenly spaced from A to B, PATH=V1,V2,... a list, PATH=V one value;
several --param make a grid. --set PATH=VALUE overrides every run; --metric NAME=KIND:COLUMN[:X]
adds a table column (mbdae.metrics.from_spec). Runs go to threads of this process (--workers N,
default one per core), to a local cluster of processes (--processes) or to a Dask scheduler.
Exit codes: 0 every run ok, 1 bad command line (option, metric), 2 bad scene or parameter path,
3 some run not ok, 4 the folder cannot be written or is in use by another sweep or run.

    python3 -m mbdae work-precision SCENE [--out DIR] [--formulations index3,index1]
        [--tols 1e-2,1e-4,...] [--columns wheel_z,wheel_vz] [--reference REF.csv] [--estimate]
        [--atol-ratio R] [--workers N]

runs every formulation at every rtol (default 1e-2 to 1e-10), measures each output column's error
against a reference (a tight run of another formulation, or REF.csv), prints each curve's slope and
floor and writes DIR/work_precision.csv and DIR/work_precision_COLUMN.png (docs/python.md)."""
import argparse
import sys

import numpy as np


def parse_values(text):
    """A:B:N as numpy.linspace(A, B, N); V1,V2,... as a list; numbers where they parse."""
    def value(s):
        try:
            return int(s)
        except ValueError:
            try:
                return float(s)
            except ValueError:
                return s
    parts = text.split(":")
    if len(parts) == 3 and not text.startswith(("{", "[")):
        try:
            a, b, n = float(parts[0]), float(parts[1]), int(parts[2])
        except ValueError:
            raise ValueError(f"'{text}': A:B:N expects two numbers and a count") from None
        return [float(v) for v in np.linspace(a, b, n)]
    if text.startswith(("[", "{")):
        return [text]
    return [value(s) for s in text.split(",")]


def _pair(text, what):
    if "=" not in text:
        raise ValueError(f"{what} expects PATH=VALUE, got '{text}'")
    return text.split("=", 1)


def _workers(text):
    try:
        n = int(text)
    except ValueError:
        n = 0
    if n < 1:
        raise argparse.ArgumentTypeError(f"expects a whole number >= 1, got '{text}'")
    return n


def _params_command(a):
    import mbdae
    try:
        params = mbdae.load(a.scene).parameters()
    except mbdae.SceneError as e:
        print(e, file=sys.stderr)
        return 2
    for p in params:
        print(f"{p['path']} = {p['value']}" + (f" [{p['unit']}]" if p["unit"] else ""))
    return 0


class _Parser(argparse.ArgumentParser):
    """argparse with the documented exit code 1 for a bad command line (argparse's own is 2)."""

    def error(self, message):
        self.print_usage(sys.stderr)
        self.exit(1, f"{self.prog}: error: {message}\n")


def _list(text, what, convert=str):
    items = [x.strip() for x in text.split(",")]
    if not all(items):
        raise ValueError(f"{what}: expected a comma-separated list, got '{text}'")
    try:
        return [convert(x) for x in items]
    except ValueError:
        raise ValueError(f"{what}: expected numbers, got '{text}'") from None


def _work_precision(a):
    import math

    import mbdae
    from mbdae.work_precision import report
    try:
        scene = mbdae.load(a.scene)
    except mbdae.SceneError as e:
        print(e, file=sys.stderr)
        return 2
    try:
        forms = _list(a.formulations, "--formulations") if a.formulations else None
        unknown = [f for f in forms or [] if f not in mbdae.formulations()]
        if unknown:
            raise ValueError(f"--formulations: unknown {', '.join(unknown)} (expected {', '.join(mbdae.formulations())})")
        tols = _list(a.tols, "--tols", float) if a.tols else None
        if tols and not all(1e-14 <= t <= 0.5 for t in tols):
            raise ValueError(f"--tols: every rtol must be in [1e-14, 0.5], got '{a.tols}'")
        columns = _list(a.columns, "--columns") if a.columns else None
        if a.atol_ratio is not None and not (a.atol_ratio > 0 and math.isfinite(a.atol_ratio)):
            raise ValueError(f"--atol-ratio: must be a positive number, got {a.atol_ratio}")
        if a.workers is not None and a.workers < 1:
            raise ValueError(f"--workers: must be at least 1, got {a.workers}")
        if columns:
            known = mbdae._core.check_error_sensors(scene._core, columns)
            if known:
                raise ValueError("; ".join(k.replace("error_sensors", "--columns") for k in known))
        table, curves, notes = report(scene, a.out, forms, tols, columns, reference_csv=a.reference,
                                         estimate=a.estimate, atol_ratio=a.atol_ratio, workers=a.workers,
                                         progress=not a.no_progress)
    except (ValueError, FileNotFoundError, KeyError) as e:
        print(f"mbdae work-precision: {e}", file=sys.stderr)
        return 1
    for n in notes:
        print(n)
    print(f"{'formulation':12s} {'column':12s} {'runs':>4s} {'slope':>6s} {'min error':>10s}  floor from rtol")
    for c in curves:
        floor = "none (keeps falling)" if c["floor_from_rtol"] is None else f"{c['floor_from_rtol']:g}"
        print(f"{c['formulation']:12s} {c['column']:12s} {c['runs']:4d} {c['slope']:6.2f} {c['min_error']:10.3g}  {floor}")
    print(f"table {a.out}/work_precision.csv, figures {a.out}/work_precision_*.png")
    return 0 if (table["status"] == "ok").all() else 3


def main(argv=None):
    ap = _Parser(prog="python3 -m mbdae", description="mbdae parameter sweeps (threads, or Dask)")
    sub = ap.add_subparsers(dest="command", required=True, parser_class=_Parser)
    wpp = sub.add_parser("work-precision", help="error against CPU time and rtol, every formulation")
    wpp.add_argument("scene")
    wpp.add_argument("--out", default="work_precision")
    wpp.add_argument("--formulations", help="comma-separated (default: every formulation)")
    wpp.add_argument("--tols", help="comma-separated rtols (default 1e-2,1e-3,...,1e-10)")
    wpp.add_argument("--columns", help="comma-separated output sensors (default: all)")
    wpp.add_argument("--reference", help="a CSV with t and the columns (default: a tight index2-ggl run)")
    wpp.add_argument("--estimate", action="store_true", help="also each run's --error-estimate (est_COLUMN)")
    wpp.add_argument("--atol-ratio", type=float, help="atol = R rtol (default: the scene's rule)")
    wpp.add_argument("--workers", type=int, help="Dask worker processes (default: runs one after the other)")
    wpp.add_argument("--no-progress", action="store_true")
    sw = sub.add_parser("sweep", help="run a scene over a grid of parameters")
    sw.add_argument("scene")
    sw.add_argument("--param", action="append", default=[], metavar="PATH=A:B:N|V1,V2,...")
    sw.add_argument("--set", action="append", default=[], metavar="PATH=VALUE")
    sw.add_argument("--metric", action="append", default=[], metavar="NAME=KIND:COLUMN[:X]")
    sw.add_argument("--out", required=True)
    sw.add_argument("--scheduler", help="a Dask scheduler's address (default: threads of this process)")
    sw.add_argument("--processes", action="store_true", help="a local Dask cluster of worker processes")
    sw.add_argument("--workers", type=_workers, help="local threads or processes (default: one per core)")
    sw.add_argument("--extend", action="store_true", help="add these runs to a folder holding another sweep")
    sw.add_argument("--worker-timeout", type=float, default=60.0,
                    help="seconds without any Dask worker before the unfinished runs are recorded lost")
    for opt in ("rtol", "atol", "output-step"):
        sw.add_argument(f"--{opt}", type=float)
    sw.add_argument("--formulation")
    sw.add_argument("--no-progress", action="store_true")
    pa = sub.add_parser("params", help="list a scene's parameter paths with values and units")
    pa.add_argument("scene")
    a = ap.parse_args(argv)
    if a.command == "work-precision":
        return _work_precision(a)
    if a.command == "params":
        return _params_command(a)
    if a.scheduler and (a.processes or a.workers):
        ap.error("--workers and --processes are for local runs; a scheduler's workers are started with it")

    import mbdae
    try:
        scene = mbdae.load(a.scene)
        if a.set:
            scene = scene.with_params([_pair(s, "--set") for s in a.set])
    except mbdae.SceneError as e:
        print(e, file=sys.stderr)
        return 2
    except ValueError as e:
        print(f"mbdae sweep: {e}", file=sys.stderr)
        return 1
    try:
        grid = {k: parse_values(v) for k, v in (_pair(p, "--param") for p in a.param)}
        metrics = {k: mbdae.metrics.from_spec(v) for k, v in (_pair(m, "--metric") for m in a.metric)}
    except ValueError as e:
        print(f"mbdae sweep: {e}", file=sys.stderr)
        return 1
    options = {k: v for k, v in (("rtol", a.rtol), ("atol", a.atol), ("output_step", a.output_step),
                                 ("formulation", a.formulation)) if v is not None}
    client = a.scheduler or ("processes" if a.processes else None)
    try:
        table = mbdae.sweep(scene, grid or [{}], a.out, client=client, metrics=metrics, options=options,
                            workers=a.workers, progress=not a.no_progress, extend=a.extend,
                            worker_timeout=a.worker_timeout)
    except mbdae.SceneError as e:
        print(e, file=sys.stderr)
        return 2
    except OSError as e:  # SweepOutputError: the folder in use or not writable
        print(f"mbdae sweep: {e.strerror or e}", file=sys.stderr)
        return 4
    except ValueError as e:
        print(f"mbdae sweep: {e}", file=sys.stderr)
        return 1
    counts = table["status"].value_counts().to_dict()
    print(f"{len(table)} runs ({table.attrs['skipped']} done before): "
          + ", ".join(f"{n} {s}" for s, n in counts.items()) + f"; table {a.out}/runs.csv")
    return 0 if counts.get("ok", 0) == len(table) else 3


if __name__ == "__main__":
    sys.exit(main())
