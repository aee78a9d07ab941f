"""The shell form of mbdae.sweep:

    python3 -m mbdae sweep SCENE --param forces.suspension.damping=700:2800:8 \\
        --param forces.tyre.stiffness=1e5,2e5,4e5 --out DIR [--scheduler tcp://HOST:8786] [--workers N]

--param PATH=A:B:N is N values evenly spaced from A to B, PATH=V1,V2,... a list, PATH=V one value;
several --param make a grid. --set PATH=VALUE overrides every run; --metric NAME=KIND:COLUMN[:X]
adds a table column (mbdae.metrics.from_spec)."""
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


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python3 -m mbdae", description="mbdae parameter sweeps on Dask")
    sub = ap.add_subparsers(dest="command", required=True)
    sw = sub.add_parser("sweep", help="run a scene over a grid of parameters")
    sw.add_argument("scene")
    sw.add_argument("--param", action="append", default=[], metavar="PATH=A:B:N|V1,V2,...")
    sw.add_argument("--set", action="append", default=[], metavar="PATH=VALUE")
    sw.add_argument("--metric", action="append", default=[], metavar="NAME=KIND:COLUMN[:X]")
    sw.add_argument("--out", required=True)
    sw.add_argument("--scheduler", help="a Dask scheduler's address (default: a local cluster)")
    sw.add_argument("--workers", type=int, help="local worker processes (default: one per core)")
    for opt in ("rtol", "atol", "output-step"):
        sw.add_argument(f"--{opt}", type=float)
    sw.add_argument("--formulation")
    sw.add_argument("--no-progress", action="store_true")
    a = ap.parse_args(argv)

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
    table = mbdae.sweep(scene, grid or [{}], a.out, client=a.scheduler, metrics=metrics, options=options,
                        workers=a.workers, progress=not a.no_progress)
    counts = table["status"].value_counts().to_dict()
    print(f"{len(table)} runs ({table.attrs['skipped']} done before): "
          + ", ".join(f"{n} {s}" for s, n in counts.items()) + f"; table {a.out}/runs.csv")
    return 0 if counts.get("ok", 0) == len(table) else 3


if __name__ == "__main__":
    sys.exit(main())
