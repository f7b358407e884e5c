"""The README's catkin workspace route, as a ROS user takes it: its block (marked ROUTE_MARK) runs
as one script in a new workspace, on a fresh clone of this repository (its committed HEAD), with
catkin_make and catkin_make install; then the package must work from the install space and from
the devel space: the node by roslaunch and by rosrun, the nodelet, the launch and rviz files, the
messages and the Python module. On the shared KITTI excerpt (skipped without ../shared/data) the
install space's kitti.launch must give the checkout's AUC@10.

The build takes about 10 minutes on two cores; with ccache installed it is cached (the
workspace's paths are relative to CCACHE_BASEDIR, so every run's fresh workspace hits)."""
import os
import re
import shutil
import subprocess

import pytest

from conftest import ROOT, data_dir
from node_runs import check_node, ros, ros_env
from test_readme_commands import ROUTE_MARK, block_commands, readme_blocks

KITTI_SEQUENCE = "/path/to/kitti/sequences/00"


def route_commands():
    routes = [block for route, block in readme_blocks() if route]
    assert len(routes) == 1, f"the README needs one bash block after {ROUTE_MARK}"
    return block_commands(routes[0])


def user_environment(tmp_path):
    """A new user's shell: none of the checkout's build environment (scripts/test has sourced
    its devel space), system paths first, a ROS master of its own."""
    env = {k: v for k, v in os.environ.items()
           if str(ROOT) not in v and not k.startswith(("ROS", "CMAKE_", "CATKIN"))}
    env["PATH"] = "/usr/bin:/bin:/usr/sbin:/sbin"
    if shutil.which("ccache"):
        env.update(CMAKE_CXX_COMPILER_LAUNCHER="ccache", CCACHE_BASEDIR=str(tmp_path))
    return ros_env(env, tmp_path)


@pytest.fixture(scope="module")
def workspace(tmp_path_factory):
    """Runs the README's route in a new workspace: to its end with the shared KITTI excerpt,
    else up to the KITTI sequence. Returns the workspace and the route's output."""
    tmp_path = tmp_path_factory.mktemp("catkin")
    ws = tmp_path / "catkin_ws"
    kitti = data_dir() / "kitti_seq0x_51" / "sequences" / "seq0x"
    commands = route_commands()
    if not kitti.exists():
        commands = commands[:next(i for i, c in enumerate(commands) if KITTI_SEQUENCE in c)]
    script = "\n".join(["set -e"] + commands)
    for placeholder, value in [("~/catkin_ws", ws), ("/path/to/hybrid_vo", ROOT),
                               (KITTI_SEQUENCE, kitti)]:
        script = script.replace(placeholder, str(value))
    run = subprocess.run(["bash", "-c", script], cwd=tmp_path, env=user_environment(tmp_path),
                         capture_output=True, text=True, timeout=3600)
    assert run.returncode == 0, run.stdout[-5000:] + run.stderr[-5000:]
    yield ws, run.stdout
    shutil.rmtree(ws / "build", ignore_errors=True)  # the objects: about 1 GB


@pytest.mark.parametrize("space", ["install", "devel"])
def test_package_files(workspace, space, tmp_path):
    ws, _ = workspace
    env, setup = user_environment(tmp_path), ws / space / "setup.bash"
    share = ros("rospack find hybrid_vo", setup, env, ws).strip()
    expected = ws / "install/share/hybrid_vo" if space == "install" else ws / "src/hybrid_vo"
    assert share == str(expected)
    for name in ["launch/hybrid_vo.launch", "launch/kitti.launch", "launch/lamar.launch",
                 "launch/demo.launch", "config/default.yaml", "config/kitti.yaml",
                 "config/hybrid_vo.rviz", "nodelet_plugins.xml", "package.xml"]:
        assert (expected / name).is_file(), name
    plugins = ros("rospack plugins --attrib=plugin nodelet", setup, env, ws)
    assert f"hybrid_vo {expected}/nodelet_plugins.xml" in plugins, plugins
    python = ("import hybrid_vo, hybrid_vo.frontend; "
              "from hybrid_vo.msg import MotionEstimate, VanishingPoints; "
              "print(hybrid_vo.__file__, len(hybrid_vo.solvers()))")
    printed = ros(f"python3 -c '{python}'", setup, env, ws)
    assert printed.startswith(str(ws / space)), printed


@pytest.mark.parametrize("space, command, needs_master", [
    ("install", "roslaunch hybrid_vo hybrid_vo.launch image:=/cam/image camera_info:=/cam/info",
     False),
    ("install", "rosrun nodelet nodelet standalone hybrid_vo/VONodelet __name:=hybrid_vo "
                "image:=/cam/image camera_info:=/cam/info", True),
    ("install", "rosrun hybrid_vo hybrid_vo_node image:=/cam/image camera_info:=/cam/info", True),
    ("devel", "rosrun hybrid_vo hybrid_vo_node image:=/cam/image camera_info:=/cam/info", True),
    ("devel", "roslaunch hybrid_vo hybrid_vo.launch image:=/cam/image camera_info:=/cam/info",
     False),
])
def test_node_runs(workspace, space, command, needs_master, tmp_path, rendered_bag):
    ws, _ = workspace
    check_node(command, ws / space / "setup.bash", user_environment(tmp_path), ws, rendered_bag,
               needs_master)


def auc10(output):
    found = re.findall(r"^summary: .*\bauc10=([0-9.]+)", output, re.M)
    assert found, output[-3000:]
    return float(found[-1])


def test_kitti_from_the_install_space_as_from_the_checkout(workspace, tmp_path, kitti):
    _, output = workspace
    checkout = subprocess.run(
        ["scripts/eval_kitti", str(kitti / "sequences/seq0x"), "--preset", "hybrid+junc",
         "--out", str(tmp_path)], cwd=ROOT, env=ros_env(os.environ, tmp_path),
        capture_output=True, text=True, timeout=900)
    assert checkout.returncode == 0, checkout.stdout[-3000:] + checkout.stderr[-3000:]
    assert auc10(output) == auc10(checkout.stdout)
