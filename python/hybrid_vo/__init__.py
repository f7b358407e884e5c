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

import sys as _sys

from . import _core
from ._core import (  # noqa: F401  (re-exported)
    RelativePoseEstimate,
    estimate_relative_pose,
    estimator_options,
    pose_error_deg,
    presets,
    relpose_1vp_2line_1pt,
    relpose_1vp_2pt_orth,
    relpose_1vp_3line,
    relpose_1vp_3pt,
    relpose_1vp_orthline_2pt,
    relpose_2pt_3line,
    relpose_2vp_2pt,
    relpose_5pt,
    relpose_homography_1pt_3line,
    relpose_homography_2pt_2line,
    relpose_homography_3pt_1line,
    relpose_homography_4line,
    relpose_homography_4pt,
    sampson_errors_px,
    solve_minimal,
    solvers,
    synthetic,
    vp_detection_options,
)

# The generators live in the extension as a submodule; make `import hybrid_vo.synthetic` work.
_sys.modules[__name__ + ".synthetic"] = synthetic


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
        return _core._detect_vanishing_points_single(given["camera"], given["segments"], **options)
    if set(given) == set(names2):
        return _core._detect_vanishing_points_two_view(
            given["camera1"], given["camera2"], given["segments1"], given["segments2"], mode,
            **options)
    raise TypeError(
        "detect_vanishing_points takes (camera, segments) or "
        f"(camera1, camera2, segments1, segments2); got {sorted(given)}")


def __getattr__(name):
    # The front end links OpenCV: load it only when asked for.
    if name == "match_image_pair":
        from .frontend import match_image_pair
        return match_image_pair
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = [
    "RelativePoseEstimate", "detect_vanishing_points", "estimate_relative_pose",
    "estimator_options", "match_image_pair", "pose_error_deg", "presets",
    "relpose_1vp_2line_1pt", "relpose_1vp_2pt_orth", "relpose_1vp_3line", "relpose_1vp_3pt",
    "relpose_1vp_orthline_2pt", "relpose_2pt_3line", "relpose_2vp_2pt", "relpose_5pt",
    "relpose_homography_1pt_3line", "relpose_homography_2pt_2line",
    "relpose_homography_3pt_1line", "relpose_homography_4line", "relpose_homography_4pt",
    "sampson_errors_px", "solve_minimal", "solvers", "synthetic", "vp_detection_options",
]
