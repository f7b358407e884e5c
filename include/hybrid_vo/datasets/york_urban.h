#pragma once

// Reader of the York Urban database (Denis, Elder and Estrada, ECCV 2008) in the layout of
// ../shared/data/york_urban_train (its MANIFEST.md):
//   camera.txt                    "key value" lines, '#' comments: fx fy cx cy (width height)
//   splits.txt                    image names (the words "train" and "test" are skipped)
//   images/NAME/NAME.jpg          the image
//   images/NAME/vp_directions.txt the three ground-truth Manhattan directions, one per row
//   images/NAME/lines.txt         the hand-labelled segments, "x1 y1 x2 y2 vp_id" per row
// Coordinates are MATLAB's, 1-based, like the principal point; the directions have y up.

#include <string>
#include <vector>

#include <Eigen/Core>

#include "hybrid_vo/geometry/camera.h"
#include "hybrid_vo/geometry/homogeneous.h"

namespace hybrid_vo {
namespace datasets {

struct YorkUrbanSet {
  std::string dir;
  PinholeCamera camera;            // one camera for every image
  std::vector<std::string> names;  // in the order of splits.txt
};

struct YorkUrbanImage {
  std::string image_path;  // images/NAME/NAME.jpg (not checked)
  // Unit directions in the camera frame (y down): diag(1, -1, 1) d for each row d of
  // vp_directions.txt (MANIFEST.md: without the flip the segments miss their VPs).
  std::vector<Eigen::Vector3d> vp_directions;
  std::vector<LineSegment> segments;  // lines.txt, 1-based pixels; empty unless asked for
};

// The camera and the image names; false with an error naming the file.
bool read_york_urban(const std::string& dir, YorkUrbanSet* set, std::string* error);

// One image's ground truth (and its labelled segments with `with_segments`); false with
// "file:line: message" when a row has too few numbers, or when a file cannot be opened.
bool read_york_urban_image(const YorkUrbanSet& set, const std::string& name, bool with_segments,
                           YorkUrbanImage* image, std::string* error);

}  // namespace datasets
}  // namespace hybrid_vo
