#include "hybrid_vo/node/compressed_image.h"

namespace hybrid_vo {
namespace {

std::string trimmed(const std::string& s) {
  const size_t first = s.find_first_not_of(" \t");
  if (first == std::string::npos) return "";
  return s.substr(first, s.find_last_not_of(" \t") - first + 1);
}

bool fail(std::string* reason, const std::string& why) {
  *reason = why;
  return false;
}

}  // namespace

bool parse_compressed_format(const std::string& format, CompressedFormat* parsed,
                             std::string* reason) {
  *parsed = CompressedFormat();
  const size_t semicolon = format.find(';');
  const std::string how = trimmed(semicolon == std::string::npos ? format
                                                                  : format.substr(semicolon + 1));
  if (semicolon != std::string::npos) parsed->encoding = trimmed(format.substr(0, semicolon));
  // The first word of "<codec> compressed [target]", or the whole of a bare codec name.
  const std::string codec = how.substr(0, how.find(' '));
  if (codec == "compressedDepth")
    return fail(reason, "format '" + format + "' is a compressed depth image, not a camera image");
  if (codec == "jpeg" || codec == "jpg") parsed->codec = ImageCodec::kJpeg;
  else if (codec == "png") parsed->codec = ImageCodec::kPng;
  else if (!codec.empty())
    return fail(reason, "format '" + format + "' is not JPEG or PNG");
  return true;
}

bool gray_from_compressed(const sensor_msgs::CompressedImage& image, int width, int height,
                          cv::Mat* gray, std::string* reason) {
  if (image.data.empty()) return fail(reason, "empty compressed image");
  if (width <= 0 || height <= 0)
    return fail(reason, "no image size to expect (" + std::to_string(width) + "x" +
                            std::to_string(height) + ")");
  CompressedFormat format;
  if (!parse_compressed_format(image.format, &format, reason)) return false;
  EncodedImageHeader header;
  if (!read_image_header(image.data, &header, reason)) return false;
  if (format.codec != ImageCodec::kUnknown && format.codec != header.codec)
    return fail(reason, "format '" + image.format + "' names " + to_string(format.codec) +
                            ", but the payload is " + to_string(header.codec));
  return decode_gray8(image.data, gray, reason, width, height);
}

}  // namespace hybrid_vo
