#include "hybrid_vo/evaluation/plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace hybrid_vo {
namespace evaluation {
namespace {

const cv::Scalar kPalette[] = {{180, 119, 31}, {14, 127, 255}, {44, 160, 44},  {40, 39, 214},
                               {189, 103, 148}, {75, 86, 140}, {194, 119, 227}, {127, 127, 127},
                               {34, 189, 188}, {207, 190, 23}, {0, 0, 0},      {120, 200, 255},
                               {90, 60, 20}};

// Round tick spacing (1, 2 or 5 times a power of ten) for about `count` ticks over [lo, hi].
double tick_step(double lo, double hi, int count) {
  const double raw = (hi - lo) / std::max(1, count);
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * magnitude >= raw) return m * magnitude;
  return 10.0 * magnitude;
}

std::string format_tick(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%g", std::abs(v) < 1e-12 ? 0.0 : v);
  return buffer;
}

}  // namespace

bool write_line_plot(const std::string& path, const std::vector<PlotSeries>& series,
                     const PlotOptions& options) {
  double x_lo = INFINITY, x_hi = -INFINITY, y_lo = INFINITY, y_hi = -INFINITY;
  auto y_of = [&options](double y) { return options.log_y ? std::log10(y) : y; };
  for (const PlotSeries& s : series)
    for (size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (options.log_y && !(s.y[i] > 0.0)) continue;
      const double y = y_of(s.y[i]);
      if (!std::isfinite(s.x[i]) || !std::isfinite(y)) continue;
      x_lo = std::min(x_lo, s.x[i]);
      x_hi = std::max(x_hi, s.x[i]);
      y_lo = std::min(y_lo, y);
      y_hi = std::max(y_hi, y);
    }
  if (!(x_hi >= x_lo) || !(y_hi >= y_lo)) return false;
  if (x_hi == x_lo) x_hi = x_lo + 1.0;
  if (y_hi == y_lo) y_hi = y_lo + 1.0;
  const double y_pad = 0.05 * (y_hi - y_lo);
  y_lo -= options.log_y ? y_pad : std::min(y_pad, std::max(0.0, y_lo));
  y_hi += y_pad;

  cv::Mat image(options.height, options.width, CV_8UC3, cv::Scalar(255, 255, 255));
  const int left = 90, right = 230, top = 75, bottom = 70;
  const cv::Rect area(left, top, options.width - left - right, options.height - top - bottom);
  auto px = [&](double x) { return area.x + (x - x_lo) / (x_hi - x_lo) * area.width; };
  auto py = [&](double y) { return area.y + area.height - (y - y_lo) / (y_hi - y_lo) * area.height; };
  const int font = cv::FONT_HERSHEY_SIMPLEX;
  const cv::Scalar grid(225, 225, 225), ink(40, 40, 40);

  const double xs = tick_step(x_lo, x_hi, 8), ys = tick_step(y_lo, y_hi, 6);
  for (double x = std::ceil(x_lo / xs) * xs; x <= x_hi + 1e-9 * xs; x += xs) {
    cv::line(image, {int(px(x)), area.y}, {int(px(x)), area.y + area.height}, grid, 1);
    cv::putText(image, format_tick(x), {int(px(x)) - 12, area.y + area.height + 22}, font, 0.45,
                ink, 1, cv::LINE_AA);
  }
  for (double y = std::ceil(y_lo / ys) * ys; y <= y_hi + 1e-9 * ys; y += ys) {
    cv::line(image, {area.x, int(py(y))}, {area.x + area.width, int(py(y))}, grid, 1);
    const std::string label = options.log_y ? "1e" + format_tick(y) : format_tick(y);
    cv::putText(image, label, {8, int(py(y)) + 5}, font, 0.45, ink, 1, cv::LINE_AA);
  }
  cv::rectangle(image, area, ink, 1);
  cv::putText(image, options.title, {left, 28}, font, 0.65, ink, 1, cv::LINE_AA);
  cv::putText(image, options.x_label, {area.x + area.width / 2 - 60, options.height - 20}, font,
              0.5, ink, 1, cv::LINE_AA);
  cv::putText(image, options.y_label + (options.log_y ? " (log10)" : ""), {8, top - 18}, font, 0.5,
              ink, 1, cv::LINE_AA);

  for (size_t k = 0; k < series.size(); ++k) {
    const cv::Scalar colour = kPalette[k % (sizeof(kPalette) / sizeof(kPalette[0]))];
    const PlotSeries& s = series[k];
    std::vector<cv::Point> points;
    for (size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (options.log_y && !(s.y[i] > 0.0)) continue;
      const double y = y_of(s.y[i]);
      if (!std::isfinite(s.x[i]) || !std::isfinite(y)) continue;
      points.emplace_back(int(px(s.x[i])), int(py(y)));
    }
    if (points.size() > 1) cv::polylines(image, points, false, colour, 2, cv::LINE_AA);
    for (const cv::Point& p : points)
      if (points.size() < 30) cv::circle(image, p, 3, colour, cv::FILLED, cv::LINE_AA);
    const int ly = top + 18 + 22 * static_cast<int>(k);
    cv::line(image, {options.width - right + 15, ly - 5}, {options.width - right + 45, ly - 5},
             colour, 3);
    cv::putText(image, s.label, {options.width - right + 52, ly}, font, 0.45, ink, 1, cv::LINE_AA);
  }
  try {
    return cv::imwrite(path, image);
  } catch (const cv::Exception&) {
    return false;
  }
}

}  // namespace evaluation
}  // namespace hybrid_vo
