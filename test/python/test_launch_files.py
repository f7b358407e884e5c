"""Every argument of every launch file does what doc/node.md says: each is set to a value other
than its default and the launch configuration (the nodes, their parameters, remappings and
command lines, as roslaunch builds it without starting anything) is checked for its effect."""
import re
import xml.etree.ElementTree as ElementTree

import pytest

from conftest import ROOT

roslaunch = pytest.importorskip("roslaunch.config")

LAUNCH = ROOT / "launch"
LOW_TEXTURE = str(ROOT / "config" / "low_texture.yaml")


def load(launch, **args):
    argv = [f"{name}:={value}" for name, value in args.items()]
    return roslaunch.load_config_default([(str(LAUNCH / launch), argv)], None)


def node(config, name):
    found = [n for n in config.nodes if n.name == name]
    assert len(found) == 1, [n.name for n in config.nodes]
    return found[0]


def param(config, name):
    return config.params[name].value


def remaps(config, name="hybrid_vo"):
    return dict(node(config, name).remap_args)


# Per launch file, per argument: a value other than its default and what it must change.
CASES = {
    "hybrid_vo.launch": {
        "config": (LOW_TEXTURE, lambda c: param(c, "/hybrid_vo/klt_min_corner_gradient") == 1.5),
        "stereo": ("true", lambda c: param(c, "/hybrid_vo/stereo") is True),
        "image": ("/cam/img", lambda c: remaps(c)["image"] == "/cam/img"),
        "camera_info": ("/cam/info", lambda c: remaps(c)["camera_info"] == "/cam/info"),
        "left_image": ("/l/img", lambda c: remaps(c)["left/image"] == "/l/img"),
        "left_camera_info": ("/l/info", lambda c: remaps(c)["left/camera_info"] == "/l/info"),
        "right_image": ("/r/img", lambda c: remaps(c)["right/image"] == "/r/img"),
        "right_camera_info": ("/r/info", lambda c: remaps(c)["right/camera_info"] == "/r/info"),
        "node_name": ("vo", lambda c: param(c, "/vo/preset") == "hybrid" and remaps(c, "vo")),
        "preset": ("5pc", lambda c: param(c, "/hybrid_vo/preset") == "5pc"),
        "image_transport": ("compressed",
                            lambda c: param(c, "/hybrid_vo/image_transport") == "compressed"),
        "output": ("log", lambda c: node(c, "hybrid_vo").output == "log"),
        "max_cpu_ms": ("12", lambda c: param(c, "/hybrid_vo/max_cpu_ms") == 12),
    },
}
# The replay launch files share their arguments; lamar adds its cameras.
REPLAY = {
    "bag": ("/data/x.bag", lambda c: node(c, "player").args.endswith("/data/x.bag")),
    "stereo": ("true", lambda c: param(c, "/hybrid_vo/stereo") is True),
    "rviz": ("true", lambda c: node(c, "rviz").type == "rviz"),
    "record": ("/tmp/out.bag", lambda c: "-O /tmp/out.bag" in node(c, "recorder").args),
    "rate": ("3", lambda c: " -r 3 " in node(c, "player").args),
    "preset": ("5pc", lambda c: param(c, "/hybrid_vo/preset") == "5pc"),
    "image_transport": ("compressed",
                        lambda c: param(c, "/hybrid_vo/image_transport") == "compressed"),
    "config": (LOW_TEXTURE, lambda c: param(c, "/hybrid_vo/klt_min_corner_gradient") == 1.5),
    "max_cpu_ms": ("12", lambda c: param(c, "/hybrid_vo/max_cpu_ms") == 12),
    "play": ("false", lambda c: not [n for n in c.nodes if n.name == "player"]
             and param(c, "/use_sim_time") is False),
}
CASES["kitti.launch"] = dict(REPLAY)
CASES["lamar.launch"] = dict(
    REPLAY,
    camera=("cam_a", lambda c: remaps(c)["image"] == "/camera/cam_a/image_raw"),
    right_camera=("cam_b", lambda c: remaps(c)["right/image"] == "/camera/cam_b/image_raw"))
CASES["demo.launch"] = {k: v for k, v in REPLAY.items() if k not in ("preset", "play")}
CASES["demo.launch"]["stereo"] = ("false", lambda c: param(c, "/hybrid_vo/stereo") is False)
CASES["demo.launch"]["rate"] = ("2", lambda c: " -r 2 " in node(c, "player").args)
REQUIRED = {"kitti.launch": {"bag": "k.bag"}, "demo.launch": {"bag": "d.bag"},
            "lamar.launch": {"bag": "l.bag", "camera": "cam"}}


def declared_arguments(launch):
    return {arg.get("name") for arg in ElementTree.parse(LAUNCH / launch).getroot().iter("arg")
            if arg.get("value") is None}  # not the include's pass-through <arg value=...>


def test_every_launch_file_and_argument_has_a_case():
    assert {p.name for p in LAUNCH.glob("*.launch")} == set(CASES)
    for launch, cases in CASES.items():
        assert declared_arguments(launch) == set(cases), launch


@pytest.mark.parametrize("launch", sorted(CASES))
def test_every_argument_takes_effect(launch):
    required = REQUIRED.get(launch, {})
    default = load(launch, **required)
    for name, (value, took_effect) in CASES[launch].items():
        try:
            before = took_effect(default)
        except (AssertionError, KeyError):
            before = False
        assert not before, f"{launch} {name}: the default already passes"
        config = load(launch, **{**required, name: value})
        assert took_effect(config), f"{launch} {name}:={value}"


def test_every_parameter_the_launch_files_set_is_one_the_node_reads():
    # hybrid_vo.launch sets stereo, preset and image_transport besides the config file's.
    node_md = (ROOT / "doc" / "node.md").read_text()
    for name, p in load("hybrid_vo.launch", preset="5pc", image_transport="raw").params.items():
        if name.startswith("/hybrid_vo/"):
            assert f"`{name.split('/')[-1]}`" in node_md, name
    # The documented argument tables name every argument.
    for launch, cases in CASES.items():
        section = node_md[node_md.index("`" + launch + "`"):]
        for arg in cases:
            assert re.search(rf"`{arg}(:=|`)", section), f"{launch}: {arg} not in doc/node.md"
