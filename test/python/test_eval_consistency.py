"""hybrid_vo_eval_trajectory's `# consistency:` lines on a recording made up here: each pair's
errors drawn from the covariance its MotionEstimate carries, and ~odometry whose orientation
errors are drawn from its pose covariance about the odom frame's axes, for a body (base_link)
turned against the camera as KITTI's car is, and ~vanishing_points whose observations are drawn
from the covariances they carry. Honest covariances read the chi-square's median
NEES (2.366 for 3 dof, 1.386 for 2), the truth-noise options are added, and the all-zero
covariances of a node that publishes none count as missing."""
import re
import subprocess

import numpy as np
import pytest
import rosbag
import rospy
from geometry_msgs.msg import PoseStamped, TransformStamped
from hybrid_vo.msg import MotionEstimate, VanishingPoint, VanishingPoints
from nav_msgs.msg import Odometry
from tf2_msgs.msg import TFMessage

from conftest import ROOT

TOOL = ROOT / "devel/lib/hybrid_vo/hybrid_vo_eval_trajectory"
FRAMES = 401
# The camera (x right, y down, z forward) in a body with x forward, y left, z up.
R_BODY_CAMERA = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])
DEG = np.pi / 180.0


def exp_rotation(w):
    angle = np.linalg.norm(w)
    if angle == 0.0:
        return np.eye(3)
    k = w / angle
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + np.sin(angle) * K + (1.0 - np.cos(angle)) * K @ K


def quaternion(R):
    """x, y, z, w of a rotation matrix (Shepperd's method)."""
    trace = np.trace(R)
    if trace > 0.0:
        s = 2.0 * np.sqrt(1.0 + trace)
        q = [(R[2, 1] - R[1, 2]) / s, (R[0, 2] - R[2, 0]) / s, (R[1, 0] - R[0, 1]) / s, 0.25 * s]
    else:
        i = int(np.argmax(np.diag(R)))
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2.0 * np.sqrt(1.0 + R[i, i] - R[j, j] - R[k, k])
        q = [0.0] * 4
        q[i] = 0.25 * s
        q[j] = (R[j, i] + R[i, j]) / s
        q[k] = (R[k, i] + R[i, k]) / s
        q[3] = (R[k, j] - R[j, k]) / s
    return q


def set_pose(pose, R, c):
    """A geometry_msgs Pose or Transform from a rotation and a position."""
    position = pose.translation if hasattr(pose, "translation") else pose.position
    orientation = pose.rotation if hasattr(pose, "rotation") else pose.orientation
    position.x, position.y, position.z = c
    orientation.x, orientation.y, orientation.z, orientation.w = quaternion(R)


def random_covariance(rng, low, high):
    Q = exp_rotation(rng.normal(size=3) * 2.0)
    return Q @ np.diag(rng.uniform(low, high, size=3) ** 2) @ Q.T


def tangent_basis(d):
    a = np.eye(3)[int(np.argmin(np.abs(d)))]
    b1 = np.cross(d, a)
    b1 /= np.linalg.norm(b1)
    return np.stack([b1, np.cross(d, b1)], axis=1)


def write_vanishing_points(bag, stamps, R_true):
    """Four world directions seen at every frame, each observation off by its own random tangent
    covariance and of a random sign (a VP's sign is arbitrary); its own generator, so that the
    rest of the recording is the same with or without them."""
    rng = np.random.default_rng(48)
    world = [np.eye(3)[0], np.eye(3)[1], np.eye(3)[2], np.array([0.6, 0.8, 0.0])]
    for k, t in enumerate(stamps):
        message = VanishingPoints()
        message.header.stamp = rospy.Time.from_sec(t)
        message.header.frame_id = "odom"
        for i, w in enumerate(world):
            d = R_true[k].T @ w
            B = tangent_basis(d)
            C2 = np.diag(rng.uniform(0.05, 0.5, 2) * DEG) ** 2
            step = B @ rng.multivariate_normal(np.zeros(2), C2)
            observed = exp_rotation(np.cross(d, step)) @ d
            vp = VanishingPoint(id=i, seen=True)
            vp.observation_camera.x, vp.observation_camera.y, vp.observation_camera.z = \
                observed * rng.choice([-1.0, 1.0])
            vp.observation_covariance = list((B @ C2 @ B.T).ravel())
            message.vps.append(vp)
        bag.write("/hybrid_vo/vanishing_points", message, message.header.stamp)


def write_bags(directory, honest):
    """A run (relative poses, tf, odometry) and its ground truth; with `honest` false every
    covariance is zero, as the node's odometry had it before issue 43."""
    rng = np.random.default_rng(43)
    stamps = [100.0 + 0.1 * k for k in range(FRAMES)]
    R_true, c_true = [np.eye(3)], [np.zeros(3)]
    for _ in range(1, FRAMES):
        R_true.append(R_true[-1] @ exp_rotation(rng.normal(size=3) * 1.0 * DEG))
        c_true.append(c_true[-1] + R_true[-2] @ np.array([0.0, 0.0, 1.0]))
    # The odometry's own world is the first camera's; its odom frame the body at the first frame.
    world_0 = exp_rotation(np.array([0.3, -1.2, 0.7]))
    R_true = [world_0 @ R for R in R_true]
    gt_bag, run_bag = directory / "gt.bag", directory / "run.bag"
    with rosbag.Bag(str(gt_bag), "w") as bag:
        for t, R, c in zip(stamps, R_true, c_true):
            p = PoseStamped()
            p.header.stamp = rospy.Time.from_sec(t)
            p.header.frame_id = "world"
            set_pose(p.pose, R, c)
            bag.write("/ground_truth/pose", p, p.header.stamp)
    odometry_sigma = np.array([0.05, 0.2, 2.0]) * DEG  # about odom's x, y and its vertical z
    with rosbag.Bag(str(run_bag), "w") as bag:
        if honest:
            write_vanishing_points(bag, stamps, R_true)
        static = TransformStamped()
        static.header.frame_id, static.child_frame_id = "base_link", "camera"
        set_pose(static.transform, R_BODY_CAMERA, np.array([1.0, 0.0, 1.5]))
        bag.write("/tf_static", TFMessage([static]), rospy.Time.from_sec(stamps[0]))
        for k, t in enumerate(stamps):
            stamp = rospy.Time.from_sec(t)
            # The camera in the odometry's world, the body in odom (as the node publishes it).
            R_vo = R_true[0].T @ R_true[k]
            c_vo = R_true[0].T @ (c_true[k] - c_true[0])
            R_body = R_BODY_CAMERA @ R_vo @ R_BODY_CAMERA.T
            pose_covariance = np.zeros((6, 6))
            if k > 0:
                rotation_covariance = np.diag(odometry_sigma ** 2)
                w = rng.multivariate_normal(np.zeros(3), rotation_covariance)
                R_body = exp_rotation(w) @ R_body
                pose_covariance[:3, :3] = 0.01 * np.eye(3)
                pose_covariance[3:, 3:] = rotation_covariance
            c_body = R_BODY_CAMERA @ c_vo + (np.eye(3) - R_body) @ np.array([1.0, 0.0, 1.5])
            tf = TransformStamped()
            tf.header.stamp, tf.header.frame_id, tf.child_frame_id = stamp, "odom", "base_link"
            set_pose(tf.transform, R_body, c_body)
            bag.write("/tf", TFMessage([tf]), stamp)
            odometry = Odometry()
            odometry.header = tf.header
            odometry.child_frame_id = "base_link"
            set_pose(odometry.pose.pose, R_body, c_body)
            if honest:
                odometry.pose.covariance = list(pose_covariance.ravel())
                if k % 2:
                    odometry.twist.covariance = list(np.eye(6).ravel() * 1e-3)
            bag.write("/hybrid_vo/odometry", odometry, stamp)

            m = MotionEstimate()
            m.header.stamp, m.header.frame_id = stamp, "camera"
            m.reference_frame_id = "camera"
            if k == 0:
                m.status = MotionEstimate.STATUS_SKIPPED
                bag.write("/hybrid_vo/relative_pose", m, stamp)
                continue
            m.reference_stamp = rospy.Time.from_sec(stamps[k - 1])
            m.status = MotionEstimate.STATUS_OK
            m.baseline = True  # as the node marks a pair whose translation its epipolar geometry gives
            R_pair = R_true[k].T @ R_true[k - 1]
            d_pair = R_true[k].T @ (c_true[k - 1] - c_true[k])
            d_pair /= np.linalg.norm(d_pair)
            rotation_covariance = random_covariance(rng, 0.02 * DEG, 0.5 * DEG)
            B = tangent_basis(d_pair)
            Q = exp_rotation(np.array([0.0, 0.0, rng.uniform(0.0, np.pi)]))[:2, :2]
            sigmas = rng.uniform(0.2, 2.0, 2) * DEG
            direction_covariance = B @ Q @ np.diag(sigmas ** 2) @ Q.T @ B.T
            R_est = exp_rotation(rng.multivariate_normal(np.zeros(3), rotation_covariance)) @ R_pair
            step = rng.multivariate_normal(np.zeros(3), direction_covariance)
            d_est = exp_rotation(np.cross(d_pair, step)) @ d_pair  # |step| radians towards step
            set_pose(m.transform, R_est, d_est)
            if honest and k % 10:  # every tenth pair without a covariance
                covariance = np.zeros((6, 6))
                covariance[:3, :3] = rotation_covariance
                covariance[3:, 3:] = direction_covariance
                m.covariance = list(covariance.ravel())
            bag.write("/hybrid_vo/relative_pose", m, stamp)
    return run_bag, gt_bag


def evaluate(run_bag, gt_bag, *options):
    """The `# consistency:` lines by what they measure, and the summary line's fields."""
    out = subprocess.run([str(TOOL), "--bag", str(run_bag), "--gt", str(gt_bag), *options],
                         check=True, capture_output=True, text=True, timeout=120).stdout
    prefix = "# consistency: "
    lines = {line[len(prefix):].split(" (")[0]: line
             for line in out.splitlines() if line.startswith(prefix)}
    summary = re.search(r"^summary: (.*)$", out, re.M).group(1)
    return lines, dict(re.findall(r"(\w+)=(\S+)", summary))


def median_of(line):
    return float(re.search(r"NEES median ([0-9.]+)", line).group(1))


@pytest.fixture(scope="module")
def honest(tmp_path_factory):
    return write_bags(tmp_path_factory.mktemp("honest"), honest=True)


def test_honest_covariances_read_the_chi_square(honest):
    lines, summary = evaluate(*honest)
    rotation = lines["rotation per pair"]
    direction = lines["translation direction per pair"]
    orientation = lines["orientation against the first frame"]
    assert abs(median_of(rotation) - 2.366) < 0.4, rotation
    assert "; 360 of 400 estimated pairs with a covariance" in rotation
    assert abs(median_of(direction) - 1.386) < 0.3, direction
    # Through base_link -> camera: the body's increment about odom's axes is the camera's.
    assert abs(median_of(orientation) - 2.366) < 0.4, orientation
    assert "; 400 of 400 poses with a covariance" in orientation
    assert "99.8 % of 401 odometry messages with a pose covariance, 49.9 % with a twist" \
        in orientation
    for key in ("nees_rot_pair", "nees_orient"):
        assert abs(float(summary[key]) - 2.366) < 0.4, summary
    for key in ("in95_rot_pair", "in95_orient"):
        assert abs(float(summary[key]) - 95.0) < 4.0, summary


def test_vp_observations_read_the_chi_square(honest):
    lines, _ = evaluate(*honest)
    line = lines["VP observation against the same direction's earlier one"]
    # Four directions, each compared every fifth message: 4 x 80.
    assert "; 320 of 320 sightings compared with a covariance" in line, line
    assert abs(median_of(line) - 1.386) < 0.25, line


def test_truth_noise_is_added(honest):
    # 5 degrees per axis of the truth's own noise dwarfs every error drawn here.
    lines, _ = evaluate(*honest, "--truth-rotation-sigma-deg", "5", "--truth-direction-sigma-deg",
                        "5", "--truth-orientation-sigma-deg", "5")
    assert len(lines) == 4, lines
    for what, line in lines.items():
        if what.startswith("VP observation"):  # two observations, no truth of their own
            continue
        assert "truth sigma 5 deg" in line, line
        assert median_of(line) < 0.3, line


def test_zero_covariances_are_missing(tmp_path):
    lines, summary = evaluate(*write_bags(tmp_path, honest=False))
    assert not any(what.startswith("VP observation") for what in lines), lines  # none recorded
    assert "NEES: none of 400 estimated pairs with a covariance" in lines["rotation per pair"]
    assert "NEES: none of 400 poses with a covariance; 0.0 % of 401 odometry messages" \
        in lines["orientation against the first frame"]
    for key in ("nees_rot_pair", "in95_rot_pair", "nees_orient", "in95_orient"):
        assert summary[key] == "nan", summary


@pytest.mark.parametrize("value", ["-1", "nan", "x"])
def test_bad_truth_sigma(honest, value):
    run = subprocess.run([str(TOOL), "--bag", str(honest[0]), "--gt", str(honest[1]),
                          "--truth-rotation-sigma-deg", value], capture_output=True, text=True)
    assert run.returncode == 2
    assert "--truth-rotation-sigma-deg: expected a number of degrees >= 0" in run.stderr
