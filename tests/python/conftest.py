"""Fixtures of the Python package's tests: the executable to compare with, and the real data.

Tests that need ../shared skip with a message in a user's clone; CALIBENCH_REQUIRE_SHARED=1
(.ci/run) makes them fail instead, so CI never skips them.
"""
import os
import subprocess
from pathlib import Path

import pytest


@pytest.fixture(scope="session")
def exe() -> str:
    path = os.environ.get("CALIBENCH_EXE")
    if not path or not Path(path).is_file():
        pytest.fail("CALIBENCH_EXE must name the built calibench (ctest sets it)")
    return path


@pytest.fixture(scope="session")
def shared() -> Path:
    path = Path(os.environ.get("CALIBENCH_SHARED_DIR", "../shared"))
    if not (path / "datasets").is_dir():
        message = f"the shared datasets are not at {path} (set CALIBENCH_SHARED_DIR)"
        if os.environ.get("CALIBENCH_REQUIRE_SHARED") == "1":
            pytest.fail(message)
        pytest.skip(message)
    return path


@pytest.fixture(scope="session")
def acfr(shared: Path, tmp_path_factory) -> Path:
    """The real VLP-16 + fisheye set laid out as a user's folder (scripts/acfr_folder.sh)."""
    folder = tmp_path_factory.mktemp("acfr") / "acfr"
    source = Path(os.environ["CALIBENCH_SOURCE_DIR"])
    subprocess.run(["bash", str(source / "scripts/acfr_folder.sh"), str(folder)], check=True,
                   env={**os.environ, "CALIBENCH_SHARED_DIR": str(shared.resolve())},
                   capture_output=True)
    return folder


@pytest.fixture(scope="session")
def simulated(exe: str, tmp_path_factory) -> Path:
    """A small simulated dataset (12 pairs, VLP-16, A3), written by the command line."""
    folder = tmp_path_factory.mktemp("sim") / "sim"
    subprocess.run([exe, "simulate", "--out", str(folder), "--pairs", "12", "--seed", "3"],
                   check=True, capture_output=True)
    return folder
