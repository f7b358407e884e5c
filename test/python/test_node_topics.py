"""Every topic the node publishes can be read with rostopic, as a new user reads it after the
README's set-up (scripts/setup installs each message package's Python module): while rendered
stereo frames play, `rostopic echo -n 1` prints a message and `rostopic hz` a rate on each. The
node's old parameter name vp_tracker still takes effect, and says once that it is deprecated."""
import os
import re
import time

import pytest

from conftest import ROOT
from node_runs import NODE_TOPICS, ros, ros_env, start, start_master, stop, wait_until_up

SETUP = ROOT / "devel" / "setup.bash"
# The node's outputs (README, "The node"), and tf.
TOPICS = sorted(NODE_TOPICS | {"/tf"})
# The rendered bag's stereo topics into the node's inputs.
REMAPS = ("left/image:=/camera/left/image_raw left/camera_info:=/camera/left/camera_info "
          "right/image:=/camera/right/image_raw right/camera_info:=/camera/right/camera_info")


@pytest.fixture
def node_with_frames(tmp_path, rendered_bag):
    """A roscore; yields a function that starts the node (stereo, with extra private parameters)
    and plays the rendered frames into it in a loop, and returns the node's process."""
    env = ros_env(os.environ, tmp_path)
    master = start_master(SETUP, env, ROOT)
    started = []

    def run(params=""):
        node = start(f"source {SETUP} && exec rosrun hybrid_vo hybrid_vo_node _stereo:=true "
                     f"{params} {REMAPS}", env, ROOT)
        started.append(node)
        assert wait_until_up(node, SETUP, env, ROOT), "the node did not come up"
        started.append(start(f"source {SETUP} && exec rosbag play -q -l {rendered_bag}", env,
                             ROOT))
        return node, env

    yield run
    for process in reversed(started):
        stop(process)
    stop(master)


def publications(env):
    """The topics the node advertises (rosnode info), but /rosout."""
    info = ros("rosnode info /hybrid_vo", SETUP, env, ROOT)
    section = info.split("Publications:")[1].split("Subscriptions:")[0]
    return {t for t in re.findall(r"\* (\S+) \[", section) if t != "/rosout"}


def diagnostic(text, key):
    """A value of the node's status in an echoed DiagnosticArray."""
    found = re.search(rf'key: "{re.escape(key)}"\s+value: "([^"]*)"', text)
    return found.group(1) if found else None


def echo(topic, env, arrays=False, timeout=60):
    """One message of `topic` as rostopic prints it (long arrays left out but when `arrays`)."""
    flags = "" if arrays else "--noarr"
    return ros(f"timeout {timeout} rostopic echo -n 1 {flags} {topic}", SETUP, env, ROOT,
               timeout=timeout + 10)


def test_every_topic_echoes_and_has_a_rate(node_with_frames):
    node, env = node_with_frames()
    assert publications(env) == set(TOPICS), "a published topic is not tested here, or is gone"
    for topic in TOPICS:
        out = echo(topic, env)
        assert "---" in out, f"rostopic echo -n 1 {topic} printed no message:\n{out[-2000:]}"
        assert "Cannot load message class" not in out, out[-2000:]
    # All at once, each for 20 s: fifteen rospy processes starting together take several seconds
    # of a 2-core machine before they subscribe (8 s once left ~debug_image without a rate in CI),
    # and the 1 Hz /diagnostics needs two messages after that.
    rates = {topic: start(f"source {SETUP} && exec timeout -s INT 20 rostopic hz {topic}", env,
                          ROOT) for topic in TOPICS}
    for topic, process in rates.items():
        process.wait(timeout=60)
        out = process.stdout.read()
        rate = re.findall(r"average rate: ([0-9.]+)", out)
        assert rate and float(rate[-1]) > 0.0, f"rostopic hz {topic} gave no rate:\n{out[-2000:]}"
    # The map of world directions is on by default and finds the corridor's.
    status = echo("/diagnostics", env, arrays=True)
    assert int(diagnostic(status, "map directions")) > 0, status
    assert node.poll() is None, "the node died"


def test_old_parameter_name_takes_effect_and_warns_once(node_with_frames):
    node, env = node_with_frames("_vp_tracker:=false")
    deadline = time.time() + 60
    while time.time() < deadline:
        status = echo("/diagnostics", env, arrays=True)
        if int(diagnostic(status, "frames processed") or 0) >= 10:
            break
    assert int(diagnostic(status, "frames processed")) >= 10, status
    assert diagnostic(status, "map directions") == "0", status
    stop(node)
    output = node.stdout.read()
    assert output.count("vp_tracker: deprecated, use direction_map") == 1, output[-3000:]
