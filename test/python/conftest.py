"""Shared fixtures of the Python binding tests (run by scripts/test after sourcing the devel
space, so that `import hybrid_vo` finds the built module)."""
import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


def data_dir():
    """The shared real data: $HYBRID_VO_DATA, else ../shared/data beside the checkout."""
    return pathlib.Path(os.environ.get("HYBRID_VO_DATA", ROOT.parent / "shared" / "data"))


@pytest.fixture(scope="session")
def kitti():
    path = data_dir() / "kitti_seq0x_51"
    if not path.exists():
        pytest.skip(f"{path} not present")
    return path


@pytest.fixture(scope="session")
def rendered_bag(tmp_path_factory):
    """A few small rendered stereo frames, for a running node to answer (node_runs.py)."""
    bag = tmp_path_factory.mktemp("rendered") / "frames.bag"
    subprocess.run([str(ROOT / "devel/lib/hybrid_vo/hybrid_vo_render_sequence"), "--out", str(bag),
                    "--frames", "20", "--stereo", "--width", "320", "--height", "240",
                    "--supersampling", "1"], check=True, capture_output=True, timeout=300)
    return bag
