"""The shell form of mbdae.sweep:

    python3 -m mbdae sweep SCENE --param forces.suspension.damping=700:2800:8 \\
        --param forces.tyre.stiffness=1e5,2e5,4e5 --out DIR [--workers N] [--processes]
        [--scheduler tcp://HOST:8786] [--extend]
    python3 -m mbdae params SCENE    (the parameter paths, as `mbdae params`)

--param PATH=A:B:N is N values evenly spaced from A to B, PATH=V1,V2,... a list, PATH=V one value;
several --param make a grid. --set PATH=VALUE overrides every run; --metric NAME=KIND:COLUMN[:X]
adds a table column (mbdae.metrics.from_spec). Runs go to threads of this process (--workers N,
default one per core), to a local cluster of processes (--processes) or to a Dask scheduler.
Exit codes: 0 every run ok, 1 bad command line (option, metric), 2 bad scene or parameter path,
3 some run not ok, 4 the folder cannot be written or is in use by another sweep or run."""
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


def main(argv=None):
    ap = _Parser(prog="python3 -m mbdae", description="mbdae parameter sweeps (threads, or Dask)")
    sub = ap.add_subparsers(dest="command", required=True, parser_class=_Parser)
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
