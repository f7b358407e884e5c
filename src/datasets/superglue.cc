// SuperGlue pairs-with-ground-truth reader (see readers.h for the format).
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "hybrid_vo/datasets/readers.h"
#include "hybrid_vo/datasets/text_file.h"

namespace hybrid_vo {
namespace datasets {
namespace {

namespace fs = std::filesystem;

bool parse_rotation_count(const std::string& token, int field, const std::string& path, int line,
                          int* value, std::string* error) {
  if (!parse_int(token, value) || *value < 0 || *value > 3)
    return fail(error, located(path, line,
                               "field " + std::to_string(field) + " '" + token +
                                   "' is not a rotation count in 0..3"));
  return true;
}

}  // namespace

bool read_superglue(const std::string& pairs_file, const std::string& image_dir,
                    std::vector<PairWithGt>* pairs, std::string* error) {
  std::vector<std::string> lines;
  if (!read_lines(pairs_file, &lines, error)) return false;
  pairs->clear();
  for (size_t k = 0; k < lines.size(); ++k) {
    if (is_blank_or_comment(lines[k])) continue;
    const int line = static_cast<int>(k + 1);
    const std::vector<std::string> fields = split_fields(lines[k]);
    if (!expect_field_count(fields, 38, "name0 name1 rot0 rot1 K0(9) K1(9) T_0to1(16)",
                            pairs_file, line, error))
      return false;
    PairWithGt pair;
    if (!parse_rotation_count(fields[2], 3, pairs_file, line, &pair.rotation0, error) ||
        !parse_rotation_count(fields[3], 4, pairs_file, line, &pair.rotation1, error))
      return false;
    double v[34];
    if (!parse_fields(fields, 4, 34, pairs_file, line, v, error)) return false;
    using RowMajor3 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;
    using RowMajor4 = Eigen::Matrix<double, 4, 4, Eigen::RowMajor>;
    const Eigen::Matrix3d K0 = Eigen::Map<const RowMajor3>(v);
    const Eigen::Matrix3d K1 = Eigen::Map<const RowMajor3>(v + 9);
    const Eigen::Matrix4d T = Eigen::Map<const RowMajor4>(v + 18);
    if (!pinhole_from_matrix(K0, pairs_file, line, &pair.camera0.pinhole, error) ||
        !pinhole_from_matrix(K1, pairs_file, line, &pair.camera1.pinhole, error))
      return false;
    if (T.row(3) != Eigen::RowVector4d(0, 0, 0, 1))
      return fail(error, located(pairs_file, line, "T_0to1's last row is not (0 0 0 1)"));
    if (!to_rotation(T.topLeftCorner<3, 3>(), pairs_file, line, &pair.pose.R, error))
      return false;
    pair.pose.t = T.topRightCorner<3, 1>();
    if (image_dir.empty()) {
      pair.image_path0 = fields[0];
      pair.image_path1 = fields[1];
    } else {
      pair.image_path0 = (fs::path(image_dir) / fields[0]).string();
      pair.image_path1 = (fs::path(image_dir) / fields[1]).string();
      std::error_code ec;
      for (const std::string* image : {&pair.image_path0, &pair.image_path1})
        if (!fs::is_regular_file(*image, ec))
          return fail(error, located(pairs_file, line, "no such image " + *image));
    }
    pairs->push_back(pair);
  }
  if (pairs->empty()) return fail(error, located(pairs_file, 0, "no pairs"));
  return true;
}

}  // namespace datasets
}  // namespace hybrid_vo
