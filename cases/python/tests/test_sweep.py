"""Sweeps on a LocalCluster of 2 worker processes (client="processes" or a Client): equal to
the runs one by one, failures recorded, resumed after a kill, a killed worker's task retried."""
import os
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import mbdae
from conftest import OVERRIDES, PAST_TRAVEL, STEP, needs_overrides
from mbdae.sweep import RUN_OPTIONS, expand


@pytest.fixture(scope="module")
def client():
    from distributed import Client, LocalCluster
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            Client(cluster) as c:
        yield c


def step_scene():
    """Dynamics I; shortened to t_end 0.8 s where overrides work (the drop and first hop)."""
    scene = mbdae.load(STEP)
    return scene.with_params({"analysis.dynamics.t_end": 0.8}) if OVERRIDES else scene


def grid_16():
    """16 runs: damping x tyre stiffness where overrides work, otherwise rtol x atol."""
    if OVERRIDES:
        return {"forces.suspension.damping": [700.0, 1400.0, 2100.0, 2800.0],
                "forces.tyre.stiffness": [1.0e5, 2.0e5, 3.0e5, 4.0e5]}
    return {"rtol": [1e-6, 1e-7, 1e-8, 1e-9], "atol": [1e-10, 1e-12, 1e-14, 1e-16]}


def split(run):
    opts = {k: v for k, v in run.items() if k in RUN_OPTIONS}
    return {k: v for k, v in run.items() if k not in opts}, opts


METRICS = {"travel": mbdae.metrics.peak_deviation("wheel_z"), "rms_az": mbdae.metrics.rms("wheel_az")}


def test_sweep_equals_the_runs_one_by_one(client, tmp_path):
    scene = step_scene()
    table = mbdae.sweep(scene, grid_16(), out=tmp_path, client=client, metrics=METRICS)
    assert len(table) == 16 and list(table["status"]) == ["ok"] * 16, table[["status", "message"]]
    assert table["worker"].nunique() == 2  # both worker processes ran some
    runs = expand(grid_16())
    for i, run in enumerate(runs):
        overrides, opts = split(run)
        alone = scene.with_params(overrides).run(**opts)
        samples, params, summary = mbdae.read_run(tmp_path, i)
        assert params == run and summary["status"] == "ok"
        assert samples.index.name == "t" and np.array_equal(samples.index.to_numpy(), alone["t"])
        assert samples.attrs["units"] == dict(zip(alone.names, alone.units))
        for c in alone.names[1:]:
            assert np.array_equal(samples[c].to_numpy(), alone[c]), (i, c)
        row = table.iloc[i]
        assert row["travel"] == np.max(np.abs(alone["wheel_z"] - alone["wheel_z"][0]))
        assert row["rms_az"] == np.sqrt(np.mean(alone["wheel_az"] ** 2))
        assert row["solver_cpu_s"] > 0 and row["cpu_s"] >= row["solver_cpu_s"] * 0.5
    assert (tmp_path / "runs.csv").exists()
    import pandas as pd
    assert pd.read_csv(tmp_path / "runs.csv", float_precision="round_trip")["travel"].tolist() == table["travel"].tolist()


def test_failed_and_invalid_runs_are_rows_and_the_rest_complete(client, tmp_path):
    params = [{"rtol": 1e-6}, {"rtol": -1.0}, {"formulation": "index7"}, {"rtol": 1e-7}]
    table = mbdae.sweep(mbdae.load(STEP), params, out=tmp_path / "a", client=client, metrics=METRICS)
    assert list(table["status"]) == ["ok", "invalid", "invalid", "ok"]
    assert "rtol" in table["message"][1] and "index7" in table["message"][2]
    assert table["file"][1] == "" and table["file"][0] == f"runs/{table['key'][0]}.h5"  # no samples: no file
    # A solve failure keeps its partial samples and message.
    failing = mbdae.sweep(mbdae.load(PAST_TRAVEL), [{"output_step": 0.01}, {"output_step": 0.002}],
                          out=tmp_path / "b", client=client)
    alone = mbdae.load(PAST_TRAVEL).run(output_step=0.01, raise_on_failure=False)
    assert list(failing["status"]) == ["integration_failed"] * 2 and failing["message"][0] == alone.message
    samples, _, _ = mbdae.read_run(tmp_path / "b", 0)
    assert np.array_equal(samples["wheel_z"].to_numpy(), alone["wheel_z"]) and len(samples) == alone.rows


@needs_overrides
def test_bad_value_is_an_invalid_row(client, tmp_path):
    params = [{"forces.tyre.stiffness": 2.0e5}, {"forces.tyre.stiffness": -1.0}]
    table = mbdae.sweep(step_scene(), params, out=tmp_path, client=client)
    assert list(table["status"]) == ["ok", "invalid"]
    assert "dynamics_step.yaml:" in table["message"][1] and "stiffness" in table["message"][1]


def _shell_sweep(out):
    cmd = [sys.executable, "-m", "mbdae", "sweep", str(STEP), "--out", str(out), "--workers", "1", "--no-progress"]
    if OVERRIDES:
        cmd += ["--param", "forces.suspension.damping=700:2800:6", "--param", "forces.tyre.stiffness=1e5:4e5:5",
                "--set", "analysis.dynamics.t_end=0.5"]
    else:
        cmd += ["--param", "rtol=1e-6:1e-5:6", "--param", "atol=1e-11,1e-12,1e-13,1e-14,1e-15"]
    return subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)


def test_sweep_killed_half_way_resumes_without_redoing_runs(tmp_path):
    runs = tmp_path / "runs"
    p = _shell_sweep(tmp_path)
    deadline = time.time() + 120
    while time.time() < deadline and p.poll() is None and len(list(runs.glob("*.json"))) < 6:
        time.sleep(0.02)
    os.killpg(p.pid, signal.SIGKILL)  # the sweep and its local worker process
    p.wait()
    # The finished runs' files: a run's .json is written last, so a .h5 without its .json (the
    # kill between the two) is an unfinished run's, rightly written again on resuming.
    rows = list(runs.glob("*.json"))
    finished = {f: f.stat().st_mtime_ns for j in rows for f in (j, j.with_suffix(".h5")) if f.exists()}
    n_done = len(rows)
    assert 6 <= n_done < 30, n_done
    p = _shell_sweep(tmp_path)
    stdout, stderr = p.communicate(timeout=300)
    assert p.returncode == 0, stderr
    assert f"30 runs ({n_done} done before): 30 ok" in stdout
    assert all(f.stat().st_mtime_ns == t for f, t in finished.items())  # not written again
    import pandas as pd
    table = pd.read_csv(tmp_path / "runs.csv")
    assert len(table) == 30 and (table["status"] == "ok").all() and table["run"].tolist() == list(range(30))


def test_a_worker_killed_during_the_sweep_does_not_lose_its_task(client, tmp_path):
    def slow_travel(r):  # keeps each task running for a while, so a worker dies in the middle of one
        time.sleep(0.7)
        return float(np.max(np.abs(r["wheel_z"] - r["wheel_z"][0])))

    killed = {}

    def kill_a_busy_worker():
        deadline = time.time() + 60
        while time.time() < deadline:
            busy = [w for w, tasks in client.processing().items() if tasks]
            if busy:
                time.sleep(0.3)  # inside the task now
                pid = client.run(os.getpid, workers=[busy[0]])[busy[0]]
                killed.update(pid=pid, tasks=list(client.processing()[busy[0]]))
                os.kill(pid, signal.SIGKILL)
                return
            time.sleep(0.05)
    killer = threading.Thread(target=kill_a_busy_worker)
    killer.start()
    params = [{"rtol": 10.0 ** -k} for k in (6, 7, 8, 9, 10, 11)]
    table = mbdae.sweep(mbdae.load(STEP), params, out=tmp_path, client=client, metrics={"travel": slow_travel})
    killer.join()
    assert killed.get("pid") and killed["tasks"], "no worker was killed"
    assert list(table["status"]) == ["ok"] * 6
    assert not any(w.endswith(f":{killed['pid']}") for w in table["worker"][table["run"].isin(
        [int(k.split("-")[2]) for k in killed["tasks"]])])  # the killed worker's task ran elsewhere
    for i, run in enumerate(params):
        alone = mbdae.load(STEP).run(**run)
        assert table["travel"][i] == np.max(np.abs(alone["wheel_z"] - alone["wheel_z"][0]))


def test_work_precision_table(client, tmp_path):
    scene = mbdae.load(STEP)
    # index2-ggl: index3's velocity error per unit step reaches its rounding floor (about 1e-9 m
    # here) from tau 1e-5 on, also at rtol 1e-11.
    reference = scene.run(formulation="index2-ggl", rtol=1e-11, atol=1e-15)
    table = mbdae.work_precision(scene, ["index3", "index1"], [1e-3, 1e-5], columns=["wheel_z"], reference=reference,
                                 out=tmp_path, client=client)
    assert list(table["formulation"]) == ["index3", "index3", "index1", "index1"]
    assert list(table["atol"]) == [1e-6 * tau for tau in (1e-3, 1e-5, 1e-3, 1e-5)] and (table["status"] == "ok").all()
    for i, row in table.iterrows():
        alone = scene.run(formulation=row["formulation"], rtol=row["rtol"], atol=row["atol"])
        assert row["err_wheel_z"] == np.max(np.abs(alone["wheel_z"] - reference["wheel_z"]))
        assert row["steps"] == alone.summary["steps"][-1]["statistics"]["steps"]
    for f in ("index3", "index1"):  # tighter tolerance, smaller error, more steps
        loose, tight = table[table["formulation"] == f].to_dict("records")
        assert tight["err_wheel_z"] < 0.1 * loose["err_wheel_z"] and tight["steps"] > loose["steps"]
