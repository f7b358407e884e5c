"""Two-view relative pose from points, line segments, junctions and vanishing points.

Python bindings of the hybrid_vo core library (after "Handbook on Leveraging Lines for
Two-View Relative Pose Estimation", Hruby et al., 3DV 2024):

- the minimal solvers, one function each (relpose_5pt, relpose_homography_4pt, ...,
  relpose_1vp_2pt_orth; solvers() lists them), and solve_minimal by name or paper code;
- estimate_relative_pose, the hybrid RANSAC with Ceres refinement;
- detect_vanishing_points, in one image or jointly in two;
- match_image_pair, the OpenCV front end on NumPy images (submodule hybrid_vo.frontend,
  loaded on first use);
- hybrid_vo.synthetic, the C++ generators of minimal problems and Manhattan scenes;
- pose_error_deg against a true pose, and sampson_errors_px: how well a pose explains point
  matches (with the truth: how good the ground truth is; on held-out matches: a score of an
  estimate without ground truth).

Conventions: X2 = R X1 + t with unit t; solvers take normalised coordinates (K^-1 x), the
estimator pixels; segments are their endpoints (x1, y1, x2, y2); VPs are directions K^-1 v.
Arrays are float64 and C-contiguous; malformed input raises ValueError naming the argument.
"""

import inspect as _inspect
import sys as _sys

from . import _core
from ._core import (  # noqa: F401  (re-exported)
    estimator_options,
    pose_error_deg,
    presets,
    sampson_errors_px,
    solvers,
    synthetic,
    vp_detection_options,
)

# What each solver does beyond its inputs (solvers() has those), for its docstring.
_SOLVER_DETAILS = {
    "5-0-0": "Nister's five-point essential matrix, decomposed.",
    "4-0-0": "Homography by DLT from coplanar points, decomposed.",
    "3-1-0": "Points and segment on one plane; lines map as l1 ~ H^T l2.",
    "2-2-0": "Degenerate for every input (a one-parameter family of homographies fits; "
             "doc/solvers.md): it always returns an empty list, and is listed for completeness.",
    "1-3-0": "Point and segments on one plane; homography by DLT.",
    "0-4-0": "Four coplanar segments; homography by DLT.",
    "2-3-0": "The three junctions of the coplanar segments complete five points.",
    "3-0-1": "Upright three-point after rotating the VP onto the y-axis.",
    "0-3-1": "Coplanar segments, whose junctions are the points of 3-0-1.",
    "2-0-2": "Rotation from the two VPs (row k of v1 matches row k of v2).",
    "2-1-1p": "The segment's 3D line is orthogonal to the VP.",
    "1-2-1p": "Intersecting segments, the first orthogonal to the VP.",
    "2-0-1p": "The points' 3D line is orthogonal to the VP.",
}


def _solver_function(info):
    """The solver's own function, with the C++ name and argument order (VPs, segments, points for
    the VP solvers; points, then segments for the others), run by the C++ dispatcher."""
    vps, lines, points = info["num_vps"], info["num_lines"], info["num_points"]
    names = (["v1", "v2"] * (vps > 0) + ["x1", "x2"] * (vps == 0 < points)
             + ["s1", "s2"] * (lines > 0) + ["x1", "x2"] * (vps > 0 < points))
    sign = {0: None, 1: "vp_sign_known", 2: "vp_signs_known"}[vps]
    P = _inspect.Parameter
    signature = _inspect.Signature([P(n, P.POSITIONAL_OR_KEYWORD) for n in names] + (
        [P(sign, P.POSITIONAL_OR_KEYWORD, default=False)] if sign else []))

    def solver(*args, **kwargs):
        given = signature.bind(*args, **kwargs).arguments
        known = given.pop(sign, False) if sign else False
        return _core._solve(info["function"], sign or "", known, **given)

    solver.__name__ = solver.__qualname__ = info["function"]
    solver.__signature__ = signature
    solver.__doc__ = (
        f"{info['code']}: {info['inputs']} (paper Fig. 2). {_SOLVER_DETAILS[info['ascii_code']]}\n"
        + (f"With {sign}, v2 = +R v1; otherwise the sign v2 = -R v1 is tried too.\n" if sign else "")
        + "Points are normalised image coordinates (K^-1 x) as N x 2 float64 arrays, segments their "
        "two endpoints\nas N x 4 (x1, y1, x2, y2), VPs directions (K^-1 v, any scale) as 3-vectors "
        "(N x 3 for two); a\nsingle point or segment may be 1-D. Returns a list of (R, t) with "
        "X2 = R X1 + t and unit t (t = 0\nfor a pure rotation), every real solution with all points "
        "and segments in front of both cameras;\nan empty list for degenerate input. Raises "
        "ValueError for wrong shapes, dtypes, strides or\nnon-finite values.")
    return solver


for _info in solvers():
    globals()[_info["function"]] = _solver_function(_info)


def solve_minimal(solver, x1=None, x2=None, s1=None, s2=None, v1=None, v2=None,
                  vp_signs_known=False):
    """Runs the minimal solver `solver` (function name such as 'relpose_1vp_3pt', or paper code
    such as '3-0-1' or '2-1-1p') through the C++ dispatcher that the hybrid RANSAC uses. Pass
    exactly the inputs the solver takes (hybrid_vo.solvers() lists them): x1, x2 as num_points x 2,
    s1, s2 as num_lines x 4, v1, v2 as num_vps x 3 (or a 3-vector for one VP); None is not given.
    Returns a list of (R, t) like the solver's own function."""
    arrays = {"x1": x1, "x2": x2, "s1": s1, "s2": s2, "v1": v1, "v2": v2}
    return _core._solve(solver, "vp_signs_known", vp_signs_known,
                        **{name: a for name, a in arrays.items() if a is not None})

# The generators live in the extension as a submodule; make `import hybrid_vo.synthetic` work.
_sys.modules[__name__ + ".synthetic"] = synthetic


class RelativePoseEstimate:
    """Result of estimate_relative_pose. The pose maps camera-1 to camera-2 coordinates,
    X2 = R X1 + t, with unit t. Masks are NumPy bool arrays aligned with the inputs."""

    __slots__ = ("_fields",)

    def __init__(self, fields):
        self._fields = fields

    def __repr__(self):
        f = self._fields
        return (f"<RelativePoseEstimate status='{f['status']}': {f['num_point_inliers']} point, "
                f"{f['num_junction_inliers']} junction, {f['num_line_inliers']} line, "
                f"{f['num_vp_inliers']} VP inliers; best solver {f['best_solver'] or '-'}; "
                f"{f['iterations']} iterations; {f['timings']['total_ms']:.2f} ms>")


# The result's fields, each a read-only property with its docstring.
_ESTIMATE_FIELDS = {
    "status": "'ok', 'invalid input', 'too little data', 'degenerate' or 'no model'.",
    "ok": "status == 'ok'.",
    "R": "3 x 3 rotation, or None when status is not 'ok'.",
    "t": "Unit translation (3,), or None when status is not 'ok'.",
    "covariance": "6 x 6 covariance of [w, t] after the final refinement: w (radians) the left "
                  "rotation increment R <- exp([w]x) R, t the unit translation (rank 5). None "
                  "when not available.",
    "point_inliers": "Per point match (points1/points2).",
    "line_inliers": "Per segment match: it meets another at an inlier junction, or agrees with "
                    "the rotation through its VP.",
    "vp_inliers": "Per VP match (given, or detected: see vps).",
    "junction_inliers": "Per junction (see junctions).",
    "endpoint_inliers": "Per segment endpoint match (see endpoints).",
    "num_point_inliers": "Number of point inliers.",
    "num_line_inliers": "Number of line inliers.",
    "num_vp_inliers": "Number of VP inliers.",
    "num_junction_inliers": "Number of junction inliers.",
    "num_endpoint_inliers": "Number of endpoint inliers.",
    "junctions": "J x 4 junction matches in pixels (x1, y1, x2, y2), from segment pairs that "
                 "intersect in both images.",
    "junction_segments": "J x 2: the two segment matches of each junction.",
    "endpoints": "E x 4 endpoint matches in pixels (only with use_endpoint_points).",
    "endpoint_segments": "E x 2: segment index and which end (0 or 1).",
    "vps": "(directions1, directions2): the K x 3 VP matches used, given or detected.",
    "vp_signs_known": "Per VP match: d2 = +R d1 known (else +-R d1).",
    "line_vp": "Per segment match: index of its VP in vps, or -1 (empty without labels).",
    "vps_detected": "True when the VPs were detected from the segments.",
    "solver_statistics": "Per solver (function name): its paper code, how often it was drawn "
                         "('sampled'), poses it produced ('models') and how often one became "
                         "the best model ('best').",
    "best_solver": "Function name of the solver behind the best model, or None.",
    "iterations": "RANSAC iterations.",
    "local_optimizations": "Local optimisations of new best models.",
    "refined": "True when the final Ceres refinement was kept.",
    "rejected": "Inputs skipped as invalid (zero-length segments, ...), per modality.",
    "timings": "Milliseconds: VP detection, derived data (junctions), RANSAC, final refinement, "
               "the whole estimator, and VP detection plus estimator.",
}
for _name, _doc in _ESTIMATE_FIELDS.items():
    setattr(RelativePoseEstimate, _name,
            property(lambda self, _name=_name: self._fields[_name], doc=_doc))


def estimate_relative_pose(camera1, camera2, points1, points2, segments1=None, segments2=None,
                           vps=None, preset="hybrid+junc", *, line_vp=None, vp_signs_known=None,
                           **options):
    """Relative pose between two calibrated views from point, segment and VP matches: the hybrid
    RANSAC over the minimal solvers with Ceres refinement (paper Sec. 4), with VP detection in
    front when segments but no VPs are given and a VP solver is enabled.

    camera1, camera2: {'fx', 'fy', 'cx', 'cy'[, 'width', 'height']} or (fx, fy, cx, cy).
    points1, points2: N x 2 undistorted pixels (float64, C-contiguous), row i of each a match;
        None for none.
    segments1, segments2: M x 4 segment matches in pixels (x1, y1, x2, y2); endpoints need not
        correspond.
    vps: (directions1, directions2), K x 3 VP matches as directions K^-1 v (any scale, either
        sign). None: detected from the segments (joint two-view detection) when a VP solver is
        enabled.
    preset: '5pc', '5pc+junc', '5pc+4pc', '5pc+4pc+junc', 'hybrid' or 'hybrid+junc' (the
        paper's rows); the options below override it.
    line_vp: per segment match, the index of its VP in vps or -1 (labels for the refinement).
    vp_signs_known: bool, or one per VP: d2 = +R d1 is known (else both signs are tried).
    **options: the estimator's option fields by name, e.g. point_threshold_px=1.0, seed=0,
        min_iterations=150, enabled={'relpose_2vp_2pt': False}; estimator_options() lists every
        name with its default. Unknown names raise ValueError; renamed ones (final_refinement:
        refinement_enabled) still work, with a DeprecationWarning.

    Returns a RelativePoseEstimate: R, t (None unless status == 'ok'), covariance, inlier masks
    per modality, junctions, the VPs used, per-solver statistics, iterations and timings.
    Raises ValueError for malformed input (shapes, dtypes, strides, NaN, unknown options); data
    the estimator cannot use gives a status instead.
    """
    return RelativePoseEstimate(_core._estimate_relative_pose(
        camera1, camera2, points1, points2, segments1, segments2, vps, preset, line_vp,
        vp_signs_known, options))


def detect_vanishing_points(*args, mode="joint", **options):
    """Vanishing points of line segments, in one image or jointly in two (paper Sec. 3).

    detect_vanishing_points(camera, segments, **options)
        Single image: sequential RANSAC on 2-segment samples, merging, refinement. Returns a
        dict with 'directions' (K x 3 unit directions K^-1 v, strongest first), 'labels' (per
        segment its VP or -1), 'inliers' (per VP its segment indices) and 'scores' (summed
        segment length in pixels).

    detect_vanishing_points(camera1, camera2, segments1, segments2, mode="joint", **options)
        Two views, on segment matches (row i of segments1 matches row i of segments2).
        mode="joint" detects and matches at once (a VP's segments must agree in both images);
        mode="standard" detects in each image and matches the VPs by their segment matches
        (the baseline). Returns a dict with 'vps' (directions1, directions2: K x 3 each),
        'vp_signs_known', 'line_vp' (per match its VP or -1), 'inliers' and 'scores': 'vps',
        'line_vp' and 'vp_signs_known' are keyword arguments of estimate_relative_pose.

    Cameras are {'fx', 'fy', 'cx', 'cy'} dicts or (fx, fy, cx, cy); segments M x 4 pixels
    (x1, y1, x2, y2). Options are the fields of VpDetectionOptions (vp_detection_options()
    lists them with their defaults), e.g. inlier_threshold_px=2.0, min_inliers=6, max_vps=4,
    manhattan=False, seed=0. Raises ValueError for malformed input or unknown options.
    """
    names1 = ("camera", "segments")
    names2 = ("camera1", "camera2", "segments1", "segments2")
    two_view = len(args) > 2 or any(name in options for name in names2)
    given = dict(zip(names2 if two_view else names1, args))
    for name in names1 + names2:
        if name in options:
            if name in given:
                raise TypeError(f"detect_vanishing_points: {name} given twice")
            given[name] = options.pop(name)
    if set(given) == set(names1):
        if mode != "joint":
            raise ValueError("mode: only for two views (camera1, camera2, segments1, segments2)")
        return _core._detect_vanishing_points(given["camera"], given["segments"], None, None, mode,
                                              options)
    if set(given) == set(names2):
        return _core._detect_vanishing_points(given["camera1"], given["segments1"],
                                              given["camera2"], given["segments2"], mode, options)
    raise TypeError(
        "detect_vanishing_points takes (camera, segments) or "
        f"(camera1, camera2, segments1, segments2); got {sorted(given)}")


def __getattr__(name):
    # The front end links OpenCV: load it only when asked for.
    if name == "match_image_pair":
        from .frontend import match_image_pair
        return match_image_pair
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
