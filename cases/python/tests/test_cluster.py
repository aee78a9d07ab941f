"""A sweep through a separate Dask scheduler and two workers, started here as `dask scheduler`
and `dask worker` processes on 127.0.0.1; and a sweep whose workers all die."""
import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

import mbdae
from conftest import STEP


def start_cluster(tmp_path, nanny=True):
    """(address, processes) of a scheduler and two one-thread workers on 127.0.0.1."""
    file = tmp_path / "scheduler.json"
    procs = []
    try:
        procs.append(subprocess.Popen(["dask", "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                                       "--scheduler-file", str(file)], stdout=subprocess.DEVNULL,
                                      stderr=subprocess.DEVNULL))
        deadline = time.time() + 60
        while not file.exists() and time.time() < deadline:
            time.sleep(0.1)
        address = json.loads(file.read_text())["address"]
        assert address.startswith("tcp://127.0.0.1:")
        for _ in range(2):
            procs.append(subprocess.Popen(["dask", "worker", address, "--host", "127.0.0.1", "--nworkers", "1",
                                           "--nthreads", "1", "--no-dashboard", "--local-directory", str(tmp_path),
                                           *([] if nanny else ["--no-nanny"])],
                                          stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                          env=dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))))
        return address, procs
    except BaseException:
        stop(procs)
        raise


def stop(procs):
    for p in reversed(procs):
        p.terminate()
    for p in procs:
        try:
            p.wait(timeout=20)
        except subprocess.TimeoutExpired:
            p.kill()


@pytest.fixture
def scheduler(tmp_path):
    address, procs = start_cluster(tmp_path)
    try:
        yield address
    finally:
        stop(procs)


def test_sweep_through_a_scheduler_address(scheduler, tmp_path):
    from distributed import Client
    with Client(scheduler) as c:
        c.wait_for_workers(2, timeout=60)
        assert len(c.scheduler_info()["workers"]) == 2
    params = {"rtol": [1e-6, 1e-7, 1e-8, 1e-9], "formulation": ["index3", "index1"]}
    table = mbdae.sweep(mbdae.load(STEP), params, out=tmp_path / "out", client=scheduler,
                        metrics={"travel": mbdae.metrics.peak_deviation("wheel_z")})
    assert list(table["status"]) == ["ok"] * 8
    for i in range(8):
        alone = mbdae.load(STEP).run(rtol=table["rtol"][i], formulation=table["formulation"][i])
        samples, _, _ = mbdae.read_run(tmp_path / "out", i)
        assert np.array_equal(samples["wheel_z"].to_numpy(), alone["wheel_z"])
        assert table["travel"][i] == np.max(np.abs(alone["wheel_z"] - alone["wheel_z"][0]))


def test_a_sweep_whose_workers_all_die_ends_in_bounded_time(tmp_path):
    """Both workers (no nanny to restart them) killed by PID while the sweep runs: the sweep
    notices within worker_timeout (plus its polling), records the unfinished runs `lost` with
    the reason, keeps the finished ones, and the next sweep runs the lost ones again."""
    from distributed import Client
    address, procs = start_cluster(tmp_path, nanny=False)
    try:
        with Client(address) as c:
            c.wait_for_workers(2, timeout=60)
            pids = list(c.run(os.getpid).values())

        def slow(r):
            time.sleep(0.5)
            return float(r["wheel_z"][-1])
        import threading
        killer = threading.Timer(4.0, lambda: [os.kill(pid, signal.SIGKILL) for pid in pids])
        killer.start()
        t0 = time.monotonic()
        params = [{"rtol": 10.0 ** -k} for k in np.linspace(6, 9, 40)]
        table = mbdae.sweep(mbdae.load(STEP), params, out=tmp_path / "out", client=address, metrics={"end": slow},
                            worker_timeout=5.0, progress=False)
        elapsed = time.monotonic() - t0
        killer.join()
    finally:
        stop(procs)
    lost = table[table["status"] == "lost"]
    assert len(lost) > 0 and (table["status"].isin(["ok", "lost"])).all(), table["status"].value_counts()
    # Lost for want of a worker, or, for a run that finished on a worker killed before its result
    # was fetched, for want of the result (without the limit that fetch waited forever).
    assert lost["message"].str.contains("no Dask worker for 5 s|result was not fetched within 5 s").all(), \
        lost["message"].tolist()
    assert elapsed < 60, elapsed  # killed at 4 s, noticed 5 s later (plus polling and closing)
    done = table[table["status"] == "ok"]
    for _, row in done.iterrows():
        samples, _, _ = mbdae.read_run(tmp_path / "out", row["run"])
        assert len(samples) == row["rows"] > 0
    again = mbdae.sweep(mbdae.load(STEP), params, out=tmp_path / "out", metrics={"end": slow}, progress=False)
    assert again.attrs["skipped"] == len(done) and (again["status"] == "ok").all()
