"""mbdae from Python: scenes, runs and results in memory, and parameter sweeps on Dask.

    import mbdae
    scene = mbdae.load("cases/five_point_suspension/dynamics_step.yaml")
    scene.set("forces.tyre.stiffness", 3.0e5)
    r = scene.run(rtol=1e-8)
    r.table          # pandas DataFrame: t, then the output sensors
    r.columns["wheel_z"], r.summary["status"]

    table = mbdae.sweep(scene, {"forces.suspension.damping": [700, 1400, 2800]}, out="build/sweep",
                        metrics={"travel": mbdae.metrics.peak_deviation("wheel_z")})
    scene.parameters()   # every parameter path with its value and unit

See docs/python.md."""
from . import metrics
from ._core import __version__, formulations
from .errors import SceneError, SolveError
from .result import Result
from .scene import Scene, load
from .sweep import SweepOutputError, read_run, read_sweep, runs_dataset, sweep
from .work_precision import work_precision

__all__ = ["Scene", "Result", "SceneError", "SolveError", "SweepOutputError", "load", "sweep", "read_run",
           "read_sweep", "runs_dataset", "work_precision", "formulations", "metrics", "__version__"]
