#!/usr/bin/env python3
"""Calibrate every capture in a directory (a fleet's robots, a day's recordings) and say which
ones hold: one line per capture with its sigma, and how far it is from a reference result.

    PYTHONPATH=build/python python3 examples/calibrate_every_capture.py captures/ \
        [--reference lab_result.json] [--goal-mm 5 --goal-deg 0.2]

A capture is a folder (clouds/ + images/, or a manifest) or a recording (.bag, .mcap, .db3), which
is imported first (its board from a target.json beside it, else the preset that fits).
"""
import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np

import calibench

RECORDINGS = {".bag", ".mcap", ".db3"}


def change(a: np.ndarray, b: np.ndarray) -> tuple[float, float]:
    """Translation [mm] and rotation [deg] between two cam_from_lidar."""
    delta = np.linalg.inv(a) @ b
    angle = np.arccos(np.clip((np.trace(delta[:3, :3]) - 1) / 2, -1, 1))
    return 1e3 * np.linalg.norm(delta[:3, 3]), float(np.degrees(angle))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("directory")
    parser.add_argument("--reference", help="a result file to compare each capture with")
    parser.add_argument("--goal-mm", type=float, default=5.0, help="largest change that holds")
    parser.add_argument("--goal-deg", type=float, default=0.2, help="largest change that holds")
    args = parser.parse_args()
    reference = calibench.load_result(args.reference) if args.reference else None
    failed = 0
    with tempfile.TemporaryDirectory() as tmp:
        for capture in sorted(Path(args.directory).iterdir()):
            name = capture.name
            try:
                dataset = capture
                if capture.suffix in RECORDINGS:
                    dataset = Path(calibench.import_recording(capture, Path(tmp) / name)["folder"])
                result = calibench.calibrate(dataset)
            except calibench.Error as error:
                failed += 1
                print(f"{name:24s} no calibration: {error.message.splitlines()[-1]}")
                continue
            line = (f"{name:24s} sigma {np.round(result.std_t_m * 1e3, 1).tolist()} mm "
                    f"{np.round(result.std_r_deg, 2).tolist()} deg")
            if reference is not None:
                mm, deg = change(reference.cam_from_lidar, result.cam_from_lidar)
                holds = mm <= args.goal_mm and deg <= args.goal_deg
                failed += not holds
                line += f"; {mm:.1f} mm / {deg:.2f} deg from the reference: "
                line += "holds" if holds else "MOVED"
            print(line)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
