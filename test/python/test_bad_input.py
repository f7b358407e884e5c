"""Malformed input raises ValueError naming the argument, in every function: wrong shapes,
NaN and infinity, non-contiguous arrays, wrong dtypes and types, bad cameras, presets and
options. Never a crash, never a silently misread array."""
import numpy as np
import pytest

import hybrid_vo

SCENE = hybrid_vo.synthetic.manhattan_scenes(1, seed=3, num_points=50, num_segments=40)[0]
INPUTS = SCENE["inputs"]
X5 = hybrid_vo.synthetic.minimal_instance("5-0-0", seed=1)["inputs"]["x1"]
VP = np.array([0.0, 1.0, 0.1])


def with_nan(a, index=(1, 1)):
    a = a.copy()
    a[index] = np.nan
    return a


def with_inf(a):
    a = a.copy()
    a.flat[0] = np.inf
    return a


# Bad values of an N x 2 array argument, and the word the message must contain.
BAD_POINTS = [
    ("nan", with_nan(X5), "not finite"),
    ("inf", with_inf(X5), "not finite"),
    ("too_few_rows", X5[:4].copy(), "shape"),
    ("three_columns", np.zeros((5, 3)), "shape"),
    ("flat", X5.ravel().copy(), "shape"),
    ("three_dims", X5[None].copy(), "shape"),
    ("column_view", np.zeros((5, 4))[:, :2], "C-contiguous"),
    ("fortran_order", np.asfortranarray(X5), "C-contiguous"),
    ("transpose", np.ascontiguousarray(X5.T).T, "C-contiguous"),
    ("reversed_rows", X5[::-1], "C-contiguous"),
    ("float32", X5.astype(np.float32), "float64"),
    ("int64", X5.astype(np.int64), "float64"),
    ("big_endian", X5.astype(">f8"), "float64"),
    ("complex", X5.astype(complex), "float64"),
    ("bool", X5 > 0, "float64"),
    ("object", X5.astype(object), "float64"),
    ("strings", [["a", "b"]] * 5, "numbers"),
    ("ragged_list", [[0.0, 1.0]] * 4 + [[0.0]], "array"),
    ("masked", np.ma.masked_array(X5, mask=X5 > 0), "masked"),
    ("none", None, "expected"),
    ("scalar", 3.0, "expected"),
    ("dict", {"x": 1}, "expected"),
]


@pytest.mark.parametrize("value,word", [c[1:] for c in BAD_POINTS], ids=[c[0] for c in BAD_POINTS])
def test_solver_point_arrays(value, word):
    with pytest.raises(ValueError, match=r"^x2: .*" + word):
        hybrid_vo.relpose_5pt(X5, value)


# The estimator takes any number of rows.
ESTIMATOR_BAD_POINTS = [c for c in BAD_POINTS if c[0] != "too_few_rows"]


@pytest.mark.parametrize("value,word", [c[1:] for c in ESTIMATOR_BAD_POINTS],
                         ids=[c[0] for c in ESTIMATOR_BAD_POINTS])
def test_estimator_point_arrays(value, word):
    points = INPUTS["points1"]
    if isinstance(value, np.ndarray) and value.shape[:1] == (5,):  # same rows as points2 below
        points = points[:5].copy()
    if value is None:
        word = "pass both or neither"
    with pytest.raises(ValueError, match=r"^points1: .*" + word):
        hybrid_vo.estimate_relative_pose(INPUTS["camera1"], INPUTS["camera2"], value, points)


def test_solver_segments_and_vps():
    inputs = hybrid_vo.synthetic.minimal_instance("2-1-1p", seed=2)["inputs"]
    f = hybrid_vo.relpose_1vp_orthline_2pt
    one_row = f(**{**inputs, "s1": inputs["s1"][0].copy(), "s2": inputs["s2"][0].copy()})
    np.testing.assert_array_equal([R for R, _ in f(**inputs)], [R for R, _ in one_row])
    cases = {
        "s1": [np.zeros((2, 4)), np.zeros(3), with_nan(inputs["s1"], (0, 2))],
        "v1": [np.zeros(3), np.zeros(2), np.zeros((2, 3)), [0, np.nan, 1], "up"],
        "vp_sign_known": [1, 0.0, "yes", None, np.array([True])],
    }
    for name, values in cases.items():
        for value in values:
            with pytest.raises(ValueError, match="^" + name + ": "):
                f(**{**inputs, name: value})
    with pytest.raises(ValueError, match="^v2: .*shape"):
        hybrid_vo.relpose_2vp_2pt(np.eye(3)[:2].copy(), VP, X5[:2].copy(), X5[:2].copy())


def test_solve_minimal_inputs():
    with pytest.raises(ValueError, match="^solver: unknown solver"):
        hybrid_vo.solve_minimal("6-0-0", x1=X5, x2=X5)
    with pytest.raises(ValueError, match="^x2: required"):
        hybrid_vo.solve_minimal("5-0-0", x1=X5)
    with pytest.raises(ValueError, match="^v1: relpose_5pt takes no VPs"):
        hybrid_vo.solve_minimal("5-0-0", x1=X5, x2=X5, v1=VP)


def estimate(**changes):
    return hybrid_vo.estimate_relative_pose(**{**INPUTS, **changes})


CAMERA_CASES = [
    ({"fx": 500.0, "fy": 500.0, "cx": 320.0}, "missing key 'cy'"),
    ({"fx": 500.0, "fy": 500.0, "cx": 320.0, "cy": 240.0, "f": 1.0}, "unknown key 'f'"),
    ({"fx": 500.0, "fy": 500.0, "cx": 320.0, "cy": 240.0, "distortion": [0] * 5},
     "undistorted"),
    ({"fx": 500.0, "fy": 500.0, "cx": np.nan, "cy": 240.0}, "finite"),
    ({"fx": 500.0, "fy": 500.0, "cx": 320.0, "cy": 240.0, "width": -1}, "size"),
    ({"fx": 500.0, "fy": 500.0, "cx": 320.0, "cy": 240.0, "width": 1.5}, "integer"),
    ((500.0, 500.0, 320.0), "3 values"),
    ((500.0, -500.0, 320.0, 240.0), "positive"),
    ((500.0, 0.0, 320.0, 240.0), "positive"),
    ((500.0, "500", 320.0, 240.0), "number"),
    ("pinhole", "expected a dict"),
    (None, "expected a dict"),
]


@pytest.mark.parametrize("camera,word", CAMERA_CASES, ids=[str(i) for i in range(len(CAMERA_CASES))])
def test_cameras(camera, word):
    with pytest.raises(ValueError, match=r"^camera2.*" + word):
        estimate(camera2=camera)
    with pytest.raises(ValueError, match=r"^camera.*" + word):
        hybrid_vo.detect_vanishing_points(camera, INPUTS["segments1"])


def test_estimator_matches():
    n = len(INPUTS["segments1"])
    k = len(INPUTS["vps"][0])
    cases = [
        (dict(points2=INPUTS["points2"][:-1]), "points2: 49 rows, but points1 has 50"),
        (dict(points2=None), "points2: None while points1 is given"),
        (dict(segments2=INPUTS["segments2"][:, :2].copy()), "segments2: shape"),
        (dict(segments1=with_nan(INPUTS["segments1"])), "segments1: .*not finite"),
        (dict(vps=INPUTS["vps"][0]), "vps: expected a pair"),
        (dict(vps=(INPUTS["vps"][0], INPUTS["vps"][1][:2])), r"vps\[1\]: 2 rows"),
        (dict(vps=(np.zeros((k, 3)), INPUTS["vps"][1])), r"vps\[0\]: direction 0 is zero"),
        (dict(line_vp=INPUTS["line_vp"][:-1]), f"line_vp: {n - 1} labels for {n} segments"),
        (dict(line_vp=np.full(n, k)), "line_vp: label .* is neither -1 nor a VP index"),
        (dict(line_vp=INPUTS["line_vp"].astype(float)), "line_vp: dtype float64"),
        (dict(line_vp=np.zeros((n, 2), int)), "line_vp: shape"),
        (dict(vps=None, vp_signs_known=None), "line_vp: .*needs segments1/2 and vps"),
        (dict(vps=None, line_vp=None), "vp_signs_known: given without vps"),
        (dict(vp_signs_known=[True]), f"vp_signs_known: 1 values for {k} VPs"),
        (dict(vp_signs_known="yes"), "vp_signs_known: expected a bool"),
        (dict(vp_signs_known=[1] * k), r"vp_signs_known\[0\]: expected True or False"),
    ]
    for changes, message in cases:
        with pytest.raises(ValueError, match="^" + message):
            estimate(**changes)


def test_presets_and_options():
    cases = [
        (dict(preset="6pc"), "preset: unknown preset '6pc' .*hybrid\\+junc"),
        (dict(preset=None), "preset: expected a preset name"),
        (dict(poin_threshold_px=1.0), "estimate_relative_pose: unknown option 'poin_threshold_px' "
                                      "\\(did you mean 'point_threshold_px'"),
        (dict(foo=1, bar=2), "estimate_relative_pose: unknown options 'foo', 'bar'"),
        (dict(ransac={"seed": 1}), "estimate_relative_pose: unknown option 'ransac'"),
        (dict(point_threshold_px=-1.0), "point_threshold_px: must be > 0"),
        (dict(point_threshold_px=np.nan), "point_threshold_px: expected a finite number"),
        (dict(point_threshold_px="1"), "point_threshold_px: expected a number"),
        (dict(point_threshold_px=True), "point_threshold_px: expected a number"),
        (dict(confidence=1.0), "confidence: must be in \\(0, 1\\)"),
        (dict(min_iterations=1.5), "min_iterations: expected an integer"),
        (dict(min_iterations=2**40), "min_iterations: integer out of range"),
        (dict(seed=-1), "seed: must be >= 0"),
        (dict(refinement_enabled=1), "refinement_enabled: expected True or False"),
        (dict(enabled={"relpose_6pt": True}), "enabled: unknown solver 'relpose_6pt'"),
        (dict(enabled={"5-0-0": 1}), "enabled\\['5-0-0'\\]: expected True or False"),
        (dict(enabled=[True] * 12), "enabled: 12 values, expected one per solver"),
        (dict(enabled=True), "enabled: expected a dict"),
        (dict(prior={"5-0-0": -1.0}), "prior\\['5-0-0'\\]: must be >= 0"),
        (dict(vp_detection_inlier_threshold_px=0), "vp_detection_inlier_threshold_px: must be"),
    ]
    for changes, message in cases:
        with pytest.raises(ValueError, match="^" + message):
            estimate(**changes)
    # Numpy scalars are numbers, and per-solver lists work.
    assert estimate(point_threshold_px=np.float32(1.5), min_iterations=np.int64(160),
                    enabled=[True] * 13, refinement_enabled=np.bool_(False)).ok


def test_vanishing_point_and_synthetic_arguments():
    c, s = INPUTS["camera1"], INPUTS["segments1"]
    with pytest.raises(ValueError, match="^segments: shape"):
        hybrid_vo.detect_vanishing_points(c, s[:, :3].copy())
    with pytest.raises(ValueError, match="^segments2: 39 rows, but segments1 has 40"):
        hybrid_vo.detect_vanishing_points(c, c, s, s[1:].copy())
    with pytest.raises(ValueError, match="^min_inliers: expected an integer"):
        hybrid_vo.detect_vanishing_points(c, s, min_inliers=2.5)
    with pytest.raises(ValueError, match="^count: must be >= 0"):
        hybrid_vo.synthetic.manhattan_scenes(-1)
    with pytest.raises(ValueError, match="^manhattan_scenes: unknown option 'points'"):
        hybrid_vo.synthetic.manhattan_scenes(1, points=10)
    with pytest.raises(ValueError, match="^seed: "):
        hybrid_vo.synthetic.minimal_instance("5-0-0", seed=-3)


GARBAGE = [None, 0, -1, 1e308, np.nan, "", "x", b"x", [], [[]], [None], {}, set(), object(),
           np.zeros(0), np.zeros((0, 2)), np.zeros((2, 0)), np.empty((3, 3, 3)), np.array(np.nan),
           np.zeros(5, dtype=[("a", float)]), np.zeros((5, 2))[::2], lambda: None]


@pytest.mark.parametrize("info", hybrid_vo.solvers(), ids=[s["ascii_code"] for s in hybrid_vo.solvers()])
def test_garbage_in_every_solver_argument_raises_value_error(info):
    inputs = hybrid_vo.synthetic.minimal_instance(info["function"], seed=0)["inputs"]
    f = getattr(hybrid_vo, info["function"])
    for name in inputs:
        for value in GARBAGE:
            if name.startswith("vp_sign") and value is None:
                continue
            with pytest.raises(ValueError, match="^" + name + ": "):
                f(**{**inputs, name: value})


def test_garbage_in_every_estimator_argument_raises_value_error():
    for name in INPUTS:
        for value in GARBAGE:
            if value is None and name not in ("camera1", "camera2"):
                continue  # None means "no such data"
            try:
                estimate(**{name: value})
            except ValueError as e:
                assert str(e).split(":")[0] in (name, "points1", "segments1", "line_vp",
                                                "vps[0]", "vps[1]") or name in str(e), str(e)
            else:
                # Only empty arrays of the right width are valid data.
                assert isinstance(value, np.ndarray) and value.shape == (0, 2), (name, value)
