"""calibench.import_recording, advise, check, report, lrf_calibrate, run: each the command's own
work."""
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import calibench


def cli(exe, *args):
    return subprocess.run([exe, *map(str, args)], capture_output=True, text=True)


def files_of(folder: Path) -> dict:
    return {p.relative_to(folder).as_posix(): p.read_bytes()
            for p in sorted(folder.rglob("*")) if p.is_file()}


def test_a_recording_imported_from_python_equals_the_command_lines_folder(exe, tmp_path):
    recording = tmp_path / "capture.mcap"
    subprocess.run([os.environ["CALIBENCH_WRITE_SIM_RECORDING"], str(recording), "5"], check=True,
                   capture_output=True)
    by_cli, by_python = tmp_path / "cli", tmp_path / "python"
    printed = cli(exe, "import", recording, "--board", "a3", "--out", by_cli)
    assert printed.returncode == 0, printed.stderr
    phases = set()
    record = calibench.import_recording(recording, by_python, board="a3",
                                        progress=lambda phase, done, total, item:
                                        phases.add(phase))
    assert record["folder"] == str(by_python)
    assert len(record["pairs"]) == 5, record
    cli_files, py_files = files_of(by_cli), files_of(by_python)
    assert sorted(cli_files) == sorted(py_files)
    for name in cli_files:
        if name != "import.json":
            assert cli_files[name] == py_files[name], name
    # import.json: the same record but for what says how long it took.
    cli_record = json.loads(cli_files["import.json"])
    for key in set(cli_record) | set(record):
        if key not in ("folder",) and "second" not in key:
            assert cli_record.get(key) == record.get(key), key
    assert phases  # the progress callback was called

    # The folder calibrates from Python as from the command line.
    result = calibench.calibrate(by_python)
    assert sum(p.status == "accepted" for p in result.pairs) >= 4

    with pytest.raises(calibench.InputError) as error:
        calibench.import_recording(tmp_path / "absent.mcap", tmp_path / "x")
    assert "absent.mcap" in str(error.value)


def test_advise_returns_the_commands_json(exe, simulated):
    printed = cli(exe, "advise", "--dataset", simulated, "--json", "--goal-mm", "2")
    assert printed.returncode == 0, printed.stderr
    advice = calibench.advise(simulated, goal_mm=2.0)
    assert advice == json.loads(printed.stdout)
    assert isinstance(advice["done"], bool)


def test_report_writes_the_html_of_a_result(simulated, tmp_path):
    result = calibench.calibrate(simulated)
    page = calibench.report(tmp_path / "report.html", result, dataset=simulated, views=False,
                            no_cross_validation=True)
    html = page.read_text()
    assert html.startswith("<!DOCTYPE html>") or html.lstrip().lower().startswith("<!doctype")
    assert f"{result.cam_from_lidar[0, 3]:.4f}" in html or "cam_from_lidar" in html
    with pytest.raises(calibench.InputError) as error:
        calibench.report(tmp_path / "r.html", tmp_path / "no_result.json", dataset=simulated)
    assert "no_result.json" in str(error.value)


def test_lrf_calibrate_equals_the_command_line(exe, tmp_path):
    dataset = tmp_path / "lrf"
    assert cli(exe, "simulate", "--kind", "lrf", "--out", dataset).returncode == 0
    printed = cli(exe, "lrf-calibrate", "--dataset", dataset, "--out", tmp_path / "cli.json")
    assert printed.returncode == 0, printed.stderr
    result = calibench.lrf_calibrate(dataset, out=tmp_path / "py.json")
    assert (tmp_path / "py.json").read_bytes() == (tmp_path / "cli.json").read_bytes()
    truth = json.loads((dataset / "manifest.json").read_text())["ground_truth"]
    truth = np.array(truth.get("cam_from_lrf", truth), dtype=float).reshape(4, 4)
    error = np.linalg.inv(truth) @ result.cam_from_lidar
    assert np.linalg.norm(error[:3, 3]) < 0.02  # the paper's simulation: ~5 mm
    np.testing.assert_allclose(result.cam_from_lidar @ result.lidar_from_cam, np.eye(4),
                               atol=1e-12)
    # Its report, from the Result itself: the LRF method's page.
    page = calibench.report(tmp_path / "lrf.html", result, dataset=dataset)
    assert "Calibench 2D LRF calibration report" in page.read_text(encoding="utf-8")


def test_lrf_calibrate_with_a_workbench_session(exe, tmp_path):
    dataset = tmp_path / "lrf"
    assert cli(exe, "simulate", "--kind", "lrf", "--observations", "6", "--out",
               dataset).returncode == 0
    ids = [p["id"] for p in json.loads((dataset / "manifest.json").read_text())["pairs"]]
    # The LRF workbench's session as it writes one: pair 2 rejected, the closed-form method.
    session = {
        "format": "calibench.session.v1", "version": 1, "dataset": "manifest.json",
        "options": {"method": "weighted-ml", "huber_delta": 0.05, "estimate_range_offset": False,
                    "max_iterations": 50, "ransac_threshold_m": 0.02,
                    "lrf_method": "paper-linear"},
        "pairs": [{"id": i, "status": "rejected" if k == 2 else "pending",
                   "reason": "rejected by the user" if k == 2 else "", "brush": None,
                   "brush_from_seed": False} for k, i in enumerate(ids)],
        "view": {}, "result": None}
    session_file = dataset / "calibench.lrf-session.json"
    session_file.write_text(json.dumps(session))
    result = calibench.lrf_calibrate(session=session_file, out=tmp_path / "py.json")
    kept = ",".join(i for k, i in enumerate(ids) if k != 2)
    printed = cli(exe, "lrf-calibrate", "--dataset", dataset, "--method", "paper-linear",
                  "--pairs", kept, "--out", tmp_path / "cli.json")
    assert printed.returncode == 0, printed.stderr
    cli_result = calibench.load_result(tmp_path / "cli.json")
    np.testing.assert_array_equal(result.cam_from_lidar, cli_result.cam_from_lidar)
    with pytest.raises(calibench.UsageError) as error:
        calibench.lrf_calibrate(session=session_file, method="refined")
    assert "disagrees" in str(error.value)
    # calibrate reads either kind of session: the LRF job, the same transform.
    through_calibrate = calibench.calibrate(session=session_file, out=tmp_path / "calibrate.json")
    np.testing.assert_array_equal(through_calibrate.cam_from_lidar, cli_result.cam_from_lidar)
    with pytest.raises(calibench.UsageError) as error:
        calibench.calibrate(session=session_file, method="kim")
    assert "LiDAR-camera method's" in str(error.value)


def test_run_and_version(exe):
    code, out, err = calibench.run("--version")
    assert code == 0 and out.startswith(f"calibench {calibench.__version__}\n")
    assert "assets: /" in out
    assert "calibrate" in calibench.commands() and "import" in calibench.commands()
    code, out, err = calibench.run("calibrat")
    assert code == 1 and "did you mean 'calibrate'" in err


def test_the_examples_run(simulated, tmp_path):
    source = Path(os.environ["CALIBENCH_SOURCE_DIR"])
    env = {**os.environ, "MPLBACKEND": "Agg"}
    plot = tmp_path / "residuals.png"
    run = subprocess.run([sys.executable, str(source / "examples/calibrate_folder.py"),
                          str(simulated), "--plot", str(plot)], capture_output=True, text=True,
                         env=env)
    assert run.returncode == 0, run.stderr
    assert plot.stat().st_size > 10_000 and "sigma" in run.stdout
    folder = tmp_path / "fleet"
    folder.mkdir()
    (folder / "robot_a").symlink_to(simulated)
    run = subprocess.run([sys.executable, str(source / "examples/calibrate_every_capture.py"),
                          str(folder)], capture_output=True, text=True, env=env)
    assert run.returncode == 0, run.stderr
    assert "robot_a" in run.stdout


def test_the_man_page_and_completion_come_from_the_commands_help(exe):
    import gzip

    build = Path(os.environ["CALIBENCH_BINARY_DIR"])
    page = build / "man/calibench.1.gz"
    if not page.exists():
        pytest.skip("help2man is not installed: no man page (scripts/install_deps.sh installs it)")
    text = gzip.decompress(page.read_bytes()).decode()
    for command in calibench.commands():
        assert f'.SH "COMMAND {command.upper()}"' in text or f".SH COMMAND {command.upper()}" in text, command
    assert "\\-\\-huber\\-delta" in text and "\\-\\-list\\-presets" in text
    completion = (build / "completion/calibench").read_text()
    assert "complete -F _calibench calibench" in completion
    assert "a3 a4 charuco-a3 charuco-a4 paper" in completion
    calibrate_flags = next(line for line in completion.splitlines()
                           if line.strip().startswith("calibrate)"))
    for flag in ("--dataset", "--huber-delta", "--no-jackknife", "--session", "--report"):
        assert flag + " " in calibrate_flags or flag + '"' in calibrate_flags, flag
    # Completing in bash: `calibench cal<TAB>` and `calibench target --preset ch<TAB>`.
    script = (f"source {build / 'completion/calibench'}; "
              "COMP_WORDS=(calibench cal); COMP_CWORD=1; _calibench; echo ${COMPREPLY[@]}; "
              "COMP_WORDS=(calibench target --preset ch); COMP_CWORD=3; _calibench; "
              "echo ${COMPREPLY[@]}; "
              "COMP_WORDS=(calibench advise --goal); COMP_CWORD=2; _calibench; echo ${COMPREPLY[@]}")
    lines = subprocess.run(["bash", "-c", script], capture_output=True, text=True,
                           check=True).stdout.splitlines()
    assert lines == ["calibrate", "charuco-a3 charuco-a4", "--goal-deg --goal-mm"], lines


def test_the_installed_package_works_from_its_files_alone(tmp_path):
    """cmake --install: the module imports from <prefix>/lib/python3/dist-packages and finds the
    assets in <prefix>/share/calibench/assets (not the source tree's), from another folder."""
    build = Path(os.environ["CALIBENCH_BINARY_DIR"])
    prefix = tmp_path / "prefix"
    subprocess.run(["cmake", "--install", str(build), "--prefix", str(prefix)], check=True,
                   capture_output=True)
    site = prefix / "lib/python3/dist-packages"
    assert (site / "calibench/__init__.py").is_file()
    assert list((site / "calibench").glob("_calibench*.so"))
    assert (prefix / "share/man/man1/calibench.1.gz").is_file() or not (
        build / "man/calibench.1.gz").exists()
    assert (prefix / "share/bash-completion/completions/calibench").is_file()
    env = {k: v for k, v in os.environ.items()
           if k not in ("PYTHONPATH", "CALIBENCH_ASSETS")}
    env["PYTHONPATH"] = str(site)
    script = ("import calibench; code, out, err = calibench.run('--version'); print(out); "
              "print(calibench.__file__)")
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    printed = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                             env=env, cwd=elsewhere, check=True).stdout
    assert f"assets: {prefix / 'share/calibench/assets'}" in printed, printed
    assert str(site / "calibench/__init__.py") in printed


def test_check_judges_a_calibration_as_the_command_line_does(exe, acfr, tmp_path):
    result = calibench.calibrate(acfr, out=tmp_path / "result.json")
    printed = cli(exe, "check", "--dataset", acfr, "--result", tmp_path / "result.json", "--json")
    assert printed.returncode == 0, printed.stderr
    expected = json.loads(printed.stdout)
    verdict = calibench.check(acfr, result, write_result=tmp_path / "targetless.json")
    assert verdict["verdict"] == expected["verdict"] == "consistent", verdict["why"]
    assert verdict["frames_used"] == 40
    np.testing.assert_array_equal(verdict["cam_from_lidar"], np.array(expected["cam_from_lidar"]))
    # The estimate saved as a result, its provenance targetless, readable as any result.
    saved = calibench.load_result(tmp_path / "targetless.json")
    np.testing.assert_allclose(saved.cam_from_lidar, verdict["cam_from_lidar"], atol=1e-12)
    assert saved.document["provenance"]["kind"] == "targetless"
    # A calibration moved by 1 degree about the camera's y axis: miscalibrated, and corrected.
    moved = result.document.copy()
    turn = np.eye(4)
    c, s = np.cos(np.radians(1.0)), np.sin(np.radians(1.0))
    turn[0, 0], turn[0, 2], turn[2, 0], turn[2, 2] = c, s, -s, c
    moved_matrix = turn @ result.cam_from_lidar
    moved["cam_from_lidar"] = {"matrix": moved_matrix.tolist()}
    moved["lidar_from_cam"] = {"matrix": np.linalg.inv(moved_matrix).tolist()}
    (tmp_path / "moved.json").write_text(json.dumps(moved))
    off = calibench.check(acfr, tmp_path / "moved.json")
    assert off["verdict"] == "miscalibrated", off["why"]
    assert abs(off["change_r_deg"][1] + 1.0) < 0.5
    with pytest.raises(calibench.InputError):
        calibench.check(tmp_path / "nowhere", result)
