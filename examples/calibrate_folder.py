#!/usr/bin/env python3
"""Calibrate one capture folder and plot each pair's residuals.

    PYTHONPATH=build/python python3 examples/calibrate_folder.py my_capture/ --plot residuals.png

The folder is what `calibench calibrate --dataset` takes (clouds/, images/, camera.yaml,
target.json; a manifest; or a recording). Needs python3-matplotlib for --plot.
"""
import argparse
import sys

import numpy as np

import calibench


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("dataset")
    parser.add_argument("--plot", help="write the per-pair residuals here (PNG)")
    parser.add_argument("--out", help="also write the result file (calibench.result.v1)")
    args = parser.parse_args()

    def progress(phase: str, done: int, total: int, item: str) -> None:
        print(f"\r{phase} {done}/{total} {item}   ", end="" if done < total else "\n",
              file=sys.stderr, flush=True)

    try:
        result = calibench.calibrate(args.dataset, out=args.out, progress=progress)
    except calibench.Error as error:
        print(f"not calibrated: {error}", file=sys.stderr)
        return error.exit_code
    t = result.cam_from_lidar[:3, 3]
    print(f"cam_from_lidar translation [m]: {np.round(t, 4).tolist()}")
    print(f"sigma translation [mm]: {np.round(result.std_t_m * 1e3, 2).tolist()}")
    print(f"sigma rotation [deg]:   {np.round(result.std_r_deg, 3).tolist()}")
    for pair in result.pairs:
        if pair.status != "accepted":
            print(f"  {pair.id}: {pair.status}: {pair.reason}")
        elif pair.weight == 0.0:
            print(f"  {pair.id}: accepted, but down-weighted to nothing by the robust kernel")

    if args.plot:
        import matplotlib.pyplot as plt

        used = [p for p in result.pairs if p.residuals.size == 4]
        ids = [p.id for p in used]
        angle_deg = [np.degrees(np.linalg.norm(p.residuals[:3])) for p in used]
        distance_mm = [1e3 * p.residuals[3] for p in used]
        weight = [p.weight for p in used]
        figure, (top, bottom) = plt.subplots(2, 1, figsize=(10, 6), sharex=True)
        top.bar(ids, distance_mm, color=plt.cm.viridis(weight))
        top.set_ylabel("plane distance [mm]")
        bottom.bar(ids, angle_deg, color=plt.cm.viridis(weight))
        bottom.set_ylabel("normal angle [deg]")
        bottom.tick_params(axis="x", labelrotation=90)
        figure.suptitle("per-pair residuals at the solution (colour: robust weight, yellow = 1)")
        figure.tight_layout()
        figure.savefig(args.plot, dpi=100)
        print(f"wrote {args.plot}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
