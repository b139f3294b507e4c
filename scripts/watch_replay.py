#!/usr/bin/env python3
"""Replays a finished capture folder (clouds/, images/, camera.yaml, target.json) into an empty
folder pair by pair, as a capture script writes it (temporary name, then rename), while
`calibench watch --json-lines` follows it; prints each pair's latency (its last file renamed into
place -> the `solve` line after its `pair` line) and the summary.

  scripts/watch_replay.py SOURCE_FOLDER [--every 1.0] [--calibench build/calibench] [--work DIR]
                          [-- extra watch flags]
"""
import argparse
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time


def natural(name):
    return [int(t) if t.isdigit() else t for t in re.split(r"(\d+)", name)]


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("source")
    parser.add_argument("--every", type=float, default=1.0, help="seconds between pairs")
    parser.add_argument("--calibench", default="build/calibench")
    parser.add_argument("--work", default="")
    parser.add_argument("--idle-exit", type=float, default=5.0)
    parser.add_argument("watch_flags", nargs="*")
    args, extra = parser.parse_known_args()
    args.watch_flags += [f for f in extra if f != "--"]

    work = args.work or tempfile.mkdtemp(prefix="calibench_watch_replay_")
    watched = os.path.join(work, "watched")
    shutil.rmtree(watched, ignore_errors=True)
    os.makedirs(os.path.join(watched, "clouds"))
    os.makedirs(os.path.join(watched, "images"))
    if os.path.exists(os.path.join(args.source, "camera.yaml")):
        for name in ("camera.yaml", "target.json"):
            shutil.copyfile(os.path.join(args.source, name), os.path.join(watched, name))
    else:  # a simulated dataset: its manifest's pinhole camera and target in the folder form
        manifest = json.load(open(os.path.join(args.source, "dataset.json")))
        camera = manifest["camera"]
        k = [camera["fx"], 0, camera["cx"], 0, camera["fy"], camera["cy"], 0, 0, 1]
        with open(os.path.join(watched, "camera.yaml"), "w") as out:
            out.write("image_width: %d\nimage_height: %d\ncamera_name: sim\n" %
                      (camera["width"], camera["height"]))
            out.write("camera_matrix: {rows: 3, cols: 3, data: %s}\n" % json.dumps(k))
            out.write("distortion_model: plumb_bob\n")
            out.write("distortion_coefficients: {rows: 1, cols: 5, data: %s}\n" %
                      json.dumps(camera["distortion"]))
        json.dump(manifest["target"], open(os.path.join(watched, "target.json"), "w"))
    stream_path = os.path.join(work, "stream.jsonl")
    with open(stream_path, "w") as stream:
        watch = subprocess.Popen(
            [args.calibench, "watch", watched, "--json-lines", "--idle-exit", str(args.idle_exit)]
            + args.watch_flags, stdout=stream, stderr=subprocess.STDOUT)
        clouds = {os.path.splitext(f)[0]: f for f in os.listdir(os.path.join(args.source, "clouds"))}
        images = {os.path.splitext(f)[0]: f for f in os.listdir(os.path.join(args.source, "images"))}
        completed = {}
        for stem in sorted(set(clouds) & set(images), key=natural):
            start = time.time()
            for sub, files in (("clouds", clouds), ("images", images)):
                src = os.path.join(args.source, sub, files[stem])
                dst = os.path.join(watched, sub, files[stem])
                shutil.copyfile(src, dst + ".part")
                os.rename(dst + ".part", dst)
            completed[stem] = time.time()
            time.sleep(max(0.0, args.every - (time.time() - start)))
        watch.wait()
    import resource
    peak_mib = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024.0
    events = [json.loads(line) for line in open(stream_path) if line.startswith("{")]
    latency = {}
    pending = []
    verdict = {}
    for event in events:
        if event["event"] == "pair":
            verdict[event["name"]] = event["accepted"]
            if event["name"] not in latency:
                pending.append(event["name"])
        elif event["event"] == "solve":
            for name in pending:
                latency[name] = event["time"] - completed[name]
            pending = []
    solves = [e for e in events if e["event"] == "solve"]
    done_at = next((i for i, e in enumerate(solves) if e.get("done")), None)
    values = sorted(latency.values())
    print("pairs: %d, accepted: %d" % (len(verdict), sum(verdict.values())))
    print("latency (pair complete -> its solve line): median %.2f s, 90th percentile %.2f s, max %.2f s"
          % (statistics.median(values), values[int(0.9 * (len(values) - 1))], values[-1]))
    last = solves[-1]
    print("last solve: %d pairs used, sigma_t_mm %s, sigma_r_deg %s" %
          (last["pairs_used"], last.get("sigma_t_mm"), last.get("sigma_r_deg")))
    if done_at is not None:
        print("done fired at solve %d (%d pairs used): cam_from_lidar %s" %
              (done_at + 1, solves[done_at]["pairs_used"], json.dumps(solves[done_at]["cam_from_lidar"])))
    else:
        print("done never fired")
    print("last cam_from_lidar %s" % json.dumps(last["cam_from_lidar"]))
    print("watch peak memory %.0f MiB; latency of the last pair %.2f s" %
          (peak_mib, latency[max(latency, key=lambda n: completed[n])]))
    print("stream: %s" % stream_path)


if __name__ == "__main__":
    sys.exit(main())
