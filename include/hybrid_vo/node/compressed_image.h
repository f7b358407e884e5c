#pragma once

// sensor_msgs/CompressedImage to the front end's 8-bit grey image, without the
// compressed_image_transport plugin (Debian ships none): the node subscribes <image>/compressed
// itself with `image_transport: compressed` and decodes here (features/image_codec.h).

#include <string>

#include <opencv2/core.hpp>
#include <sensor_msgs/CompressedImage.h>

#include "hybrid_vo/features/image_codec.h"

namespace hybrid_vo {

// The `format` field as compressed_image_transport writes it: "<encoding>; <jpeg|png> compressed
// [<target encoding>]" (e.g. "mono8; png compressed ", "bgr8; jpeg compressed bgr8"), or the bare
// "jpeg" / "png" of older publishers; empty is taken too (the bytes say which codec). False with
// the reason for another transport ("16UC1; compressedDepth png" is a depth image) or codec.
struct CompressedFormat {
  std::string encoding;  // the original image's encoding, when the format names it
  ImageCodec codec = ImageCodec::kUnknown;  // kUnknown: not named
};
bool parse_compressed_format(const std::string& format, CompressedFormat* parsed,
                             std::string* reason);

// The message's image in 8-bit grey (decode_gray8: 8 or 16 bits, grey or colour), refused unless
// it is width x height (its camera_info's size; checked from the header, before decoding).
// False with the reason for an empty payload, an unsupported format, a payload that is not the
// codec the format names, damaged or cut short, or of another size.
bool gray_from_compressed(const sensor_msgs::CompressedImage& image, int width, int height,
                          cv::Mat* gray, std::string* reason);

}  // namespace hybrid_vo
