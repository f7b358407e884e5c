"""scripts/eval_real, the real-data yardstick, and its ratchet: on the shared real sets (skipped
without them) today's code is no worse than the committed baseline (doc/real_data_baseline.json)
beyond the noise; the ratchet's own rules on made-up numbers; its data-less run."""
import copy
import importlib.machinery
import importlib.util
import json
import subprocess

import pytest

from conftest import ROOT, data_dir

SCRIPT = ROOT / "scripts/eval_real"
BASELINE = ROOT / "doc/real_data_baseline.json"


def load_script():
    loader = importlib.machinery.SourceFileLoader("eval_real", str(SCRIPT))
    spec = importlib.util.spec_from_loader("eval_real", loader)
    module = importlib.util.module_from_spec(spec)
    loader.exec_module(module)
    return module


def result(window, last, nees, answered=100):
    median = {"window_deg": window, "last_deg": last, "rot_nees": nees}
    return {"median": median, "worst": {"answered": answered}}


def test_the_ratchet_fails_beyond_the_margins_and_only_there():
    eval_real = load_script()
    baseline = {"sets": {"a": result(2.0, 10.0, 3.0)}}
    # Within the noise: 1.05 x 2 + 0.01 and 1.1 x 10 + 0.02.
    assert eval_real.check({"a": result(2.109, 11.019, 5.9)}, baseline) == []
    # Better is always fine.
    assert eval_real.check({"a": result(0.5, 1.0, 1.0)}, baseline) == []
    problems = eval_real.check({"a": result(2.111, 10.0, 3.0)}, baseline)
    assert len(problems) == 1 and "1 s windows" in problems[0]
    problems = eval_real.check({"a": result(2.0, 11.03, 3.0)}, baseline)
    assert len(problems) == 1 and "last frame" in problems[0]
    # The NEES leaving [0.8, 6], or moving further out when it was out already.
    assert "NEES" in eval_real.check({"a": result(2.0, 10.0, 6.5)}, baseline)[0]
    assert "NEES" in eval_real.check({"a": result(2.0, 10.0, 0.7)}, baseline)[0]
    out = {"sets": {"a": result(2.0, 10.0, 8.0)}}
    assert eval_real.check({"a": result(2.0, 10.0, 7.9)}, out) == []
    assert "NEES" in eval_real.check({"a": result(2.0, 10.0, 9.0)}, out)[0]
    # A frame no longer answered, or a measure gone missing.
    assert "answered" in eval_real.check({"a": result(2.0, 10.0, 3.0, 99)}, baseline)[0]
    assert "1 s windows" in eval_real.check({"a": result(None, 10.0, 3.0)}, baseline)[0]
    # Sets the baseline does not know are not judged.
    assert eval_real.check({"new": result(9.0, 90.0, 30.0)}, baseline) == []


def test_the_bench_output_is_parsed():
    eval_real = load_script()
    out = """# answers: 458 of 458 frames after the first have a pose (100.0 %), 2 of them rotation-only
median ms: total 23.6; CPU per frame 23.6
accuracy: pairs 319, AUC@5/10/20 1.84 / 6.00 / 15.59, drift 13.89 % and 1548.957 deg/100 m, ATE 0.0437 m (scale aligned), RPE rotation 1.4184 deg
rotation error (deg): median 0.964 per estimated pair (458), 4.047 over 1 s windows (431), orientation against the first frame 7.718 at the last frame and 14.666 at most; median translation direction error 28.60 deg
# consistency: rotation per pair (3 dof, truth sigma 0.1 deg): NEES median 6.31 (honest 2.366), p90 30.50, 56.3 % inside the 95 % ellipsoid (7.815); 458 of 458
# consistency: translation direction per pair (2 dof, truth sigma 0.1 deg): NEES median 11.22 (honest 1.386), p90 244.28, 37.9 % inside the 95 % ellipsoid (5.992); 319 of 319
"""
    r = eval_real.parse(out)
    assert (r["pair_deg"], r["window_deg"], r["last_deg"], r["max_deg"]) == (0.964, 4.047, 7.718,
                                                                             14.666)
    assert (r["auc10"], r["ate"], r["drift_percent"]) == (6.0, 0.0437, 13.89)
    assert (r["answered"], r["frames"], r["cpu_ms"]) == (458, 458, 23.6)
    assert (r["rot_nees"], r["rot_inside"], r["dir_nees"], r["dir_inside"]) == (6.31, 56.3, 11.22,
                                                                                 37.9)
    assert eval_real.parse("nothing")["window_deg"] is None


def test_without_the_data_it_says_so_and_passes(tmp_path):
    done = subprocess.run([str(SCRIPT), "--data", str(tmp_path), "--check", str(BASELINE)],
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "no shared real data" in done.stdout


def test_the_baseline_is_committed_with_every_set():
    baseline = json.loads(BASELINE.read_text())
    eval_real = load_script()
    assert set(baseline["sets"]) == set(eval_real.SETS)
    assert baseline["seeds"] == 5
    for name, res in baseline["sets"].items():
        assert len(res["runs"]) == 5, name
        assert res["median"]["window_deg"] is not None, name


def test_every_real_set_is_no_worse_than_the_baseline(tmp_path):
    """The ratchet: all shared real sets, seeds 0-4, against doc/real_data_baseline.json."""
    if not (data_dir() / "tum_fr1_rpy_459").exists():
        pytest.skip(f"{data_dir()} not present")
    out = tmp_path / "now.json"
    done = subprocess.run([str(SCRIPT), "--data", str(data_dir()), "--check", str(BASELINE),
                           "--json", str(out)], capture_output=True, text=True, timeout=1800)
    assert done.returncode == 0, done.stdout[-4000:] + done.stderr[-4000:]
    now = json.loads(out.read_text())
    assert set(now["sets"]) == set(json.loads(BASELINE.read_text())["sets"])
