"""calibench.calibrate and its Result against the command line: same pipeline, same bytes."""
import json
import shutil
import subprocess
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import calibench


def cli(exe, *args):
    return subprocess.run([exe, *map(str, args)], capture_output=True, text=True)


def test_python_equals_the_command_line_bit_for_bit_on_the_real_vlp16_folder(exe, acfr, tmp_path):
    cli_file, py_file = tmp_path / "cli.json", tmp_path / "py.json"
    printed = cli(exe, "calibrate", "--dataset", acfr, "--out", cli_file)
    assert printed.returncode == 0, printed.stderr
    seen = []
    result = calibench.calibrate(acfr, out=py_file,
                                 progress=lambda phase, done, total, item:
                                 seen.append((phase, done, total, item)))
    assert py_file.read_bytes() == cli_file.read_bytes()
    assert result.summary.replace(str(py_file), str(cli_file)) == printed.stdout

    # The callback saw every pair once, counted 1..40 of 40.
    extracted = [s for s in seen if s[0] == "extracted"]
    assert sorted(item for _, _, _, item in extracted) == sorted(p.id for p in result.pairs)
    assert len(result.pairs) == 40
    assert sorted(done for _, done, _, _ in extracted) == list(range(1, 41))
    assert {total for _, _, total, _ in extracted} == {40}

    # The arrays say what the file says, and hold together.
    document = result.document
    assert result.cam_from_lidar.shape == (4, 4) and result.covariance.shape == (6, 6)
    np.testing.assert_array_equal(result.cam_from_lidar, document["cam_from_lidar"]["matrix"])
    np.testing.assert_allclose(result.cam_from_lidar @ result.lidar_from_cam, np.eye(4),
                               atol=1e-12)
    np.testing.assert_allclose(result.covariance, result.covariance.T, atol=0)
    assert np.all(np.linalg.eigvalsh(result.covariance) > 0)
    assert np.all(result.std_t_m > 0) and np.all(result.std_t_m < 0.01)  # mm-level, not metres
    assert np.all(result.std_r_deg > 0) and np.all(result.std_r_deg < 0.5)
    assert result.well_constrained
    used = [p for p in result.pairs if p.status == "accepted"]
    assert len(used) == 40  # all 40 boards found (README: none false)
    pose1 = next(p for p in result.pairs if p.id == "pose1")
    assert pose1.weight == 0.0 and pose1.residuals.shape == (4,)

    # save() writes the same bytes; load_result reads them back to the same arrays.
    assert result.save(tmp_path / "again.json").read_bytes() == cli_file.read_bytes()
    loaded = calibench.load_result(cli_file)
    np.testing.assert_array_equal(loaded.cam_from_lidar, result.cam_from_lidar)
    np.testing.assert_array_equal(loaded.covariance, result.covariance)
    assert [p.id for p in loaded.pairs] == [p.id for p in result.pairs]


def test_options_are_the_flags_and_change_what_they_should(simulated):
    base = calibench.calibrate(simulated)
    ids = [p.id for p in base.pairs]
    assert len(ids) == 12 and all(p.status == "accepted" for p in base.pairs)

    chosen = calibench.calibrate(simulated, pairs=ids[:6])
    assert sorted(p.id for p in chosen.pairs if p.status == "accepted") == sorted(ids[:6])
    assert not np.array_equal(chosen.cam_from_lidar, base.cam_from_lidar)

    kim = calibench.calibrate(simulated, method="kim")
    assert kim.document["solver"]["method"] == "kim"
    assert base.document["solver"]["method"] == "weighted-ml"
    assert not np.array_equal(kim.cam_from_lidar, base.cam_from_lidar)

    tight = calibench.calibrate(simulated, huber_delta=0.05, max_iterations=7)
    assert tight.document["solver"]["huber_delta"] == 0.05

    plain = calibench.calibrate(simulated, no_jackknife=True)
    assert base.document["solver"]["jackknife_pairs"] > 0
    assert plain.document["solver"].get("jackknife_pairs", 0) == 0

    # --threads does not change the result (the command line's promise), to the bit.
    one = calibench.calibrate(simulated, threads=1)
    np.testing.assert_array_equal(one.cam_from_lidar, base.cam_from_lidar)

    # The simulator's truth: the weighted-ml result is within 5 mm / 0.2 deg of it.
    manifest = json.loads((simulated / "dataset.json").read_text())
    truth = np.array(manifest["ground_truth"]["cam_from_lidar"], dtype=float).reshape(4, 4)
    error = np.linalg.inv(truth) @ base.cam_from_lidar
    assert np.linalg.norm(error[:3, 3]) < 0.005
    angle = np.degrees(np.arccos(np.clip((np.trace(error[:3, :3]) - 1) / 2, -1, 1)))
    assert angle < 0.2


def test_bad_input_raises_with_the_file_named(simulated, tmp_path):
    missing = tmp_path / "no_such_capture"
    with pytest.raises(calibench.InputError) as error:
        calibench.calibrate(missing)
    assert str(missing) in str(error.value) and error.value.exit_code == 2

    broken = tmp_path / "broken"
    shutil.copytree(simulated, broken)
    (broken / "dataset.json").write_text('{"format": "calibench.dataset.v1", "pairs": [')
    with pytest.raises(calibench.InputError) as error:
        calibench.calibrate(broken)
    assert "dataset.json" in str(error.value)

    # One unreadable image: the others still calibrate, the error names the file and carries
    # their result (the command line writes it and exits 2).
    damaged = tmp_path / "damaged"
    shutil.copytree(simulated, damaged)
    image = sorted((damaged / "images").iterdir())[0]
    image.write_bytes(b"not a png")
    with pytest.raises(calibench.InputError) as error:
        calibench.calibrate(damaged)
    assert str(image) in str(error.value)  # the message names the file, not "see above"
    assert error.value.result is not None
    assert sum(p.status == "accepted" for p in error.value.result.pairs) == 11

    with pytest.raises(calibench.UsageError) as error:
        calibench.calibrate(simulated, hubr_delta=0.1)
    assert "--hubr-delta" in str(error.value) and "--huber-delta" in str(error.value)
    with pytest.raises(calibench.UsageError) as error:
        calibench.calibrate(simulated, method="newton")
    assert "newton" in str(error.value)

    not_result = tmp_path / "dataset_copy.json"
    not_result.write_text((simulated / "dataset.json").read_text())
    with pytest.raises(calibench.InputError) as error:
        calibench.load_result(not_result)
    assert str(not_result) in str(error.value)
    with pytest.raises(calibench.InputError) as error:
        calibench.load_result(tmp_path / "absent.json")
    assert "absent.json" in str(error.value)


def test_too_few_pairs_is_refused_not_called_fine(simulated):
    with pytest.raises(calibench.NoCalibrationError) as error:
        calibench.calibrate(simulated, pairs=["0000", "0001"])
    assert error.value.exit_code == 3 and error.value.message


def test_the_core_runs_without_the_gil(simulated):
    ticks = 0
    done = threading.Event()

    def count():
        nonlocal ticks
        while not done.is_set():
            ticks += 1
            time.sleep(0.001)

    counter = threading.Thread(target=count)
    counter.start()
    start = time.monotonic()
    try:
        calibench.calibrate(simulated, threads=1)
    finally:
        done.set()
        counter.join()
    seconds = time.monotonic() - start
    # Python's thread kept running while the solve ran: held GIL would leave it at ~0 ticks.
    assert ticks > 0.25 * seconds / 0.001 * 0.5, (ticks, seconds)


def test_an_exception_in_the_callback_reaches_the_caller(simulated):
    def fail(phase, done, total, item):
        raise RuntimeError(f"stop at {item}")

    with pytest.raises(RuntimeError, match="stop at"):
        calibench.calibrate(simulated, progress=fail)
