#include "hybrid_vo/datasets/readers.h"

#include "hybrid_vo/datasets/text_file.h"

namespace hybrid_vo {
namespace datasets {

bool read_sequence(const std::string& format, const std::string& path, Sequence* sequence,
                   std::string* error) {
  if (format == "kitti") return read_kitti(path, sequence, error);
  if (format == "tum") return read_tum(path, sequence, error);
  if (format == "strecha") return read_strecha(path, sequence, error);
  return fail(error, "unknown data set format '" + format + "' (kitti, tum or strecha)");
}

}  // namespace datasets
}  // namespace hybrid_vo
