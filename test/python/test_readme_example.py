"""The README's Python example runs as written (from the checkout, on the shared KITTI frames,
next to OpenCV's findEssentialMat) and both poses are close to the ground truth."""
import re
import subprocess
import sys

import pytest

from conftest import ROOT, data_dir


def readme_example():
    text = (ROOT / "README.md").read_text()
    match = re.search(r"<!-- example:python -->\n```python\n(.*?)```", text, re.S)
    assert match, "README.md has lost its '<!-- example:python -->' block"
    return match.group(1)


def test_readme_example_runs(kitti):
    pytest.importorskip("cv2")
    # The README reads ../shared/data relative to the checkout; follow $HYBRID_VO_DATA if set.
    code = readme_example().replace('"../shared/data/', f'"{data_dir()}/')
    run = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True,
                         timeout=600)
    assert run.returncode == 0, run.stderr
    errors = dict(re.findall(r"^(\S+) rotation / translation error: ([\d.]+ / [\d.]+) deg$",
                             run.stdout, re.M))
    assert set(errors) == {"hybrid_vo", "OpenCV"}, run.stdout
    rotation, translation = map(float, errors["hybrid_vo"].split(" / "))
    assert rotation < 0.5 and translation < 3.0, run.stdout
