"""estimate_relative_pose from Python on synthetic Manhattan scenes (the C++ generator): the
pose, the inlier masks against the scene's truth, the statistics, and that every option and
the VP detection in front reach the C++ estimator."""
import concurrent.futures

import warnings

import numpy as np
import pytest

import hybrid_vo

SCENES = hybrid_vo.synthetic.manhattan_scenes(3, seed=11, num_points=500,
                                              point_outlier_ratio=0.3, line_outlier_ratio=0.3)
VP_SOLVERS = [s["function"] for s in hybrid_vo.solvers() if s["num_vps"] > 0]


def without_vps(inputs):
    return {k: v for k, v in inputs.items() if k not in ("vps", "line_vp", "vp_signs_known")}


def angle_deg(a, b):
    """Angle between two directions of either sign."""
    c = abs(np.dot(a, b)) / np.linalg.norm(a) / np.linalg.norm(b)
    return np.degrees(np.arccos(min(c, 1.0)))


@pytest.mark.parametrize("preset", hybrid_vo.presets())
def test_pose_and_inliers_of_synthetic_scenes(preset):
    for scene in SCENES:
        inputs = scene["inputs"]
        est = hybrid_vo.estimate_relative_pose(**inputs, preset=preset, seed=1)
        assert est.ok and est.status == "ok", est
        rotation, translation = hybrid_vo.pose_error_deg(est.R, est.t, scene["R"], scene["t"])
        assert rotation < 0.3 and translation < 1.5, (rotation, translation)
        assert np.linalg.norm(est.t) == pytest.approx(1.0)

        truth = scene["point_inlier"]
        mask = est.point_inliers
        assert mask.dtype == bool and mask.shape == (len(inputs["points1"]),)
        assert mask[truth].mean() > 0.9            # recall
        assert mask[~truth].mean() < 0.05          # random outliers rarely pass 1 px
        assert est.num_point_inliers == mask.sum()
        assert est.line_inliers.shape == (len(inputs["segments1"]),)
        assert est.vp_inliers.shape == (3,)
        assert est.junction_inliers.shape == (len(est.junctions),)
        assert est.junction_segments.shape == (len(est.junctions), 2)
        assert (est.junction_segments >= 0).all()
        assert (est.junction_segments < len(inputs["segments1"])).all()

        stats = est.solver_statistics
        assert set(stats) == {s["function"] for s in hybrid_vo.solvers()}
        assert sum(s["sampled"] for s in stats.values()) == est.iterations
        assert stats[est.best_solver]["best"] >= 1
        if preset.startswith("5pc"):
            assert all(stats[f]["sampled"] == 0 for f in VP_SOLVERS)
        else:
            assert est.vp_inliers.all()  # the scene's VPs are exact
            assert sum(stats[f]["sampled"] for f in VP_SOLVERS) > 0

        cov = est.covariance
        assert cov.shape == (6, 6) and np.allclose(cov, cov.T)
        assert np.linalg.eigvalsh(cov).min() > -1e-12
        assert set(est.timings) == {"vp_detection_ms", "derive_ms", "ransac_ms", "refine_ms",
                                    "estimator_ms", "total_ms"}
        assert est.timings["total_ms"] > 0


def test_the_same_seed_gives_the_same_estimate():
    inputs = SCENES[0]["inputs"]
    a = hybrid_vo.estimate_relative_pose(**inputs, seed=5)
    b = hybrid_vo.estimate_relative_pose(**inputs, seed=5)
    np.testing.assert_array_equal(a.R, b.R)
    np.testing.assert_array_equal(a.point_inliers, b.point_inliers)
    assert a.solver_statistics == b.solver_statistics


def test_the_gil_is_released_and_threads_give_the_same_results():
    inputs = SCENES[1]["inputs"]
    expected = [hybrid_vo.estimate_relative_pose(**inputs, seed=s).R for s in range(4)]
    with concurrent.futures.ThreadPoolExecutor(2) as pool:
        got = list(pool.map(lambda s: hybrid_vo.estimate_relative_pose(**inputs, seed=s).R,
                            range(4)))
    for a, b in zip(expected, got):
        np.testing.assert_array_equal(a, b)


def test_vps_are_detected_when_not_given():
    scene = SCENES[2]
    est = hybrid_vo.estimate_relative_pose(**without_vps(scene["inputs"]), preset="hybrid")
    assert est.ok and est.vps_detected
    directions1, directions2 = est.vps
    assert len(directions1) >= 2 and directions1.shape == directions2.shape
    for d1, d2 in zip(directions1, directions2):
        assert min(angle_deg(d1, m) for m in scene["directions"].T) < 1.0
        assert angle_deg(scene["R"] @ d1, d2) < 1.0
    labels = est.line_vp
    assert labels.shape == (len(scene["inputs"]["segments1"]),)
    assert labels.max() < len(directions1) and (labels >= 0).sum() > 30
    rotation, translation = hybrid_vo.pose_error_deg(est.R, est.t, scene["R"], scene["t"])
    assert rotation < 0.3 and translation < 1.5
    # Without detection the VP solvers have nothing to draw.
    est = hybrid_vo.estimate_relative_pose(**without_vps(scene["inputs"]), preset="hybrid",
                                           detect_vps=False)
    assert not est.vps_detected and len(est.vps[0]) == 0
    assert all(est.solver_statistics[f]["sampled"] == 0 for f in VP_SOLVERS)


def test_options_reach_the_estimator():
    inputs = SCENES[0]["inputs"]
    est = hybrid_vo.estimate_relative_pose(**inputs, preset="hybrid",
                                           enabled={"relpose_5pt": False, "2-0-2": False})
    assert est.solver_statistics["relpose_5pt"]["sampled"] == 0
    assert est.solver_statistics["relpose_2vp_2pt"]["sampled"] == 0
    assert est.solver_statistics["relpose_1vp_3pt"]["sampled"] > 0
    est = hybrid_vo.estimate_relative_pose(**inputs, min_iterations=400, refinement_enabled=False)
    assert est.iterations >= 400 and not est.refined and est.covariance is None
    loose = hybrid_vo.estimate_relative_pose(**inputs, point_threshold_px=5.0)
    tight = hybrid_vo.estimate_relative_pose(**inputs, point_threshold_px=0.3)
    assert loose.num_point_inliers > tight.num_point_inliers
    assert len(hybrid_vo.estimate_relative_pose(**inputs, use_junction_points=False,
                                                junctions_min_angle_deg=80.0).junctions) < \
        len(hybrid_vo.estimate_relative_pose(**inputs).junctions)


def test_a_renamed_option_still_works_with_a_deprecation_warning():
    # final_refinement became refinement_enabled when the options were flattened (issue 33).
    inputs = SCENES[0]["inputs"]
    with pytest.warns(DeprecationWarning, match="'final_refinement' is deprecated, use "
                                                "'refinement_enabled'"):
        old = hybrid_vo.estimate_relative_pose(**inputs, seed=3, final_refinement=False)
    new = hybrid_vo.estimate_relative_pose(**inputs, seed=3, refinement_enabled=False)
    assert not old.refined and not new.refined
    assert np.array_equal(old.R, new.R) and np.array_equal(old.t, new.t)
    assert "final_refinement" not in hybrid_vo.estimator_options()
    assert hybrid_vo.estimator_options()["refinement_enabled"] is True
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the warning is an error where the caller asks for it
        with pytest.raises(DeprecationWarning):
            hybrid_vo.estimate_relative_pose(**inputs, final_refinement=True)


@pytest.mark.parametrize("preset", ["5pc", "hybrid+junc"])
def test_every_option_takes_its_own_default(preset):
    """The table's getters and setters agree: passing every option at its preset value changes
    nothing."""
    inputs = SCENES[0]["inputs"]
    options = hybrid_vo.estimator_options(preset)
    assert "point_threshold_px" in options and "vp_detection_min_inliers" in options
    a = hybrid_vo.estimate_relative_pose(**inputs, preset=preset)
    b = hybrid_vo.estimate_relative_pose(**inputs, preset=preset, **options)
    np.testing.assert_array_equal(a.R, b.R)
    assert a.solver_statistics == b.solver_statistics


def test_too_little_data_gives_a_status_and_no_pose():
    inputs = SCENES[0]["inputs"]
    est = hybrid_vo.estimate_relative_pose(inputs["camera1"], inputs["camera2"],
                                           inputs["points1"][:3], inputs["points2"][:3])
    assert not est.ok and est.status == "too little data"
    assert est.R is None and est.t is None and est.covariance is None
    assert est.best_solver is None
    assert est.point_inliers.shape == (3,) and not est.point_inliers.any()


def test_zero_length_segments_are_counted_not_used():
    inputs = dict(SCENES[0]["inputs"])
    segments1 = inputs["segments1"].copy()
    segments1[0, 2:] = segments1[0, :2]
    inputs["segments1"] = segments1
    est = hybrid_vo.estimate_relative_pose(**inputs)
    assert est.ok and est.rejected == {"points": 0, "lines": 1, "vps": 0}


def test_sampson_errors_rank_the_truth_and_score_held_out_matches():
    scene = hybrid_vo.synthetic.manhattan_scenes(1, seed=5, num_points=400, noise_px=0.5,
                                                 point_outlier_ratio=0.2)[0]
    inputs = scene["inputs"]
    inlier = scene["point_inlier"]
    args = (inputs["camera1"], inputs["camera2"])
    truth = hybrid_vo.sampson_errors_px(*args, scene["R"], scene["t"], inputs["points1"],
                                        inputs["points2"])
    assert truth.shape == (len(inlier),) and truth.dtype == np.float64
    # Inliers carry 0.5 px of noise; random outliers are far off their epipolar lines.
    assert 0.1 < np.median(truth[inlier]) < 0.6
    assert np.median(truth[~inlier]) > 5.0
    # Estimated on half the matches, the pose explains the other half about as well as the truth.
    half = np.arange(len(inlier)) % 2 == 0
    est = hybrid_vo.estimate_relative_pose(
        *args, np.ascontiguousarray(inputs["points1"][half]),
        np.ascontiguousarray(inputs["points2"][half]), seed=2)
    held_out = hybrid_vo.sampson_errors_px(*args, est.R, est.t, inputs["points1"][~half],
                                           inputs["points2"][~half])
    assert np.median(held_out[inlier[~half]]) < 1.2 * np.median(truth[inlier & ~half])
    # A rotation 2 degrees off does not.
    c, s = np.cos(np.radians(2.0)), np.sin(np.radians(2.0))
    off = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]]) @ scene["R"]
    wrong = hybrid_vo.sampson_errors_px(*args, off, scene["t"], inputs["points1"],
                                        inputs["points2"])
    assert np.median(wrong[inlier]) > 5.0 * np.median(truth[inlier])
    # No translation: no epipolar geometry.
    assert np.isnan(hybrid_vo.sampson_errors_px(*args, scene["R"], np.zeros(3),
                                                inputs["points1"], inputs["points2"])).all()
    with pytest.raises(ValueError, match="points2"):
        hybrid_vo.sampson_errors_px(*args, scene["R"], scene["t"], inputs["points1"],
                                    inputs["points2"][:-1])
    with pytest.raises(ValueError, match="R"):
        hybrid_vo.sampson_errors_px(*args, np.eye(2), scene["t"], inputs["points1"],
                                    inputs["points2"])
