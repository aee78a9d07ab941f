"""Sweeps in threads (the default): checks before the first run, resume keyed by runs and
metrics, files verified on resume, units and index in the files, the folder's lock, the README
snippet as a script without a __main__ guard and from stdin, a full disk."""
import errno
import fcntl
import hashlib
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import mbdae
from conftest import ROOT, STEP
from mbdae import metrics as M
from mbdae.sweep import expand
from mbdae.sweep_files import read_h5, read_h5_sensitivities


def short_scene():
    """Dynamics I to 0.3 s: the drop at 0.2 s and the first bounce (about 30 ms CPU a run)."""
    return mbdae.load(STEP).with_params({"analysis.dynamics.t_end": 0.3})


GRID = {"forces.suspension.damping": [700.0, 1400.0, 2800.0]}


def no_runs_started(out):
    return not list((Path(out) / "runs").glob("*.json")) and not (Path(out) / "runs.csv").exists()


def test_misspelt_path_is_refused_with_a_suggestion_before_any_run(tmp_path):
    for bad, good in (("forces.suspension.dampng", "forces.suspension.damping"),
                      ("forces.suspenson.damping", "forces.suspension.damping"),
                      ("bodies.chasis.mass", "bodies.chassis.mass")):
        with pytest.raises(mbdae.SceneError) as e:
            mbdae.sweep(short_scene(), {bad: [1.0, 2.0]}, out=tmp_path / "a", progress=False)
        assert f"'{bad}'" in str(e.value) and f"did you mean '{good}'" in str(e.value), str(e.value)
        assert e.value.field == bad
        assert no_runs_started(tmp_path / "a")
    # A path to an optional field the file does not write is a parameter too.
    table = mbdae.sweep(short_scene(), {"analysis.dynamics.max_step": [0.01]}, out=tmp_path / "b", progress=False)
    assert list(table["status"]) == ["ok"]


def test_shell_misspelt_path_exits_2_before_any_run(tmp_path):
    p = subprocess.run([sys.executable, "-m", "mbdae", "sweep", str(STEP), "--param",
                        "forces.suspension.dampng=700,1400", "--out", str(tmp_path), "--no-progress"],
                       capture_output=True, text=True)
    assert p.returncode == 2 and "did you mean 'forces.suspension.damping'" in p.stderr, p.stderr
    assert no_runs_started(tmp_path)


def test_metric_on_a_missing_column_is_rejected_before_the_first_run(tmp_path):
    with pytest.raises(ValueError, match=r"no output column 'wheel_zz' \(did you mean 'wheel_z'"):
        mbdae.sweep(short_scene(), GRID, out=tmp_path, metrics={"travel": M.peak_deviation("wheel_zz")},
                    progress=False)
    assert no_runs_started(tmp_path)
    with pytest.raises(ValueError, match="options: unknown run option 'rtoll'"):
        mbdae.sweep(short_scene(), GRID, out=tmp_path, options={"rtoll": 1e-6}, progress=False)
    # A metric that fails at run time is not counted ok.
    table = mbdae.sweep(short_scene(), GRID, out=tmp_path, metrics={"bad": lambda r: r["nothing"]}, progress=False)
    assert list(table["status"]) == ["metric_failed"] * 3 and table["bad"].isna().all()
    assert "metric bad: KeyError" in table["message"][0]


def test_changed_metrics_on_resume_are_recomputed_from_the_stored_runs(tmp_path):
    scene = short_scene()
    first = mbdae.sweep(scene, GRID, out=tmp_path, metrics={"m": M.peak_deviation("wheel_z")}, progress=False)
    h5 = {f: f.stat().st_mtime_ns for f in (tmp_path / "runs").glob("*.h5")}
    assert len(h5) == 3
    scale = 2.0
    again = mbdae.sweep(scene, GRID, out=tmp_path, progress=False,
                        metrics={"m": M.peak("wheel_z"), "k": lambda r: scale * r["wheel_z"][-1]})
    assert again.attrs["skipped"] == 3  # not run again
    assert all(f.stat().st_mtime_ns == t for f, t in h5.items())
    for i, run in enumerate(expand(GRID)):
        alone = scene.with_params(run).run()
        assert again["m"][i] == np.max(np.abs(alone["wheel_z"])) != first["m"][i]
        assert again["k"][i] == 2.0 * alone["wheel_z"][-1]
    scale = 3.0  # the closure's value changed: recomputed again
    third = mbdae.sweep(scene, GRID, out=tmp_path, progress=False,
                        metrics={"m": M.peak("wheel_z"), "k": lambda r: scale * r["wheel_z"][-1]})
    assert np.allclose(third["k"], 1.5 * again["k"], rtol=1e-15) and third.attrs["skipped"] == 3
    assert list(pd.read_csv(tmp_path / "runs.csv")["k"]) == list(third["k"])


TYRE = "forces.tyre.stiffness"


def test_resumed_runs_keep_their_sensitivities_for_changed_metrics(tmp_path):
    """A reused run is rebuilt from its file with its sensitivities (stored under the key
    "sensitivities"), so a changed metric that reads them gets the run's values, not None."""
    scene, grid = short_scene(), {"forces.suspension.damping": [700.0, 2800.0]}
    peak = {"p": lambda r: r.sensitivities[("wheel_z", TYRE)].abs().max()}
    first = mbdae.sweep(scene, grid, out=tmp_path, options={"sensitivities": [TYRE]}, metrics=peak, progress=False)
    last = {"p": lambda r: r.sensitivities[("wheel_vz", TYRE)].iloc[-1]}
    again = mbdae.sweep(scene, grid, out=tmp_path, options={"sensitivities": [TYRE]}, metrics=last, progress=False)
    assert again.attrs["skipped"] == 2 and list(again["status"]) == ["ok", "ok"], again["message"].tolist()
    for i, run in enumerate(expand(grid)):
        alone = scene.with_params(run).run(sensitivities=[TYRE]).sensitivities
        assert first["p"][i] == alone[("wheel_z", TYRE)].abs().max()
        assert again["p"][i] == alone[("wheel_vz", TYRE)].iloc[-1]
        stored = read_h5_sensitivities(tmp_path / again["file"][i])
        assert np.array_equal(stored.to_numpy(), alone.to_numpy())
        assert stored.attrs["units"][f"d(wheel_z)/d({TYRE})"] == "m/(N/m)"


def test_a_stored_run_without_its_sensitivities_runs_again(tmp_path, monkeypatch, capsys):
    """A run file that lacks the sensitivities its run asked for (written before they were
    stored) is not handed to a changed metric without them: the run is computed again."""
    scene, grid = short_scene(), {"forces.suspension.damping": [1400.0]}
    monkeypatch.setattr(sys.modules["mbdae.sweep"], "_sensitivity_payload", lambda result: None)
    mbdae.sweep(scene, grid, out=tmp_path, options={"sensitivities": [TYRE]}, progress=False)
    monkeypatch.undo()
    assert read_h5_sensitivities(next((tmp_path / "runs").glob("*.h5"))) is None
    capsys.readouterr()
    metric = {"p": lambda r: r.sensitivities[("wheel_z", TYRE)].abs().max()}
    table = mbdae.sweep(scene, grid, out=tmp_path, options={"sensitivities": [TYRE]}, metrics=metric, progress=False)
    assert table.attrs["skipped"] == 0 and list(table["status"]) == ["ok"], table["message"].tolist()
    assert "run 0: its file holds no sensitivities for the changed metrics; it runs again" in capsys.readouterr().err
    assert read_h5_sensitivities(tmp_path / table["file"][0]) is not None


@pytest.mark.parametrize("params, options, error, words", [
    ({"sensitivities": [TYRE, "bodies.wheel.mas"]}, {}, ValueError,
     "params: run 1 (sensitivities='bodies.wheel.mas'): sensitivities 'bodies.wheel.mas': no such parameter"),
    ({"formulation": ["index2-ggl", "index3"]}, {"sensitivities": [TYRE]}, ValueError,
     "params: run 1 (sensitivities=['forces.tyre.stiffness'], formulation='index3'): sensitivities: not with "
     "formulation index3"),
    ([{"sensitivities": [TYRE], "formulation": "index3"}], {}, ValueError, "params: run 0 ("),
    ([{"rtol": 1e-6}, {"sensitivities": {TYRE}}], {}, TypeError,
     "params: run 1 (sensitivities={'forces.tyre.stiffness'}): sensitivities expects a parameter path"),
    (GRID, {"sensitivities": b"gravity.2"}, TypeError, "sensitivities expects a parameter path"),
    (GRID, {"sensitivities": [TYRE], "formulation": "index3"}, ValueError, "sensitivities: not with formulation"),
])
def test_sensitivities_of_every_run_are_checked_before_the_first_run(tmp_path, params, options, error, words):
    """The grid's own sensitivities, and the options' with a grid formulation, are checked as the
    options' are: before anything runs, naming the grid entry (they were `invalid` rows)."""
    with pytest.raises(error) as e:
        mbdae.sweep(short_scene(), params, out=tmp_path, options=options, progress=False)
    assert str(e.value).startswith(words), str(e.value)
    assert no_runs_started(tmp_path)


def test_grid_sensitivities_run_per_entry_and_a_bad_formulation_stays_an_invalid_row(tmp_path):
    grid = {"sensitivities": [TYRE, [TYRE, "forces.suspension.damping"]], "formulation": ["index1", "index7"]}
    table = mbdae.sweep(short_scene(), grid, out=tmp_path, progress=False,
                        metrics={"n": lambda r: len(r.sensitivities.columns)})
    assert list(table["status"]) == ["ok", "invalid", "ok", "invalid"], table["message"].tolist()
    assert "got 'index7'" in table["message"][1]
    assert table["n"][2] == 2 * table["n"][0] > 0


def test_units_and_t_index_in_the_sweep_files(tmp_path):
    scene = short_scene()
    table = mbdae.sweep(scene, GRID, out=tmp_path, metrics={"travel": M.peak_deviation("wheel_z"),
                                                            "airborne": M.time_at_or_below("wheel_z", 0.0)},
                        progress=False)
    units = table.attrs["units"]
    assert units["travel"] == "m" and units["airborne"] == "s" and units["cpu_s"] == "s"
    assert units["forces.suspension.damping"] == "N s/m"
    back = mbdae.read_sweep(tmp_path)
    assert back.attrs["units"] == units and list(back["travel"]) == list(table["travel"])
    samples, params, summary = mbdae.read_run(tmp_path, 1)
    alone = scene.with_params(params).run()
    assert samples.index.name == "t" and np.array_equal(samples.index.to_numpy(), alone["t"])
    assert samples.attrs["units"] == {"t": "s", "wheel_z": "m", "wheel_vz": "m/s", "wheel_az": "m/s^2"}
    ds = mbdae.runs_dataset(tmp_path)
    assert ds["wheel_z"].dims == ("run", "t") and ds["wheel_z"].attrs["units"] == "m"
    assert np.array_equal(ds["wheel_z"].sel(run=1).to_numpy(), alone["wheel_z"])
    assert list(ds["forces.suspension.damping"].to_numpy()) == GRID["forces.suspension.damping"]
    assert "<b>mbdae sweep</b>: 3 runs: 3 ok" in table._repr_html_() and "travel [m]" in table._repr_html_()


def test_one_sweep_per_folder_and_other_runs_only_with_extend(tmp_path):
    scene = short_scene()
    fd = os.open(tmp_path / ".mbdae.lock", os.O_RDWR | os.O_CREAT)
    fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)  # another sweep (or `mbdae run`) holds the folder
    with pytest.raises(mbdae.SweepOutputError, match="folder in use"):
        mbdae.sweep(scene, GRID, out=tmp_path, progress=False)
    os.close(fd)
    assert no_runs_started(tmp_path)
    mbdae.sweep(scene, GRID, out=tmp_path, progress=False)
    other = {"forces.suspension.damping": [700.0, 2100.0]}
    with pytest.raises(ValueError, match="holds another sweep .* extend=True"):
        mbdae.sweep(scene, other, out=tmp_path, progress=False)
    with pytest.raises(ValueError, match="parameters forces.suspension.damping"):
        mbdae.sweep(scene, {"forces.tyre.stiffness": [1e5]}, out=tmp_path, progress=False)
    table = mbdae.sweep(scene, other, out=tmp_path, progress=False, extend=True)
    assert list(table["forces.suspension.damping"]) == [700.0, 1400.0, 2800.0, 2100.0]
    assert table.attrs["skipped"] == 3 and (table["status"] == "ok").all()
    p = subprocess.run([sys.executable, "-m", "mbdae", "sweep", str(STEP), "--param",
                        "forces.suspension.damping=700,900", "--set", "analysis.dynamics.t_end=0.3", "--out",
                        str(tmp_path), "--no-progress"], capture_output=True, text=True)
    assert p.returncode == 1 and "--extend" in p.stderr, p.stderr


def test_resume_verifies_each_runs_files_and_reruns_broken_ones(tmp_path, capsys):
    scene = short_scene()
    first = mbdae.sweep(scene, GRID, out=tmp_path, metrics={"travel": M.peak_deviation("wheel_z")}, progress=False)
    runs = tmp_path / "runs"
    keys = list(first["key"])
    (runs / f"{keys[0]}.h5").unlink()                            # deleted samples
    text = (runs / f"{keys[1]}.json").read_text()
    (runs / f"{keys[1]}.json").write_text(text[: len(text) // 2])  # truncated row
    data = bytearray((runs / f"{keys[2]}.h5").read_bytes())
    data[len(data) // 2] ^= 0xFF                                   # a flipped byte
    (runs / f"{keys[2]}.h5").write_bytes(bytes(data))
    again = mbdae.sweep(scene, GRID, out=tmp_path, metrics={"travel": M.peak_deviation("wheel_z")}, progress=False)
    assert again.attrs["skipped"] == 0 and again.attrs["rerun_broken"] == 3 and (again["status"] == "ok").all()
    err = capsys.readouterr().err
    assert f"run 0: runs/{keys[0]}.h5 is missing; it runs again" in err
    assert "run 1: its row is truncated or not JSON" in err and "run 2: " in err and "SHA-256" in err
    assert list(again["travel"]) == list(first["travel"])
    for i in range(3):
        samples, _, _ = mbdae.read_run(tmp_path, i)
        assert np.array_equal(samples["wheel_z"].to_numpy(), scene.with_params(
            {"forces.suspension.damping": GRID["forces.suspension.damping"][i]}).run()["wheel_z"])


@pytest.mark.parametrize("workers", [0, -1, 1.5, True, "2"])
def test_workers_is_range_checked(tmp_path, workers):
    with pytest.raises(ValueError, match="workers expects a whole number >= 1"):
        mbdae.sweep(short_scene(), GRID, out=tmp_path, workers=workers, progress=False)
    assert no_runs_started(tmp_path)


def test_workers_has_an_upper_bound(tmp_path):
    with pytest.raises(ValueError, match="more than 1024 local threads"):
        mbdae.sweep(short_scene(), GRID, out=tmp_path, workers=100000, progress=False)
    with pytest.raises(ValueError, match=r"local processes \(4 per core\)"):
        mbdae.sweep(short_scene(), GRID, out=tmp_path, workers=100000, client="processes", progress=False)
    assert no_runs_started(tmp_path)


@pytest.mark.parametrize("workers", ["0", "-1"])
def test_shell_workers_is_range_checked(tmp_path, workers):
    p = subprocess.run([sys.executable, "-m", "mbdae", "sweep", str(STEP), "--out", str(tmp_path), "--workers",
                        workers], capture_output=True, text=True, timeout=60)
    assert p.returncode == 1 and "--workers: expects a whole number >= 1" in p.stderr, p.stderr


def readme_sweep_snippet(out):
    """The README's Python block that calls mbdae.sweep, writing into `out`."""
    blocks = re.findall(r"```python\n(.*?)```", (ROOT / "README.md").read_text(), re.S)
    code = next(b for b in blocks if "mbdae.sweep(" in b)
    assert 'out="build/sweep"' in code
    return code.replace('out="build/sweep"', f"out={str(out)!r}")


@pytest.mark.parametrize("how", ["script", "stdin"])
def test_readme_sweep_snippet_runs_as_a_script_and_from_stdin(tmp_path, how):
    code = readme_sweep_snippet(tmp_path / "sweep")
    assert "__main__" not in code
    if how == "script":
        (tmp_path / "snippet.py").write_text(code)
        p = subprocess.run([sys.executable, str(tmp_path / "snippet.py")], cwd=ROOT, capture_output=True, text=True,
                           timeout=300)
    else:
        p = subprocess.run([sys.executable, "-"], input=code, cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    table = mbdae.read_sweep(tmp_path / "sweep")
    scene = mbdae.load(STEP)
    assert list(table["status"]) == ["ok"] * len(table) and len(table) == 3
    for i, row in table.iterrows():
        alone = scene.with_params({"forces.suspension.damping": row["forces.suspension.damping"]}).run()
        assert row["travel"] == np.max(np.abs(alone["wheel_z"] - alone["wheel_z"][0]))
    assert not list((tmp_path / "sweep").rglob("*.tmp"))


def _tiny_filesystem(path):
    """A 1 MB tmpfs at `path` (root only), or None."""
    path.mkdir()
    if os.geteuid() != 0:
        return None
    p = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=1m", "tmpfs", str(path)], capture_output=True)
    return path if p.returncode == 0 else None


def test_full_disk_is_a_clear_error_and_keeps_the_runs_done(tmp_path, monkeypatch):
    scene = short_scene()  # each run file is about 30 kB: 1 MB holds some runs, not 60
    grid = {"forces.suspension.damping": list(np.linspace(700.0, 2800.0, 60))}
    disk = _tiny_filesystem(tmp_path / "disk")
    if disk is None:  # not root: an injected write error after 10 files
        import mbdae.sweep_files as files
        real, count = files.write_bytes, {"n": 0}

        def failing(path, data):
            count["n"] += 1
            if count["n"] > 10:
                raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(path))
            real(path, data)
        monkeypatch.setattr(files, "write_bytes", failing)
    try:
        p = subprocess.run([sys.executable, "-m", "mbdae", "sweep", str(STEP), "--param",
                            "forces.suspension.damping=700:2800:60", "--set", "analysis.dynamics.t_end=0.3",
                            "--out", str(tmp_path / "disk" / "out"), "--no-progress", "--workers", "2"],
                           capture_output=True, text=True, timeout=300) if disk else None
        if disk:
            assert p.returncode == 4, (p.returncode, p.stderr)
            assert "No space left on device" in p.stderr and "finished runs are kept whole" in p.stderr, p.stderr
        else:
            with pytest.raises(mbdae.SweepOutputError, match="No space left on device"):
                mbdae.sweep(scene, grid, out=tmp_path / "disk" / "out", progress=False)
        out = tmp_path / "disk" / "out"
        rows = sorted((out / "runs").glob("*.json"))
        assert rows and not list((out / "runs").glob("*.tmp"))
        for j in rows:  # every run left is whole: its row parses and its file matches the row
            row = json.loads(j.read_text())
            assert row["status"] == "ok"
            assert hashlib.sha256((out / row["file"]).read_bytes()).hexdigest() == row["file_sha256"]
            samples, _, _ = read_h5(out / row["file"])
            assert len(samples) == row["rows"] == 301
    finally:
        if disk:
            subprocess.run(["umount", str(disk)], check=False)


def test_an_out_that_names_no_folder_is_a_type_error_naming_out(tmp_path):
    for bad in (None, 3, ""):
        with pytest.raises(TypeError) as e:
            mbdae.sweep(short_scene(), GRID, out=bad, progress=False)
        assert str(e.value).startswith("out expects the sweep's folder"), str(e.value)


def test_failed_runs_in_a_sweep_print_no_bare_line(tmp_path, capfd):
    """A failing run is a row with its message; nothing on stderr names no run."""
    table = mbdae.sweep(short_scene(), {"forces.suspension.damping": [1400.0, 1e300]}, out=tmp_path / "s",
                        client="threads", progress=False)
    assert list(table["status"])[0] == "ok" and list(table["status"])[1] != "ok", list(table["status"])
    assert table["message"].iloc[1], "the failed run's row keeps its message"
    err = capfd.readouterr().err
    assert "mbdae: " not in err, err
