"""The node run as a user runs it, by a command in a shell that has sourced a workspace's setup
file, and what a user expects of it: it comes up, advertises its topics and answers frames.
Shared by the README's command tests and the catkin workspace test."""
import os
import re
import signal
import socket
import subprocess
import time

# What the node advertises (README, "The node").
NODE_TOPICS = {"/hybrid_vo/relative_pose", "/hybrid_vo/odometry", "/hybrid_vo/path",
               "/hybrid_vo/vanishing_points", "/hybrid_vo/markers", "/hybrid_vo/debug_image",
               "/diagnostics"}

# The rendered bag's topics (hybrid_vo_render_sequence --stereo) and the command arguments that
# name the node's inputs (launch arguments or, for the node alone, remappings), first match wins.
BAG_INPUTS = {
    "/camera/left/image_raw": ("image", "left_image"),
    "/camera/left/camera_info": ("camera_info", "left_camera_info"),
    "/camera/right/image_raw": ("right_image",),
    "/camera/right/camera_info": ("right_camera_info",),
}


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def ros_env(base, tmp_path):
    """`base` with a ROS master of its own (on a free port) and a ROS_HOME in tmp_path."""
    return dict(base, ROS_MASTER_URI=f"http://localhost:{free_port()}",
                ROS_HOME=str(tmp_path / "ros_home"))


def start(script, env, cwd):
    """A bash script in a process group of its own (stop() ends all of it)."""
    return subprocess.Popen(["bash", "-c", script], cwd=cwd, env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, start_new_session=True)


def stop(process):
    if process is None or process.poll() is not None:
        return
    os.killpg(process.pid, signal.SIGINT)
    try:
        process.wait(timeout=30)
    except subprocess.TimeoutExpired:
        os.killpg(process.pid, signal.SIGKILL)
        process.wait()


def ros(command, setup, env, cwd, timeout=30):
    """A ROS command line after `source setup`; its output."""
    run = subprocess.run(["bash", "-c", f"source {setup} && {command}"], cwd=cwd, env=env,
                         capture_output=True, text=True, timeout=timeout)
    return run.stdout


def start_master(setup, env, cwd):
    port = env["ROS_MASTER_URI"].rsplit(":", 1)[1]
    master = start(f"source {setup} && exec roscore -p {port}", env, cwd)
    deadline = time.time() + 30
    while time.time() < deadline and "/rosout" not in ros("rosnode list", setup, env, cwd):
        time.sleep(1)
    return master


def wait_until_up(process, setup, env, cwd, timeout=60):
    """True once the node /hybrid_vo is registered, while `process` still runs."""
    deadline = time.time() + timeout
    while time.time() < deadline and process.poll() is None:
        if "/hybrid_vo" in ros("rosnode list", setup, env, cwd).split():
            return True
        time.sleep(2)
    return False


def advertised(setup, env, cwd):
    return set(ros("rostopic list -p", setup, env, cwd).split())


def input_remaps(command):
    """The bag's topics renamed to the inputs that `command` gives the node."""
    given = dict(re.findall(r"(?:^|\s)(\w+):=(\S+)", command))
    remaps = []
    for topic, names in BAG_INPUTS.items():
        name = next((n for n in names if n in given), None)
        if name is not None:
            remaps.append(f"{topic}:={given[name]}")
    return remaps


def answers_frames(setup, env, cwd, bag, remaps, timeout=90):
    """True when the node publishes a motion while the rendered bag plays (in a loop) into the
    inputs `remaps` name."""
    echo = start(f"source {setup} && exec rostopic echo -n 1 /hybrid_vo/relative_pose/status",
                 env, cwd)
    time.sleep(3)  # subscribed before the first frame
    play = start(f"source {setup} && exec rosbag play -q -l {bag} {' '.join(remaps)}", env, cwd)
    try:
        echo.wait(timeout=timeout)
        return echo.returncode == 0 and echo.stdout.read().strip() != ""
    except subprocess.TimeoutExpired:
        return False
    finally:
        stop(play)
        stop(echo)


def check_node(command, setup, env, cwd, bag, needs_master):
    """Runs `command` (after `source setup`), beside a roscore when `needs_master`; asserts that
    the node comes up, advertises its topics and answers the rendered frames."""
    master = start_master(setup, env, cwd) if needs_master else None
    served = start(f"source {setup} && set -e && {command}", env, cwd)
    try:
        up = wait_until_up(served, setup, env, cwd)
        assert up and served.poll() is None, "the node did not come up"
        missing = NODE_TOPICS - advertised(setup, env, cwd)
        assert not missing, f"not advertised: {sorted(missing)}"
        assert answers_frames(setup, env, cwd, bag, input_remaps(command)), \
            "no motion published for the rendered frames"
    finally:
        stop(served)
        stop(master)
    output = served.stdout.read()
    assert "hybrid_vo:" in output or up, output[-3000:]
