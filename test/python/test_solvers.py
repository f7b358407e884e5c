"""The minimal solvers from Python: every solver's function (made from the solver table, with the
C++ argument order) on random instances of the C++ generator, against solve_minimal given the same
arrays by name (the code path of the hybrid RANSAC) and the ground truth, and on instances built
here in NumPy to pin down the conventions (X2 = R X1 + t, v2 = R v1)."""
import inspect

import numpy as np
import pytest

import hybrid_vo

SOLVERS = hybrid_vo.solvers()
IDS = [s["ascii_code"] for s in SOLVERS]
SEEDS = range(20)


def best_error_deg(poses, R, t):
    return min((max(hybrid_vo.pose_error_deg(Ri, ti, R, t)) for Ri, ti in poses), default=np.inf)


def dispatcher_inputs(inputs):
    """solve_minimal names the VP sign flag vp_signs_known for every solver."""
    kwargs = dict(inputs)
    if "vp_sign_known" in kwargs:
        kwargs["vp_signs_known"] = kwargs.pop("vp_sign_known")
    return kwargs


def assert_same_poses(a, b):
    assert len(a) == len(b)
    for (Ra, ta), (Rb, tb) in zip(a, b):
        np.testing.assert_array_equal(Ra, Rb)
        np.testing.assert_array_equal(ta, tb)


def assert_valid_poses(poses):
    for R, t in poses:
        assert R.shape == (3, 3) and t.shape == (3,)
        assert R.dtype == np.float64 and R.flags.c_contiguous
        np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-9)
        assert np.linalg.det(R) == pytest.approx(1.0, abs=1e-9)
        assert np.linalg.norm(t) == pytest.approx(1.0, abs=1e-9) or np.linalg.norm(t) == 0.0


def test_the_table_has_the_papers_thirteen_configurations():
    assert len(SOLVERS) == 13
    assert [s["code"] for s in SOLVERS][:3] == ["5-0-0", "4-0-0", "3-1-0"]
    assert [s["function"] for s in SOLVERS if not s["well_posed"]] == [
        "relpose_homography_2pt_2line"]


@pytest.mark.parametrize("info", SOLVERS, ids=IDS)
def test_every_solver_has_a_function_with_a_docstring(info):
    function = getattr(hybrid_vo, info["function"])
    assert str(inspect.signature(function)).startswith("(x1" if info["num_vps"] == 0 < info["num_points"] else "(")
    assert info["code"] in function.__doc__ and "(R, t)" in function.__doc__


@pytest.mark.parametrize("info", SOLVERS, ids=IDS)
def test_noiseless_instances_match_the_cpp_dispatcher_and_the_truth(info):
    function = getattr(hybrid_vo, info["function"])
    errors = []
    for seed in SEEDS:
        instance = hybrid_vo.synthetic.minimal_instance(info["function"], seed)
        poses = function(**instance["inputs"])
        assert_valid_poses(poses)
        assert_same_poses(poses, hybrid_vo.solve_minimal(info["code"],
                                                         **dispatcher_inputs(instance["inputs"])))
        if info["well_posed"]:
            errors.append(best_error_deg(poses, instance["R"], instance["t"]))
        else:
            assert poses == []  # 2-2-0 is degenerate for every input (doc/solvers.md)
    if info["well_posed"]:
        assert max(errors) < 1e-6, errors


@pytest.mark.parametrize("info", [s for s in SOLVERS if s["well_posed"]], ids=lambda s: s["ascii_code"])
def test_noisy_instances_match_the_cpp_dispatcher(info):
    function = getattr(hybrid_vo, info["function"])
    solved = 0
    for seed in SEEDS:
        instance = hybrid_vo.synthetic.minimal_instance(info["function"], seed, noise=1e-3,
                                                        lines_per_vp=3, orient_vps=True)
        poses = function(**instance["inputs"])
        assert_same_poses(poses, hybrid_vo.solve_minimal(info["function"],
                                                         **dispatcher_inputs(instance["inputs"])))
        solved += len(poses) > 0
    assert solved >= len(SEEDS) // 2  # not a comparison of empty lists


def test_lists_and_single_rows_are_accepted():
    instance = hybrid_vo.synthetic.minimal_instance("1-2-1p", seed=4)
    inputs = instance["inputs"]
    reference = hybrid_vo.relpose_1vp_2line_1pt(**inputs)
    as_lists = {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in inputs.items()}
    as_lists["x1"], as_lists["x2"] = as_lists["x1"][0], as_lists["x2"][0]  # (2,) for one point
    assert_same_poses(hybrid_vo.relpose_1vp_2line_1pt(**as_lists), reference)


# -- instances built in NumPy: the conventions, independently of the C++ generator -------------

def random_rotation(rng, max_angle):
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    angle = rng.uniform(0, max_angle)
    K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def two_view(rng, X1):
    """Camera 2 at a random pose; returns R, unit t and both projections of X1 (N x 3)."""
    R = random_rotation(rng, 0.3)
    t = rng.normal(size=3) * 0.5
    X2 = X1 @ R.T + t
    assert (X1[:, 2] > 0).all() and (X2[:, 2] > 0).all()
    return R, t / np.linalg.norm(t), X1[:, :2] / X1[:, 2:], X2[:, :2] / X2[:, 2:]


@pytest.mark.parametrize("seed", range(5))
def test_five_points_from_numpy(seed):
    rng = np.random.default_rng(seed)
    X = rng.normal(size=(5, 3)) + [0, 0, 6]
    R, t, x1, x2 = two_view(rng, X)
    assert best_error_deg(hybrid_vo.relpose_5pt(x1, x2), R, t) < 1e-6


@pytest.mark.parametrize("seed", range(5))
def test_homography_from_numpy(seed):
    rng = np.random.default_rng(seed)
    # Points on the plane z = 6 + 0.2 x.
    xy = rng.uniform(-2, 2, size=(4, 2))
    X = np.column_stack([xy, 6 + 0.2 * xy[:, 0]])
    R, t, x1, x2 = two_view(rng, X)
    assert best_error_deg(hybrid_vo.relpose_homography_4pt(x1, x2), R, t) < 1e-6


@pytest.mark.parametrize("seed", range(5))
def test_vp_solvers_from_numpy(seed):
    rng = np.random.default_rng(seed)
    X = rng.normal(size=(3, 3)) + [0, 0, 6]
    R, t, x1, x2 = two_view(rng, X)
    d = random_rotation(rng, np.pi)  # columns: two orthogonal directions of the scene
    v1 = np.ascontiguousarray(d[:, :2].T) * 3.0  # any scale
    v2 = np.ascontiguousarray((R @ d[:, :2]).T)
    assert best_error_deg(hybrid_vo.relpose_1vp_3pt(v1[0], v2[0], x1, x2, vp_sign_known=True),
                          R, t) < 1e-6
    assert best_error_deg(hybrid_vo.relpose_1vp_3pt(v1[0], -v2[0], x1, x2), R, t) < 1e-6
    assert best_error_deg(hybrid_vo.relpose_2vp_2pt(v1, v2, x1[:2], x2[:2]), R, t) < 1e-6
