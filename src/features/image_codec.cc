#include "hybrid_vo/features/image_codec.h"

#include <cstdio>
#include <limits>

#include <opencv2/imgcodecs.hpp>

namespace hybrid_vo {
namespace {

uint32_t big_endian(const std::vector<uint8_t>& b, size_t at, int bytes) {
  uint32_t v = 0;
  for (int k = 0; k < bytes; ++k) v = (v << 8) | b[at + k];
  return v;
}

bool is_png(const std::vector<uint8_t>& b) {
  static const uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  if (b.size() < 8) return false;
  for (int k = 0; k < 8; ++k)
    if (b[k] != kSignature[k]) return false;
  return true;
}

// OpenCV's own test for a JPEG (FF D8 FF), whatever the name says.
bool is_jpeg(const std::vector<uint8_t>& b) {
  return b.size() >= 3 && b[0] == 0xFF && b[1] == 0xD8 && b[2] == 0xFF;
}

bool fail(std::string* reason, const std::string& why) {
  *reason = why;
  return false;
}

std::string first_bytes(const std::vector<uint8_t>& b) {
  std::string s;
  for (size_t k = 0; k < b.size() && k < 4; ++k) {
    char hex[4];
    std::snprintf(hex, sizeof(hex), "%02X", b[k]);
    s += (k ? " " : "") + std::string(hex);
  }
  return s;
}

bool read_png_header(const std::vector<uint8_t>& b, EncodedImageHeader* h, std::string* reason) {
  // Signature, then the IHDR chunk: length 13, "IHDR", width, height, bit depth, colour type.
  if (b.size() < 8 + 8 + 13) return fail(reason, "PNG cut short before the end of its header");
  if (big_endian(b, 8, 4) != 13 || b[12] != 'I' || b[13] != 'H' || b[14] != 'D' || b[15] != 'R')
    return fail(reason, "PNG without an IHDR chunk first");
  const uint32_t width = big_endian(b, 16, 4), height = big_endian(b, 20, 4);
  if (width == 0 || height == 0 || width > std::numeric_limits<int32_t>::max() ||
      height > std::numeric_limits<int32_t>::max())
    return fail(reason, "PNG header gives the size " + std::to_string(width) + "x" +
                            std::to_string(height));
  h->codec = ImageCodec::kPng;
  h->width = static_cast<int>(width);
  h->height = static_cast<int>(height);
  h->bit_depth = b[24];
  switch (b[25]) {  // colour type
    case 0: h->channels = 1; break;
    case 2: case 3: h->channels = 3; break;  // RGB, palette
    case 4: h->channels = 2; break;
    case 6: h->channels = 4; break;
    default: return fail(reason, "PNG header has an invalid colour type " + std::to_string(b[25]));
  }
  return true;
}

bool is_frame_header(uint8_t marker) {
  // SOF0..SOF15 except DHT (C4), JPG (C8) and DAC (CC).
  return marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
}

bool standalone_marker(uint8_t m) { return m == 0x01 || (m >= 0xD0 && m <= 0xD7); }

bool read_jpeg_header(const std::vector<uint8_t>& b, EncodedImageHeader* h, std::string* reason) {
  size_t i = 2;  // after SOI
  const size_t n = b.size();
  while (i + 1 < n) {
    if (b[i] != 0xFF) return fail(reason, "JPEG without a marker where one must be");
    const uint8_t marker = b[i + 1];
    if (marker == 0xFF) {  // fill byte
      ++i;
      continue;
    }
    i += 2;
    if (standalone_marker(marker)) continue;
    if (marker == 0xD9 || marker == 0xDA) break;  // EOI or SOS before any frame header
    if (i + 2 > n) break;
    const size_t length = big_endian(b, i, 2);
    if (length < 2) return fail(reason, "JPEG with a marker segment shorter than its length");
    if (is_frame_header(marker)) {
      // Length, precision, height, width, number of components.
      if (length < 8 || i + 8 > n) break;
      h->codec = ImageCodec::kJpeg;
      h->bit_depth = b[i + 2];
      h->height = static_cast<int>(big_endian(b, i + 3, 2));
      h->width = static_cast<int>(big_endian(b, i + 5, 2));
      h->channels = b[i + 7];
      if (h->width == 0 || h->height == 0)
        return fail(reason, "JPEG frame header gives the size " + std::to_string(h->width) +
                                "x" + std::to_string(h->height));
      return true;
    }
    i += length;
  }
  return fail(reason, "JPEG cut short before its frame header");
}

}  // namespace

const char* to_string(ImageCodec codec) {
  switch (codec) {
    case ImageCodec::kPng: return "PNG";
    case ImageCodec::kJpeg: return "JPEG";
    case ImageCodec::kUnknown: break;
  }
  return "unknown";
}

bool read_image_header(const std::vector<uint8_t>& bytes, EncodedImageHeader* header,
                       std::string* reason) {
  *header = EncodedImageHeader();
  if (bytes.empty()) return fail(reason, "no bytes, not an image");
  if (is_png(bytes)) return read_png_header(bytes, header, reason);
  if (is_jpeg(bytes)) return read_jpeg_header(bytes, header, reason);
  return fail(reason, "neither PNG nor JPEG (first bytes " + first_bytes(bytes) + ")");
}

bool jpeg_reaches_end(const std::vector<uint8_t>& b) {
  const size_t n = b.size();
  if (n < 4 || b[0] != 0xFF || b[1] != 0xD8) return false;
  size_t i = 2;  // after SOI
  while (i + 1 < n) {
    if (b[i] != 0xFF) return false;  // no marker where one must be
    const uint8_t marker = b[i + 1];
    if (marker == 0xFF) {  // fill byte
      ++i;
      continue;
    }
    i += 2;
    if (marker == 0xD9) return true;           // EOI
    if (standalone_marker(marker)) continue;  // TEM, RSTn: no length
    if (i + 2 > n) return false;
    const size_t length = big_endian(b, i, 2);
    if (length < 2) return false;
    i += length;
    if (marker == 0xDA)  // SOS: entropy-coded data follows, up to the next real marker
      while (i + 1 < n && !(b[i] == 0xFF && b[i + 1] != 0x00 && !standalone_marker(b[i + 1]))) ++i;
  }
  return false;
}

bool decode_gray8(const std::vector<uint8_t>& bytes, cv::Mat* gray, std::string* reason,
                  int expected_width, int expected_height, int64_t max_pixels) {
  EncodedImageHeader h;
  if (!read_image_header(bytes, &h, reason)) return false;
  const std::string size = std::to_string(h.width) + "x" + std::to_string(h.height);
  if (expected_width > 0 && expected_height > 0 &&
      (h.width != expected_width || h.height != expected_height))
    return fail(reason, std::string(to_string(h.codec)) + " of " + size + ", but " +
                            std::to_string(expected_width) + "x" +
                            std::to_string(expected_height) + " expected");
  if (static_cast<int64_t>(h.width) * h.height > max_pixels)
    return fail(reason, std::string(to_string(h.codec)) + " of " + size + " is beyond " +
                            std::to_string(max_pixels) + " pixels");
  if (h.codec == ImageCodec::kJpeg && !jpeg_reaches_end(bytes))
    return fail(reason, "JPEG cut short (no end-of-image marker)");
  cv::Mat decoded;
  try {
    // Grey straight from the decoder: a colour JPEG skips its chroma entirely.
    decoded = cv::imdecode(bytes, cv::IMREAD_GRAYSCALE | cv::IMREAD_ANYDEPTH);
  } catch (const cv::Exception& e) {
    return fail(reason, std::string("cannot decode the ") + to_string(h.codec) + " (" + e.err +
                            ")");
  }
  if (decoded.empty())
    return fail(reason, std::string("cannot decode the ") + to_string(h.codec) +
                            " (damaged or cut short)");
  if (decoded.cols != h.width || decoded.rows != h.height || decoded.channels() != 1 ||
      (decoded.depth() != CV_8U && decoded.depth() != CV_16U))
    return fail(reason, std::string("the ") + to_string(h.codec) + " decodes to an image unlike its header");
  if (decoded.depth() == CV_16U) decoded.convertTo(decoded, CV_8U, 1.0 / 256.0);
  *gray = decoded;
  return true;
}

}  // namespace hybrid_vo
