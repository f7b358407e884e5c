"""hybrid_vo.match_image_pair (submodule hybrid_vo.frontend) on NumPy images: a textured image
and its shifted copy, drawn here without OpenCV; the lazy import; bad images."""
import os
import subprocess
import sys

import numpy as np
import pytest

import hybrid_vo

SHIFT = np.array([13.0, -6.0])  # image 2 = image 1 moved by this many pixels (x, y)
CAMERA = {"fx": 500.0, "fy": 500.0, "cx": 320.0, "cy": 240.0}


def textured_pair():
    """Blobs for SIFT and flat rectangles with straight edges for LSD, and the same picture
    shifted by SHIFT."""
    rng = np.random.default_rng(0)
    h, w, margin = 480, 640, 32
    canvas = np.kron(rng.uniform(0, 255, size=((h + 2 * margin) // 8, (w + 2 * margin) // 8)),
                     np.ones((8, 8)))
    # Smooth the block texture a little (3 passes of a 5-tap box filter per axis).
    for axis in (0, 1):
        for _ in range(3):
            canvas = sum(np.roll(canvas, k, axis) for k in range(-2, 3)) / 5.0
    for _ in range(12):
        y0, x0 = rng.integers(margin, h, size=1)[0], rng.integers(margin, w, size=1)[0]
        canvas[y0:y0 + rng.integers(40, 120), x0:x0 + rng.integers(40, 160)] = rng.uniform(0, 255)
    image1 = canvas[margin:margin + h, margin:margin + w]
    dx, dy = SHIFT.astype(int)
    image2 = canvas[margin - dy:margin - dy + h, margin - dx:margin - dx + w]
    return (np.ascontiguousarray(image1.astype(np.uint8)),
            np.ascontiguousarray(image2.astype(np.uint8)))


IMAGE1, IMAGE2 = textured_pair()


def test_matches_follow_the_shift():
    matches = hybrid_vo.match_image_pair(IMAGE1, IMAGE2, CAMERA)
    assert set(matches) == {"camera1", "camera2", "points1", "points2", "segments1", "segments2"}
    assert matches["camera1"]["width"] == 640 and matches["camera1"]["height"] == 480
    points1, points2 = matches["points1"], matches["points2"]
    assert len(points1) > 100 and points1.shape == points2.shape
    assert np.median(np.linalg.norm(points2 - points1 - SHIFT, axis=1)) < 0.5
    segments1, segments2 = matches["segments1"], matches["segments2"]
    assert len(segments1) > 10 and segments1.shape[1] == 4
    # Each matched segment lies on its partner's line once shifted back.
    d = segments2[:, 2:] - segments2[:, :2]
    normal = np.column_stack([-d[:, 1], d[:, 0]]) / np.linalg.norm(d, axis=1)[:, None]
    distance = np.abs(np.sum((segments1[:, :2] + SHIFT - segments2[:, :2]) * normal, axis=1))
    assert np.median(distance) < 1.0
    # The result is what the estimator takes.
    est = hybrid_vo.estimate_relative_pose(**matches, preset="5pc")
    assert est.status in ("ok", "no model", "degenerate")


def test_options_and_distortion():
    orb = hybrid_vo.match_image_pair(IMAGE1, IMAGE2, CAMERA, points="orb", lines="none",
                                     max_features=500)
    assert len(orb["points1"]) > 50 and orb["segments1"].shape == (0, 4)
    colour = np.ascontiguousarray(np.repeat(IMAGE1[:, :, None], 3, axis=2))
    assert len(hybrid_vo.match_image_pair(colour, IMAGE2, CAMERA, lines="fld")["points1"]) > 100
    distorted = hybrid_vo.match_image_pair(IMAGE1, IMAGE2, (500, 500, 320, 240, -0.2, 0, 0, 0, 0),
                                           lines="none")
    plain = hybrid_vo.match_image_pair(IMAGE1, IMAGE2, CAMERA, lines="none")
    # Undistortion moves points away from the centre (barrel distortion removed).
    centre = np.array([320.0, 240.0])
    r_distorted = np.linalg.norm(distorted["points1"] - centre, axis=1)
    r_plain = np.linalg.norm(plain["points1"] - centre, axis=1)
    assert np.median(r_distorted) > np.median(r_plain)


def test_bad_images_and_arguments():
    cases = [
        (dict(image1=IMAGE1.astype(np.float32)), "image1: dtype float32, expected uint8"),
        (dict(image1=IMAGE1[:, ::2]), "image1: not C-contiguous"),
        (dict(image2=np.zeros((10, 10, 2), np.uint8)), "image2: expected H x W"),
        (dict(image2=np.zeros((0, 10), np.uint8)), "image2: empty image"),
        (dict(image1=IMAGE1.tolist()), "image1: expected a NumPy uint8 image"),
        (dict(camera=(500, 500, 320)), "camera: 3 values"),
        (dict(camera={**CAMERA, "distortion": [0, 0, 0]}), "camera\\['distortion'\\]: shape"),
        (dict(points="surf"), "points: expected 'sift', 'orb' or 'none'"),
        (dict(lines="edlines"), "lines: expected 'lsd', 'fld' or 'none'"),
        (dict(max_features=0), "max_features: expected 1 .. 1000000"),
    ]
    for changes, message in cases:
        kwargs = {"image1": IMAGE1, "image2": IMAGE2, "camera": CAMERA, **changes}
        with pytest.raises(ValueError, match="^" + message):
            hybrid_vo.match_image_pair(**kwargs)


def test_opencv_is_loaded_only_by_the_front_end_and_cv2_never():
    code = (
        "import sys, hybrid_vo\n"
        "maps = lambda: open('/proc/self/maps').read()\n"
        "assert 'libopencv' not in maps(), 'import hybrid_vo loaded OpenCV'\n"
        "hybrid_vo.match_image_pair\n"
        "assert 'libopencv' in maps()\n"
        "assert 'cv2' not in sys.modules\n")
    subprocess.run([sys.executable, "-c", code], check=True, env=os.environ)
