"""The package as users meet it: one version number, type stubs that match the extension, the
parameter list (Python and `mbdae params`, list indices in paths), output columns with units,
notebook views, and each run's CPU time measured on its own thread."""
import ast
import re
import subprocess
import threading
from pathlib import Path

import numpy as np
import pytest

import mbdae
from conftest import CLI, ROOT, STEP
from mbdae import _core


def test_one_version_number():
    cmake = re.search(r"project\(mbdae VERSION ([0-9.]+)", (ROOT / "CMakeLists.txt").read_text()).group(1)
    assert mbdae.__version__ == cmake
    out = subprocess.run([str(CLI), "--version"], capture_output=True, text=True)
    assert out.returncode == 0 and out.stdout.strip() == f"mbdae {cmake}"


def test_stubs_name_every_public_binding():
    stub = Path(_core.__file__).with_name("_core.pyi")
    if not stub.exists():  # the build tree copies it next to the module; so do pip and cmake --install
        stub = ROOT / "cases" / "python" / "mbdae" / "_core.pyi"
    tree = ast.parse(stub.read_text())
    stubbed = {n.name for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
    stubbed |= {n.target.id for n in tree.body if isinstance(n, ast.AnnAssign)}
    public = {n for n in dir(_core) if not n.startswith("_")} | {"__version__"}
    assert public == stubbed, (public - stubbed, stubbed - public)
    for cls in ("Scene", "Result", "RunOptions"):
        node = next(n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == cls)
        members = {m.name for m in node.body if isinstance(m, ast.FunctionDef)}
        members |= {m.target.id for m in node.body if isinstance(m, ast.AnnAssign)}
        real = {n for n in dir(getattr(_core, cls)) if not n.startswith("_")}
        assert real <= members, (cls, real - members)


def test_parameters_list_paths_values_units_from_the_resolver():
    scene = mbdae.load(STEP)
    params = {p["path"]: p for p in scene.parameters()}
    assert params["forces.suspension.damping"]["unit"] == "N s/m"
    assert params["forces.tyre.stiffness"]["value"] == "2.0e5" and params["forces.tyre.stiffness"]["unit"] == "N/m"
    assert params["bodies.chassis.mass"]["unit"] == "kg" and float(params["bodies.chassis.mass"]["value"]) == 409.91
    assert params["bodies.chassis.points.bp1"]["value"] == "[-0.064, 0.413, 0.327]"
    assert params["bodies.chassis.points.bp1.2"] == {**params["bodies.chassis.points.bp1.2"], "value": "0.327",
                                                     "unit": "m"}
    assert params["analysis.dynamics.t_end"]["unit"] == "s" and params["gravity.2"]["value"] == "-9.81"
    assert params["forces.tyre.stiffness"]["file"].endswith("dynamics_step.yaml")
    assert params["bodies.chassis.mass"]["file"].endswith("model.yaml") and params["bodies.chassis.mass"]["line"] == 11
    # Every listed path is accepted by set() with its own value, unchanged.
    base = scene.run()
    for path in ("forces.suspension.damping", "bodies.chassis.points.bp1.2", "gravity.2"):
        again = scene.with_params({path: params[path]["value"]}).run()
        assert np.array_equal(again["wheel_z"], base["wheel_z"]), path
    # Overrides show in the list.
    assert {p["path"]: p["value"] for p in scene.with_params({"bodies.chassis.points.bp1.2": 0.5}).parameters()}[
        "bodies.chassis.points.bp1"] == "[-0.064, 0.413, 0.5]"


def test_list_index_path_equals_setting_the_whole_list():
    scene = mbdae.load(STEP)
    by_index = scene.with_params({"bodies.carrier.points.cp5.2": 0.14}).run()
    whole = scene.with_params({"bodies.carrier.points.cp5": [-0.0025, 0.0323383831212649, 0.14]}).run()
    assert np.array_equal(by_index["wheel_z"], whole["wheel_z"])
    with pytest.raises(mbdae.SceneError, match="no item '3' in the list"):
        scene.with_params({"bodies.carrier.points.cp5.3": 1.0})


def test_cli_params_prints_the_same_list():
    p = subprocess.run([str(CLI), "params", str(STEP)], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    expected = [f"{q['path']} = {q['value']}" + (f" [{q['unit']}]" if q["unit"] else "")
                for q in mbdae.load(STEP).parameters()]
    assert p.stdout.splitlines() == expected
    bad = subprocess.run([str(CLI), "params", str(ROOT / "nothing.yaml")], capture_output=True, text=True)
    assert bad.returncode == 2 and "cannot read the file" in bad.stderr


def test_output_columns_and_notebook_views():
    scene = mbdae.load(STEP)
    assert scene.output_columns() == [("t", "s"), ("wheel_z", "m"), ("wheel_vz", "m/s"), ("wheel_az", "m/s^2")]
    r = scene.with_params({"analysis.dynamics.t_end": 0.3}).run()
    assert list(zip(r.names, r.units)) == scene.output_columns()
    html = r._repr_html_()
    assert "<b>mbdae.Result</b> ok" in html and "301 rows" in html and "wheel_vz [m/s]" in html
    assert f"{r.summary['steps'][-1]['statistics']['steps']} integration steps" in html
    assert "wheel_az [m/s^2]" in scene._repr_html_() and "dynamics" in scene._repr_html_()


def test_cpu_seconds_is_the_solving_threads_own():
    """Two runs at once in two threads while the main thread spins: each reports its own
    thread's CPU time, a share of the process's CPU over that time (which counts both runs and
    the spinning thread), not the process's. Compared with the process clock of the same
    interval, not with a run alone: on a loaded machine the runs' own clocks grow with cache
    sharing (1.8 times a run alone was seen under ctest -j2), their share does not."""
    import time
    scene = mbdae.load(STEP)
    alone = min(scene.run().cpu_seconds() for _ in range(2))
    results = [None, None]

    def work(k):
        results[k] = scene.run()
    threads = [threading.Thread(target=work, args=(k,)) for k in range(2)]
    process_before = time.process_time()
    for t in threads:
        t.start()
    x = 0
    while any(t.is_alive() for t in threads):  # the main thread burns CPU meanwhile
        x += 1
    for t in threads:
        t.join()
    process = time.process_time() - process_before
    own = [r.cpu_seconds() for r in results]
    # The process clock counts both runs and the spinning thread: a run's own clock is at most
    # a little over half of it (the two runs alike, the spinning thread besides), where the
    # process's would be all of it.
    for c in own:
        assert 0.5 * alone < c < 0.6 * process, (own, process, alone)
    assert sum(own) < 0.95 * process, (own, process)


def test_imported_from_the_install_under_test():
    """Under .ci/run's pip-install step (MBDAE_INSTALLED_IN: the virtual environment) the
    package comes from that environment, not from the build tree or the checkout."""
    import os
    where = os.environ.get("MBDAE_INSTALLED_IN")
    if not where:
        pytest.skip("testing the build tree (PYTHONPATH)")
    assert Path(mbdae.__file__).resolve().is_relative_to(Path(where).resolve()), mbdae.__file__
    assert Path(_core.__file__).with_name("_core.pyi").exists() and Path(mbdae.__file__).with_name("py.typed").exists()
