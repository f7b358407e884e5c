#pragma once

// PNG and JPEG bytes (a file's, or a sensor_msgs/CompressedImage's payload) to the 8-bit grey
// image the detectors take, with the checks OpenCV leaves out: the header is read first, so that
// a size nobody expects is refused before anything is allocated, and a JPEG cut short is refused
// (libjpeg only warns "Premature end of JPEG file" and fills the missing rows with grey).

#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace hybrid_vo {

enum class ImageCodec { kUnknown, kPng, kJpeg };
const char* to_string(ImageCodec codec);

// What an image's header says, without decoding its pixels.
struct EncodedImageHeader {
  ImageCodec codec = ImageCodec::kUnknown;
  int width = 0, height = 0;
  int channels = 0;   // as stored: 1 grey, 2 grey + alpha, 3 colour, 4 colour + alpha (or CMYK)
  int bit_depth = 0;  // bits per sample as stored: PNG 1, 2, 4, 8 or 16; JPEG 8 or 12
};

// PNG's IHDR chunk, or the frame header (SOFn) of a JPEG. False with the reason for bytes that
// are neither (their first bytes named), a header cut short, or a zero size.
bool read_image_header(const std::vector<uint8_t>& bytes, EncodedImageHeader* header,
                       std::string* reason);

// True when JPEG bytes reach their end-of-image marker (bytes after it are allowed): marker
// segments are skipped by their length, entropy-coded data up to the next marker that is neither
// a stuffed 0xFF00 nor a restart marker.
bool jpeg_reaches_end(const std::vector<uint8_t>& bytes);

// Decodes PNG or JPEG bytes (8 or 16 bits, grey or colour) into 8-bit grey: colour as the
// decoder turns it grey (libjpeg's luma, OpenCV's weights for PNG), 16 bits scaled by 1/256 as
// the node scales a raw mono16 image. With expected_width and expected_height > 0 an image of
// another size is refused from its header. False with the reason for empty bytes, another
// format, a JPEG cut short, a size beyond max_pixels or one that differs, or bytes the decoder
// refuses.
bool decode_gray8(const std::vector<uint8_t>& bytes, cv::Mat* gray, std::string* reason,
                  int expected_width = 0, int expected_height = 0,
                  int64_t max_pixels = int64_t{1} << 26);

}  // namespace hybrid_vo
