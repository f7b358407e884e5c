#!/usr/bin/python3
"""The cost of calling the estimator from Python, on hybrid_vo_bench_estimator's scenes.

Generates the bench's 2000-point scenes with the same C++ generator and seeds
(hybrid_vo.synthetic.manhattan_scenes), runs hybrid_vo.estimate_relative_pose on them with the
bench's per-scene RANSAC seeds, and alternates with runs of the C++ bench itself, so that both
are measured in the same time window of a shared machine. Per repeat and setting it records the
median time per call (the Python time includes the call, the argument checks, the options and
reading R, t and the point inlier mask), and per call the C++ estimator's own time
(timings['estimator_ms']) for a paired overhead that machine load hardly moves.

Usage (after `source devel/setup.bash`):
  python3 scripts/bench_estimator_python.py [--repeats 5] [--scenes 50] [--presets a,b]
"""
import argparse
import csv
import io
import pathlib
import subprocess
import time

import hybrid_vo

ROOT = pathlib.Path(__file__).resolve().parents[1]
POINTS = 2000
OUTLIERS = (0.25, 0.5)


def median(values):
    """The upper median, as the C++ tools take it (include/hybrid_vo/evaluation/statistics.h)."""
    return sorted(values)[len(values) // 2]


def scenes_of(args, outliers):
    """The bench's scenes: one generator seeded with seed + points + int(100 * outliers)."""
    return hybrid_vo.synthetic.manhattan_scenes(
        args.scenes, args.seed + POINTS + int(100 * outliers), num_points=POINTS,
        num_segments=150, point_outlier_ratio=outliers, line_outlier_ratio=0.3, noise_px=0.5,
        num_vps=3)


def run_python(args, scenes, preset):
    wall, own, rot, trans, iterations = [], [], [], [], []
    for i, scene in enumerate(scenes):
        inputs = scene["inputs"]
        start = time.perf_counter()
        est = hybrid_vo.estimate_relative_pose(**inputs, preset=preset, seed=args.seed + i)
        R, t, _ = est.R, est.t, est.point_inliers
        wall.append((time.perf_counter() - start) * 1e3)
        own.append(est.timings["estimator_ms"])
        errors = hybrid_vo.pose_error_deg(R, t, scene["R"], scene["t"]) if est.ok else (180, 180)
        rot.append(errors[0])
        trans.append(errors[1])
        iterations.append(est.iterations)
    return wall, own, median(rot), median(trans), median(iterations)


def run_cpp(args):
    """Median ms per (preset, outliers) at 2000 points, and the bench's result columns."""
    out = subprocess.run([args.bench, "--scenes", str(args.scenes), "--seed", str(args.seed),
                          "--presets", ",".join(args.presets)],
                         check=True, capture_output=True, text=True).stdout
    rows = {}
    for row in csv.DictReader(io.StringIO(out)):
        if int(row["points"]) == POINTS and row["preset"] in args.presets:
            rows[row["preset"], float(row["outlier_ratio"])] = row
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--bench", default=str(ROOT / "devel/lib/hybrid_vo/"
                                               "hybrid_vo_bench_estimator"))
    parser.add_argument("--scenes", type=int, default=50)
    parser.add_argument("--seed", type=int, default=7)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--presets", default="hybrid+junc,5pc")
    args = parser.parse_args()
    args.presets = args.presets.split(",")
    scenes = {r: scenes_of(args, r) for r in OUTLIERS}
    settings = [(p, r) for p in args.presets for r in OUTLIERS]
    cpp = {s: [] for s in settings}
    python = {s: [] for s in settings}
    paired = {s: [] for s in settings}
    results = {}
    for repeat in range(args.repeats):
        for setting, row in run_cpp(args).items():
            cpp[setting].append(float(row["median_ms"]))
            results[setting] = row
        for preset, outliers in settings:
            wall, own, rot, trans, iterations = run_python(args, scenes[outliers], preset)
            python[preset, outliers].append(median(wall))
            paired[preset, outliers] += [w / o - 1 for w, o in zip(wall, own)]
            row = results[preset, outliers]
            # Same scenes and seeds, so the same estimates as the C++ bench.
            same = (abs(rot - float(row["median_rot_err_deg"])) < 1e-4 and
                    abs(trans - float(row["median_trans_err_deg"])) < 1e-4 and
                    iterations == float(row["median_iterations"]))
            if not same:
                raise SystemExit(f"{preset} {outliers}: Python and C++ estimates differ "
                                 f"({rot:.4f}/{trans:.4f}/{iterations} vs {dict(row)})")
        print(f"# repeat {repeat + 1}/{args.repeats} done", flush=True)
    print("preset,points,outlier_ratio,cpp_bench_ms,python_ms,ratio,paired_overhead_pct,"
          "median_rot_err_deg,median_trans_err_deg")
    for setting in settings:
        c, p = median(cpp[setting]), median(python[setting])
        row = results[setting]
        print(f"{setting[0]},{POINTS},{setting[1]:.2f},{c:.3f},{p:.3f},{p / c:.3f},"
              f"{100 * median(paired[setting]):.2f},{row['median_rot_err_deg']},"
              f"{row['median_trans_err_deg']}")


if __name__ == "__main__":
    main()
