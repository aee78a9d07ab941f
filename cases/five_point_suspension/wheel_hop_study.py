#!/usr/bin/env python3
"""Wheel hop on the vibrating poster (Dynamics II, dynamics_poster.yaml) against the suspension's
damping and the tyre's stiffness: a grid of runs on Dask through mbdae.sweep, one figure.

    PYTHONPATH=build/python /usr/bin/python3 cases/five_point_suspension/wheel_hop_study.py \
        [--out build/wheel_hop] [--workers N | --scheduler tcp://HOST:8786] [--t-end 20] [--rtol R] [--docs]

Per run: the peak wheel-centre travel max |wheel_z - wheel_z(0)| (the run starts at rest in the
static equilibrium), the time without tyre contact (tyre force 0, summed over the 1 ms samples),
the first contact loss and the RMS of the tyre force about its static value. The default grid is
8 dampings (700 to 2800 N s/m) x 5 tyre stiffnesses (1e5 to 4e5 N/m) = 40 runs of the full 20 s
sweep (about 1.5 s CPU each). Table: OUT/runs.csv; figure: OUT/wheel_hop.png (and
docs/figures/wheel_hop.png with --docs). A second run into the same OUT reuses finished runs."""
import argparse
from pathlib import Path

import numpy as np
import yaml

import mbdae
from mbdae import metrics

HERE = Path(__file__).resolve().parent


def poster_scene(t_end):
    """dynamics_poster.yaml with the tyre force among the outputs (and t_end if given)."""
    path = HERE / "dynamics_poster.yaml"
    d = yaml.safe_load(path.read_text())
    d["output"] = list(dict.fromkeys(d["output"] + ["tyre_force"]))
    scene = mbdae.Scene.from_dict(d, path=str(path))
    return scene.with_params({"analysis.dynamics.t_end": t_end}) if t_end else scene


def tyre_force_rms_about_static(r):
    f = r["tyre_force"]
    return float(np.sqrt(np.mean((f - f[0]) ** 2)))


METRICS = {
    "peak_travel_m": metrics.peak_deviation("wheel_z"),
    "airborne_s": metrics.time_at_or_below("tyre_force", 0.0),
    "first_contact_loss_s": metrics.first_time_at_or_below("tyre_force", 0.0),
    "tyre_force_rms_N": tyre_force_rms_about_static,
}


def plot(table, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    ok = table[table["status"] == "ok"]
    damping = np.sort(ok["forces.suspension.damping"].unique())
    stiffness = np.sort(ok["forces.tyre.stiffness"].unique())
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), constrained_layout=True)
    for ax, col, label, scale in ((axes[0], "peak_travel_m", "peak wheel-centre travel [mm]", 1e3),
                                  (axes[1], "airborne_s", "time without tyre contact [s]", 1.0)):
        grid = ok.pivot(index="forces.tyre.stiffness", columns="forces.suspension.damping", values=col)
        grid = grid.reindex(index=stiffness, columns=damping) * scale
        mesh = ax.pcolormesh(damping, stiffness / 1e3, grid.to_numpy(), shading="nearest", cmap="viridis")
        fig.colorbar(mesh, ax=ax, label=label)
        for (i, k), v in np.ndenumerate(grid.to_numpy()):
            ax.text(damping[k], stiffness[i] / 1e3, f"{v:.3g}", ha="center", va="center", fontsize=7, color="w")
        ax.set_xlabel("suspension damping [N s/m]")
        ax.set_ylabel("tyre stiffness [kN/m]")
        ax.set_title(label)
    fig.suptitle("Wheel hop on the poster sweep (1 to 19 Hz, 5 mm): five-point suspension")
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default="build/wheel_hop")
    ap.add_argument("--scheduler", help="a Dask scheduler's address (default: threads of this process)")
    ap.add_argument("--workers", type=int, help="local threads (default: one per core)")
    ap.add_argument("--t-end", type=float, help="shorter runs (the poster's first contact loss is after 13 s)")
    ap.add_argument("--damping", default="700:2800:8", help="A:B:N [N s/m]")
    ap.add_argument("--stiffness", default="1e5:4e5:5", help="A:B:N tyre stiffness [N/m]")
    ap.add_argument("--rtol", type=float, help="override the scene's rtol (1e-7)")
    ap.add_argument("--atol", type=float, help="override the scene's atol (1e-13)")
    ap.add_argument("--docs", action="store_true", help="also write docs/figures/wheel_hop.png")
    a = ap.parse_args()
    span = lambda s: [float(v) for v in np.linspace(*map(float, s.split(":")[:2]), int(s.split(":")[2]))]  # noqa: E731
    grid = {"forces.suspension.damping": span(a.damping), "forces.tyre.stiffness": span(a.stiffness)}
    options = {k: v for k, v in (("rtol", a.rtol), ("atol", a.atol)) if v is not None}
    table = mbdae.sweep(poster_scene(a.t_end), grid, out=a.out, client=a.scheduler, workers=a.workers,
                        metrics=METRICS, options=options)
    out = Path(a.out)
    plot(table, out / "wheel_hop.png")
    if a.docs:
        plot(table, HERE.parents[1] / "docs" / "figures" / "wheel_hop.png")
    cols = ["forces.suspension.damping", "forces.tyre.stiffness", "status", *METRICS, "solver_cpu_s"]
    print(table[cols].to_string(index=False))
    print(f"{(table['status'] == 'ok').sum()}/{len(table)} ok; table {out / 'runs.csv'}, figure {out / 'wheel_hop.png'}")


if __name__ == "__main__":
    main()
