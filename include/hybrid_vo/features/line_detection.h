#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "hybrid_vo/features/gray_image.h"
#include "hybrid_vo/geometry/homogeneous.h"

namespace hybrid_vo {

enum class LineDetector {
  kLsd,  // cv::createLineSegmentDetector (von Gioi et al.), the paper's detector family
  kFld,  // cv::ximgproc::createFastLineDetector (Lee et al.), faster, fewer short segments
};

// The detectors' fixed gradient thresholds, in grey levels per pixel: LSD's rho = quant /
// sin(22.5 deg) with quant 2, and FLD's Canny thresholds of 50 on the L1 Sobel response, about
// 8 times the gradient.
constexpr double kLsdDefaultGradient = 5.226;
constexpr double kFldDefaultGradient = 6.25;

struct LineDetectionOptions {
  LineDetector detector = LineDetector::kLsd;
  double min_length_px = 20.0;  // shorter segments carry little direction and match poorly
  int max_segments = 0;         // keep only the longest ones; 0 keeps all
  // Segments that run along the image border, both endpoints within this many pixels of the same
  // side, are dropped: a dark row or column left by rectification or the sensor (TUM's Kinect
  // frames end in one) is a long straight edge fixed in the image, which matches perfectly and
  // says that nothing moved. <= 0 keeps them.
  double border_margin_px = 2.0;
  // Low contrast: the detector's gradient threshold follows the image's contrast, a fraction of
  // the given percentile of its gradient magnitude, never above the detector's own threshold nor
  // below min_gradient (grey levels per pixel). On white panels (TUM fr3 structure_notexture)
  // the panel edges have 2-5 grey levels per pixel against 6 that FLD needs; on KITTI the
  // threshold stays the detector's own.
  bool adapt_to_contrast = false;
  double contrast_percentile = 99.0;
  double contrast_fraction = 0.15;
  double min_gradient = 1.5;
  // Collinear fragments of one edge (a faint edge breaks up) are joined into one segment when
  // they point the same way within merge_angle_deg, each end of the shorter lies within
  // merge_offset_px of the longer's line, and the gap between them is at most merge_gap_px.
  bool merge_collinear = false;
  double merge_angle_deg = 2.0;
  double merge_offset_px = 1.5;
  double merge_gap_px = 20.0;
};

// Line segments of an image, in pixels. Empty for an empty image.
std::vector<LineSegment> detect_line_segments(const GrayImage& image,
                                              const LineDetectionOptions& options = {});

// The gradient threshold detect_line_segments uses for `image` (grey levels per pixel): the
// detector's default, or its contrast-adapted value.
double line_gradient_threshold(const cv::Mat& gray, const LineDetectionOptions& options);

// Joins collinear fragments (merge_angle_deg, merge_offset_px, merge_gap_px of `options`),
// longest first; the joined segment spans its fragments along their length-weighted line.
std::vector<LineSegment> merge_collinear_segments(std::vector<LineSegment> segments,
                                                  const LineDetectionOptions& options);

// True when `s` runs along a side of a width x height image within `margin` pixels.
bool along_image_border(const LineSegment& s, int width, int height, double margin);

}  // namespace hybrid_vo
