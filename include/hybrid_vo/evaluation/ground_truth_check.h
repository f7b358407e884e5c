#pragma once

#include <vector>

#include "hybrid_vo/estimation/matches.h"
#include "hybrid_vo/geometry/camera.h"
#include "hybrid_vo/geometry/epipolar_error.h"
#include "hybrid_vo/geometry/pose.h"

namespace hybrid_vo {
namespace evaluation {

// How well a data set's ground truth can rank estimators: an estimator's point inliers should fit
// the true pose about as well as they fit its estimate. Where they fit the truth several times
// worse (TUM fr1: ground truth taken up to 17 ms off the images), a pose error of a few degrees
// is the ground truth's and differences of a few AUC points between methods are not the methods'.

// The median of sampson_error_px (geometry/epipolar_error.h) over the matches whose mask entry
// is set (all matches when the mask is empty). NaN when none, or when the mask's size differs
// from the matches'.
double median_sampson_px(const PinholeCamera& camera1, const PinholeCamera& camera2,
                         const RelativePose& pose, const std::vector<PointMatch>& matches,
                         const std::vector<char>& mask = {});

// A score without ground truth: how well a pose explains point matches it was not estimated
// from. The mean over `matches` of min(e, threshold)^2 / threshold^2, e = sampson_error_px: 0
// when every match lies on its epipolar line, 1 when none is within the threshold. A match whose
// error is not finite (a pose without translation, a non-finite match) counts 1. NaN when there
// are no matches or the threshold is not finite and positive.
double truncated_sampson_cost(const PinholeCamera& camera1, const PinholeCamera& camera2,
                              const RelativePose& pose, const std::vector<PointMatch>& matches,
                              double threshold_px);

}  // namespace evaluation
}  // namespace hybrid_vo
