"""scripts/eval_sequences on a small rendered sequence in the KITTI layout: one markdown row per
set, and with --seeds the medians over RANSAC seeds plus the worst run's orientation error."""
import re
import subprocess

import pytest

from conftest import ROOT

SCRIPT = ROOT / "scripts/eval_sequences"


@pytest.fixture(scope="module")
def sequence(tmp_path_factory):
    out = tmp_path_factory.mktemp("kitti_layout")
    subprocess.run([str(ROOT / "devel/lib/hybrid_vo/hybrid_vo_render_sequence"), "--kitti-dir",
                    str(out), "--frames", "15", "--width", "320", "--height", "240",
                    "--supersampling", "1"], check=True, capture_output=True, timeout=300)
    return out / "sequences" / "00"


def run(*args):
    return subprocess.run(["bash", str(SCRIPT), *args], capture_output=True, text=True,
                          timeout=600)


def cells(line):
    return [c.strip() for c in line.strip().strip("|").split("|")]


def test_one_row_per_set(sequence):
    result = run(f"corridor={sequence}")
    assert result.returncode == 0, result.stderr
    lines = result.stdout.strip().splitlines()
    assert len(lines) == 3, result.stdout
    header, row = cells(lines[0]), cells(lines[2])
    assert len(row) == len(header) == 9, result.stdout
    assert row[0] == "corridor"
    errors = [float(x) for x in row[1].split(" / ")]
    assert len(errors) == 4 and all(e >= 0.0 for e in errors), row
    assert 0.0 <= float(row[2]) <= 100.0, row
    assert re.fullmatch(r"\d+ of 14 \(\d+\)", row[7]), row


def test_seeds_give_medians_and_the_worst_run(sequence):
    result = run("--seeds", "3", f"corridor={sequence}")
    assert result.returncode == 0, result.stderr
    lines = result.stdout.strip().splitlines()
    header, row = cells(lines[0]), cells(lines[2])
    assert header[-1] == "worst of 3: last / max (deg)", header
    assert len(row) == len(header) == 10, result.stdout
    median_last, median_max = (float(x) for x in row[1].split(" / ")[2:])
    worst_last, worst_max = (float(x) for x in row[-1].split(" / "))
    assert worst_last >= median_last and worst_max >= median_max, row


@pytest.mark.parametrize("count", ["0", "x", "-2"])
def test_a_bad_seed_count_is_refused(count):
    result = run("--seeds", count, "a=b")
    assert result.returncode == 2
    assert "--seeds: expected a count >= 1" in result.stderr
