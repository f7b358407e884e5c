#pragma once

#include <string>
#include <vector>

namespace hybrid_vo {
namespace evaluation {

struct PlotSeries {
  std::string label;  // ASCII: the Hershey fonts have no other glyphs
  std::vector<double> x, y;
};

struct PlotOptions {
  std::string title;
  std::string x_label;
  std::string y_label;
  int width = 1000;
  int height = 640;
  bool log_y = false;  // plot log10(y) for y > 0
};

// Writes a line plot of the series as a PNG (OpenCV drawing; no Python needed on the machine).
// Returns false when the file cannot be written or there is nothing to draw.
bool write_line_plot(const std::string& path, const std::vector<PlotSeries>& series,
                     const PlotOptions& options);

}  // namespace evaluation
}  // namespace hybrid_vo
