"""detect_vanishing_points from Python: the single-image mode and the two-view modes (joint and
the per-image standard baseline) on the segments of synthetic Manhattan scenes."""
import numpy as np
import pytest

import hybrid_vo

SCENE = hybrid_vo.synthetic.manhattan_scenes(1, seed=21, num_segments=200,
                                             line_outlier_ratio=0.2)[0]
INPUTS = SCENE["inputs"]


def angle_deg(a, b):
    c = abs(np.dot(a, b)) / np.linalg.norm(a) / np.linalg.norm(b)
    return np.degrees(np.arccos(min(c, 1.0)))


def closest_direction_deg(d, directions):
    return min(angle_deg(d, m) for m in directions.T)


def test_single_image():
    vps = hybrid_vo.detect_vanishing_points(INPUTS["camera1"], INPUTS["segments1"])
    directions = vps["directions"]
    assert directions.shape[1] == 3 and len(directions) >= 3
    for d in directions[:3]:
        assert closest_direction_deg(d, SCENE["directions"]) < 1.0
        assert np.linalg.norm(d) == pytest.approx(1.0)
    labels = vps["labels"]
    assert labels.shape == (len(INPUTS["segments1"]),)
    for k, inliers in enumerate(vps["inliers"]):
        assert (labels[inliers] == k).all()
    assert (np.diff(vps["scores"]) <= 0).all()  # strongest first
    # Most labelled inlier segments carry their true direction's VP.
    true_direction = SCENE["line_direction"]
    inlier = SCENE["line_inlier"] & (labels >= 0)
    first = [int(np.argmin([angle_deg(d, m) for m in SCENE["directions"].T])) for d in directions]
    assert np.mean([first[labels[i]] == true_direction[i] for i in np.flatnonzero(inlier)]) > 0.9


@pytest.mark.parametrize("mode", ["joint", "standard"])
def test_two_views(mode):
    vps = hybrid_vo.detect_vanishing_points(INPUTS["camera1"], INPUTS["camera2"],
                                            INPUTS["segments1"], INPUTS["segments2"], mode=mode)
    directions1, directions2 = vps["vps"]
    assert len(directions1) >= 3 and directions1.shape == directions2.shape
    for d1, d2 in zip(directions1[:3], directions2[:3]):
        assert closest_direction_deg(d1, SCENE["directions"]) < 1.0
        assert angle_deg(SCENE["R"] @ d1, d2) < 1.0
    assert vps["line_vp"].shape == (len(INPUTS["segments1"]),)
    assert vps["vp_signs_known"].shape == (len(directions1),)
    # The output feeds the estimator as it is.
    est = hybrid_vo.estimate_relative_pose(**{k: INPUTS[k] for k in (
        "camera1", "camera2", "points1", "points2", "segments1", "segments2")},
        vps=vps["vps"], line_vp=vps["line_vp"], vp_signs_known=vps["vp_signs_known"],
        preset="hybrid")
    assert est.ok and not est.vps_detected and est.vp_inliers.sum() >= 3


def test_options_and_keywords():
    all_vps = hybrid_vo.detect_vanishing_points(camera=INPUTS["camera1"],
                                                segments=INPUTS["segments1"])
    two = hybrid_vo.detect_vanishing_points(INPUTS["camera1"], INPUTS["segments1"], max_vps=2)
    assert len(two["directions"]) == 2
    np.testing.assert_allclose(two["directions"], all_vps["directions"][:2])
    assert set(hybrid_vo.vp_detection_options()) >= {"inlier_threshold_px", "max_vps", "seed"}
    with pytest.raises(ValueError, match="max_vp"):
        hybrid_vo.detect_vanishing_points(INPUTS["camera1"], INPUTS["segments1"], max_vp=2)
    with pytest.raises(ValueError, match="mode"):
        hybrid_vo.detect_vanishing_points(INPUTS["camera1"], INPUTS["camera2"],
                                          INPUTS["segments1"], INPUTS["segments2"], mode="both")
    with pytest.raises(TypeError):
        hybrid_vo.detect_vanishing_points(INPUTS["camera1"])
