"""Every shell command in README.md runs as written from the checkout, after the two set-up
commands: each line of every bash block, in a shell that has run the README's environment block.
A command that serves a camera (roslaunch of the node, the node alone beside a roscore) must
bring the node up, advertise its topics and answer a few rendered frames played into the inputs
it names; it is then interrupted. Commands on ../shared/data run when the data is there. A new
command that no rule below knows fails the test, so that the README cannot gain an untested
command. The catkin workspace route (the block marked ROUTE_MARK) runs in
test_catkin_workspace.py."""
import os
import re
import subprocess

import pytest

from conftest import ROOT, data_dir
from node_runs import check_node, ros_env

ENVIRONMENT = ["export PATH=/usr/bin:$PATH", "source devel/setup.bash"]
SETUP = ["scripts/demo", "scripts/test"]  # the two commands: this test is part of scripts/test

# How each command runs: (pattern, mode). "finishes": must exit 0; "serves": the node must come up,
# advertise its topics and answer frames (node_runs.check_node); "display": needs a screen, which
# the test does not have.
RULES = [
    (r"^scripts/eval_kitti ", "finishes"),
    (r"^rosrun hybrid_vo hybrid_vo_lamar_to_bag ", "finishes"),
    (r"^roslaunch hybrid_vo lamar\.launch ", "finishes"),
    (r"^roslaunch hybrid_vo hybrid_vo\.launch ", "serves"),
    (r"^rosrun hybrid_vo hybrid_vo_node ", "serves"),
    (r"^scripts/demo --rviz$", "display"),
]

ROUTE_MARK = "<!-- route:catkin -->"


def readme_blocks():
    """Each bash block of the README: (marked as the catkin route, its text)."""
    text = (ROOT / "README.md").read_text()
    return [(mark.strip() == ROUTE_MARK, block)
            for mark, block in re.findall(r"(<!-- [^>]* -->\n)?```bash\n(.*?)```", text, re.S)]


def block_commands(block):
    commands = []
    for line in block.splitlines():
        command = line.split("  #")[0].strip()
        if command:
            commands.append(command)
    return commands


def readme_commands():
    """The commands run from the checkout: every block's but the catkin route's."""
    return [c for route, block in readme_blocks() if not route for c in block_commands(block)]


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


def shell(command, tmp_path):
    """The command in a bash that has run the environment block, on a ROS master of its own."""
    script = "\n".join(ENVIRONMENT + ["set -e", command])
    return script, ros_env(os.environ, tmp_path)


@pytest.mark.parametrize("command", [c for c in readme_commands()[4:]])
def test_readme_command_runs(command, tmp_path, rendered_bag):
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
    # Serves a camera: up, its topics advertised, frames answered; the node alone needs a master.
    env["PATH"] = f"/usr/bin:{env['PATH']}"  # the environment block's first line
    check_node(command, ROOT / "devel/setup.bash", env, ROOT, rendered_bag,
               needs_master=not command.startswith("roslaunch"))
