"""Every shell command in README.md runs as written from the checkout, after the two set-up
commands: each line of every bash block, in a shell that has run the README's environment block.
A command that serves a camera (roslaunch of the node, the node alone beside a roscore) runs until
the node is up and is then interrupted; commands on ../shared/data run when the data is there. A new command that no
rule below knows fails the test, so that the README cannot gain an untested command."""
import os
import re
import signal
import socket
import subprocess
import time

import pytest

from conftest import ROOT, data_dir

ENVIRONMENT = ["export PATH=/usr/bin:$PATH", "source build/devel/setup.bash"]
SETUP = ["scripts/demo", "scripts/test"]  # the two commands: this test is part of scripts/test

# How each command runs: (pattern, mode). "finishes": must exit 0; "serves": the node must come up
# and keep running; "display": needs a screen, which the test does not have.
RULES = [
    (r"^scripts/eval_kitti ", "finishes"),
    (r"^build/devel/lib/hybrid_vo/hybrid_vo_lamar_to_bag ", "finishes"),
    (r"^roslaunch hybrid_vo lamar\.launch ", "finishes"),
    (r"^roslaunch hybrid_vo hybrid_vo\.launch ", "serves"),
    (r"^build/devel/lib/hybrid_vo/hybrid_vo_node ", "serves"),
    (r"^scripts/demo --rviz$", "display"),
]


def readme_commands():
    text = (ROOT / "README.md").read_text()
    commands = []
    for block in re.findall(r"```bash\n(.*?)```", text, re.S):
        for line in block.splitlines():
            command = line.split("  #")[0].strip()
            if command:
                commands.append(command)
    return commands


def mode_of(command):
    for pattern, mode in RULES:
        if re.search(pattern, command):
            return mode
    return None


def test_every_readme_command_has_a_rule():
    commands = readme_commands()
    assert commands[:2] == SETUP and commands[2:4] == ENVIRONMENT, commands[:4]
    unknown = [c for c in commands[4:] if mode_of(c) is None]
    assert not unknown, f"README commands without a rule in this test: {unknown}"


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def shell(command, tmp_path):
    """The command in a bash that has run the environment block, on a ROS master of its own."""
    script = "\n".join(ENVIRONMENT + ["set -e", command])
    env = dict(os.environ, ROS_MASTER_URI=f"http://localhost:{free_port()}",
               ROS_HOME=str(tmp_path / "ros_home"))
    return script, env


def node_is_up(env):
    run = subprocess.run(["bash", "-c", "source build/devel/setup.bash && rosnode list"],
                         cwd=ROOT, env=env, capture_output=True, text=True, timeout=30)
    return "/hybrid_vo" in run.stdout.split()


@pytest.mark.parametrize("command", [c for c in readme_commands()[4:]])
def test_readme_command_runs(command, tmp_path):
    mode = mode_of(command)
    if mode == "display":
        pytest.skip("needs a display (the launch files' rviz argument is tested in "
                    "test_launch_files.py)")
    if "../shared/data/" in command:
        if not data_dir().exists():
            pytest.skip(f"{data_dir()} not present")
        command = command.replace("../shared/data/", f"{data_dir()}/")
    script, env = shell(command, tmp_path)
    if mode == "finishes":
        run = subprocess.run(["bash", "-c", script], cwd=ROOT, env=env, capture_output=True,
                             text=True, timeout=900)
        assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
        if command.startswith("scripts/eval_kitti"):
            assert re.search(r"^summary: pairs=\d+ auc5=", run.stdout, re.M), run.stdout
        return
    # Serves a camera: the node must come up and stay up until interrupted.
    master = None
    if not command.startswith("roslaunch"):  # the node alone needs a master
        port = env["ROS_MASTER_URI"].rsplit(":", 1)[1]
        roscore = f"source build/devel/setup.bash && exec roscore -p {port}"
        master = subprocess.Popen(["bash", "-c", roscore],
                                  cwd=ROOT, env=env, stdout=subprocess.DEVNULL,
                                  stderr=subprocess.DEVNULL, start_new_session=True)
    served = subprocess.Popen(["bash", "-c", script], cwd=ROOT, env=env, stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, text=True, start_new_session=True)
    try:
        deadline = time.time() + 60
        up = False
        while time.time() < deadline and served.poll() is None and not up:
            time.sleep(2)
            up = node_is_up(env)
        assert up and served.poll() is None, "the node did not come up"
    finally:
        for process in (served, master):
            if process is not None and process.poll() is None:
                os.killpg(process.pid, signal.SIGINT)
                try:
                    process.wait(timeout=30)
                except subprocess.TimeoutExpired:
                    os.killpg(process.pid, signal.SIGKILL)
                    process.wait()
    output = served.stdout.read()
    assert "hybrid_vo:" in output or up, output[-3000:]
