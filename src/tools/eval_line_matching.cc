// hybrid_vo_eval_line_matching: our LBD line matcher on the line-matching benchmark of Li et al.
// ("Line segment matching: a benchmark", WACV 2016), on the benchmark's own segments.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "hybrid_vo/features/line_matching.h"

namespace {

namespace fs = std::filesystem;
using hybrid_vo::LineSegment;

void usage(const char* program) {
  std::cerr
      << "Usage: " << program << " DIR [--segments ed|lsd] [options]\n"
      << "  DIR: the benchmark (one folder per pair, or a folder `benchmark/` holding them).\n"
         "  Each pair folder holds images k = 1 and 2 (1 and 6 for the VGG pairs), their\n"
         "  segments <ed|lsd><k>.txt (x1 y1 x2 y2 per row), the ground truth\n"
         "  <ed|lsd>_GroundTruthMatches.txt (0-based groups \"(i,..) (j,..)\") and, for some,\n"
         "  H1to<k>p. The given segments are described and matched with our LBD matcher.\n"
         "Options (the matcher's defaults otherwise):\n"
         "  --octaves N  --first-octave N  --band-width W  --binary\n"
         "  --ratio R  --no-mutual  --max-l2 D  --max-hamming D\n"
         "  --no-geometric  --max-rotation DEG  --candidates N  --neighbours K\n"
         "  --max-local-rotation DEG  --min-support N  --min-candidate-support N\n"
         "  --max-position-error PX\n"
         "  --draw DIR: write each pair's matches there (green: in the GT, red: not)\n"
         "Prints per pair: pair, has_homography, matches, correct (the pair is in a GT group),\n"
         "precision, recall (correct matches / GT groups: a group matched several times counts\n"
         "several times), and for reference the GT groups hit at least once, with a homography\n"
         "the matches that are geometrically correct (both endpoints within 3 px of the matched\n"
         "line, overlapping), and the time to describe and match; then summaries (pooled over\n"
         "the pairs) over the pairs with a homography and over all pairs. With --segments lsd,\n"
         "leuven and ubc are not summarised: their LSD ground truth does not index lsd1/lsd6.\n";
}

bool read_segments(const fs::path& path, std::vector<LineSegment>* segments) {
  std::ifstream in(path);
  if (!in) return false;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    double x1, y1, x2, y2;
    if (fields >> x1 >> y1 >> x2 >> y2)
      segments->emplace_back(Eigen::Vector2d(x1, y1), Eigen::Vector2d(x2, y2));
  }
  return true;
}

// Ground-truth groups "(i[,i2..]) (j[,j2..])", 0-based.
bool read_groups(const fs::path& path,
                 std::vector<std::pair<std::vector<int>, std::vector<int>>>* groups) {
  std::ifstream in(path);
  if (!in) return false;
  const std::regex parenthesised(R"(\(([^)]*)\))");
  std::string line;
  while (std::getline(in, line)) {
    std::vector<std::vector<int>> lists;
    for (auto it = std::sregex_iterator(line.begin(), line.end(), parenthesised);
         it != std::sregex_iterator(); ++it) {
      std::vector<int> list;
      std::string item;
      std::istringstream items((*it)[1].str());
      while (std::getline(items, item, ',')) {
        if (item.find_first_not_of(" \t") == std::string::npos) continue;
        list.push_back(std::stoi(item));
      }
      lists.push_back(list);
    }
    if (lists.size() == 2 && !lists[0].empty() && !lists[1].empty())
      groups->emplace_back(lists[0], lists[1]);
  }
  return true;
}

bool read_homography(const fs::path& path, Eigen::Matrix3d* H) {
  std::ifstream in(path);
  if (!in) return false;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      if (!(in >> (*H)(r, c))) return false;
  return true;
}

// The image file of view k: "k.ext" or "imgk.ext".
fs::path find_image(const fs::path& folder, int k) {
  const std::set<std::string> extensions = {".png", ".jpg", ".jpeg", ".ppm", ".pgm", ".bmp"};
  for (const auto& entry : fs::directory_iterator(folder)) {
    const fs::path& p = entry.path();
    std::string ext = p.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
    if (!extensions.count(ext)) continue;
    const std::string stem = p.stem().string();
    if (stem == std::to_string(k) || stem == "img" + std::to_string(k)) return p;
  }
  return {};
}

// Both endpoints of s1 mapped by H within `tolerance` of s2's infinite line, and the mapped
// segment overlapping s2 along it.
bool correct_under_homography(const Eigen::Matrix3d& H, const LineSegment& s1,
                              const LineSegment& s2, double tolerance = 3.0) {
  const Eigen::Vector3d a = H * hybrid_vo::homogeneous(s1.p1),
                        b = H * hybrid_vo::homogeneous(s1.p2);
  if (std::abs(a.z()) < 1e-12 || std::abs(b.z()) < 1e-12) return false;
  const Eigen::Vector2d p = a.hnormalized(), q = b.hnormalized();
  const Eigen::Vector3d l = hybrid_vo::line_through(s2.p1, s2.p2);
  if (l.isZero()) return false;
  if (std::abs(l.dot(hybrid_vo::homogeneous(p))) > tolerance ||
      std::abs(l.dot(hybrid_vo::homogeneous(q))) > tolerance)
    return false;
  const Eigen::Vector2d u = (s2.p2 - s2.p1).normalized();
  const double t1 = u.dot(p - s2.p1), t2 = u.dot(q - s2.p1);
  return std::max(t1, t2) > 0.0 && std::min(t1, t2) < s2.length();
}

// Both images side by side, each match in green (in the GT) or red, with its index and an arrow
// head at p2 to show the orientation.
void draw_matches(const fs::path& path, const cv::Mat& image1, const cv::Mat& image2,
                  const std::vector<hybrid_vo::LineMatch>& matches,
                  const std::vector<std::pair<int, int>>& pairs, const std::vector<int>& kept1,
                  const std::vector<int>& kept2, const std::set<std::pair<int, int>>& gt_pairs) {
  cv::Mat left, right, canvas;
  cv::cvtColor(image1, left, cv::COLOR_GRAY2BGR);
  cv::cvtColor(image2, right, cv::COLOR_GRAY2BGR);
  const int height = std::max(left.rows, right.rows);
  cv::copyMakeBorder(left, left, 0, height - left.rows, 0, 0, cv::BORDER_CONSTANT);
  cv::copyMakeBorder(right, right, 0, height - right.rows, 0, 0, cv::BORDER_CONSTANT);
  cv::hconcat(left, right, canvas);
  const cv::Point2d offset(left.cols, 0);
  for (size_t m = 0; m < matches.size(); ++m) {
    const bool ok = gt_pairs.count({kept1[pairs[m].first], kept2[pairs[m].second]}) > 0;
    const cv::Scalar color = ok ? cv::Scalar(0, 200, 0) : cv::Scalar(0, 0, 255);
    const auto& s1 = matches[m].s1;
    const auto& s2 = matches[m].s2;
    const cv::Point2d a1(s1.p1.x(), s1.p1.y()), b1(s1.p2.x(), s1.p2.y());
    const cv::Point2d a2(s2.p1.x() + offset.x, s2.p1.y()), b2(s2.p2.x() + offset.x, s2.p2.y());
    cv::arrowedLine(canvas, a1, b1, color, 2, cv::LINE_AA, 0, 0.1);
    cv::arrowedLine(canvas, a2, b2, color, 2, cv::LINE_AA, 0, 0.1);
    cv::putText(canvas, std::to_string(m), 0.5 * (a1 + b1), cv::FONT_HERSHEY_PLAIN, 0.9, color);
    cv::putText(canvas, std::to_string(m), 0.5 * (a2 + b2), cv::FONT_HERSHEY_PLAIN, 0.9, color);
  }
  cv::imwrite(path.string(), canvas);
}

struct Totals {
  int pairs = 0, matches = 0, correct = 0, groups = 0, hit = 0;
  double sum_precision = 0.0, sum_recall = 0.0;
  void add(int m, int c, int g, int h) {
    ++pairs;
    matches += m;
    correct += c;
    groups += g;
    hit += h;
    sum_precision += m > 0 ? static_cast<double>(c) / m : 0.0;
    sum_recall += g > 0 ? static_cast<double>(c) / g : 0.0;
  }
  void print(const char* name) const {
    if (pairs == 0) return;
    std::printf(
        "summary %-10s pairs %2d  matches %5d  correct %5d  groups %5d  precision %.1f %%  "
        "recall %.1f %%  groups hit %.1f %%  (mean over pairs: precision %.1f %%, recall "
        "%.1f %%)\n",
        name, pairs, matches, correct, groups, 100.0 * correct / std::max(matches, 1),
        100.0 * correct / std::max(groups, 1), 100.0 * hit / std::max(groups, 1),
        100.0 * sum_precision / pairs, 100.0 * sum_recall / pairs);
  }
};

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    usage(argv[0]);
    return 2;
  }
  fs::path root, draw_dir;
  std::string kind = "ed";
  hybrid_vo::LineMatchingOptions options;
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    auto value = [&]() -> const char* {
      if (a + 1 >= argc) {
        usage(argv[0]);
        std::exit(2);
      }
      return argv[++a];
    };
    if (arg == "--segments") {
      kind = value();
    } else if (arg == "--ratio") {
      options.ratio = std::atof(value());
    } else if (arg == "--max-hamming") {
      options.max_hamming = std::atoi(value());
    } else if (arg == "--octaves") {
      options.description.octaves = std::atoi(value());
    } else if (arg == "--first-octave") {
      options.description.first_octave = std::atoi(value());
    } else if (arg == "--band-width") {
      options.description.band_width = std::atoi(value());
    } else if (arg == "--binary") {
      options.description.float_descriptor = false;
    } else if (arg == "--no-mutual") {
      options.mutual = false;
    } else if (arg == "--no-geometric") {
      options.geometric_filter = false;
    } else if (arg == "--max-rotation") {
      options.max_rotation_deviation_deg = std::atof(value());
    } else if (arg == "--max-l2") {
      options.max_l2 = std::atof(value());
    } else if (arg == "--candidates") {
      options.candidates = std::atoi(value());
    } else if (arg == "--neighbours") {
      options.neighbours = std::atoi(value());
    } else if (arg == "--max-local-rotation") {
      options.max_local_rotation_deg = std::atof(value());
    } else if (arg == "--max-position-error") {
      options.max_position_error_px = std::atof(value());
    } else if (arg == "--min-support") {
      options.min_support = std::atoi(value());
    } else if (arg == "--min-candidate-support") {
      options.min_candidate_support = std::atoi(value());
    } else if (arg == "--draw") {
      draw_dir = value();
    } else if (arg == "-h" || arg == "--help") {
      usage(argv[0]);
      return 0;
    } else if (root.empty() && arg[0] != '-') {
      root = arg;
    } else {
      std::cerr << "Unknown argument: " << arg << "\n";
      usage(argv[0]);
      return 2;
    }
  }
  if (kind != "ed" && kind != "lsd") {
    std::cerr << "--segments must be ed or lsd\n";
    return 2;
  }
  if (fs::is_directory(root / "benchmark")) root /= "benchmark";
  if (!fs::is_directory(root)) {
    std::cerr << "Not a directory: " << root << "\n";
    return 1;
  }
  std::vector<fs::path> folders;
  for (const auto& entry : fs::directory_iterator(root))
    if (entry.is_directory()) folders.push_back(entry.path());
  std::sort(folders.begin(), folders.end());

  std::printf("%-21s %-14s %5s %5s %6s %7s %7s %9s %7s %5s %5s %6s\n", "pair", "has_homography",
              "n1", "n2", "groups", "matches", "correct", "precision", "recall", "hit", "H_ok",
              "ms");
  Totals with_h, all;
  for (const fs::path& folder : folders) {
    const std::string name = folder.filename().string();
    const int k = fs::exists(folder / (kind + "6.txt")) ? 6 : 2;
    std::vector<LineSegment> segments1, segments2;
    std::vector<std::pair<std::vector<int>, std::vector<int>>> groups;
    const fs::path image1_path = find_image(folder, 1), image2_path = find_image(folder, k);
    if (!read_segments(folder / (kind + "1.txt"), &segments1) ||
        !read_segments(folder / (kind + std::to_string(k) + ".txt"), &segments2) ||
        !read_groups(folder / (kind + "_GroundTruthMatches.txt"), &groups) || image1_path.empty() ||
        image2_path.empty()) {
      std::fprintf(stderr, "%s: incomplete pair folder, skipped\n", name.c_str());
      continue;
    }
    const cv::Mat image1 = cv::imread(image1_path.string(), cv::IMREAD_GRAYSCALE);
    const cv::Mat image2 = cv::imread(image2_path.string(), cv::IMREAD_GRAYSCALE);
    if (image1.empty() || image2.empty()) {
      std::fprintf(stderr, "%s: cannot read the images, skipped\n", name.c_str());
      continue;
    }
    Eigen::Matrix3d H;
    const bool has_h = read_homography(folder / ("H1to" + std::to_string(k) + "p"), &H);
    // The MANIFEST: the LSD ground truth of leuven and ubc does not index the shipped rows.
    const bool gt_unusable = kind == "lsd" && (name == "leuven" || name == "ubc");

    const auto start = std::chrono::steady_clock::now();
    std::vector<int> kept1, kept2;
    const hybrid_vo::LineFeatures f1 =
        hybrid_vo::describe_line_segments(image1, segments1, &kept1, options.description);
    const hybrid_vo::LineFeatures f2 =
        hybrid_vo::describe_line_segments(image2, segments2, &kept2, options.description);
    std::vector<std::pair<int, int>> pairs;
    const std::vector<hybrid_vo::LineMatch> matches =
        hybrid_vo::match_line_features(f1, f2, options, &pairs);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();

    std::set<std::pair<int, int>> gt_pairs;
    std::vector<std::vector<int>> groups_of(segments1.size());
    for (size_t g = 0; g < groups.size(); ++g)
      for (int i : groups[g].first)
        for (int j : groups[g].second) {
          gt_pairs.insert({i, j});
          if (i >= 0 && i < static_cast<int>(groups_of.size())) groups_of[i].push_back(g);
        }
    int correct = 0, h_ok = 0;
    std::set<int> hit;
    for (size_t m = 0; m < pairs.size(); ++m) {
      const int i = kept1[pairs[m].first], j = kept2[pairs[m].second];
      if (gt_pairs.count({i, j})) {
        ++correct;
        for (int g : groups_of[i]) {
          const auto& right = groups[g].second;
          if (std::find(right.begin(), right.end(), j) != right.end()) hit.insert(g);
        }
      }
      if (has_h && correct_under_homography(H, matches[m].s1, matches[m].s2)) ++h_ok;
    }
    if (!draw_dir.empty())
      draw_matches(draw_dir / (name + ".png"), image1, image2, matches, pairs, kept1, kept2,
                   gt_pairs);
    const int n = static_cast<int>(matches.size()), n_groups = static_cast<int>(groups.size());
    char h_text[16] = "-";
    if (has_h) std::snprintf(h_text, sizeof(h_text), "%d", h_ok);
    std::printf("%-21s %-14s %5zu %5zu %6d %7d %7d %8.1f%% %6.1f%% %5zu %5s %6.1f%s\n",
                name.c_str(), has_h ? "yes" : "no", segments1.size(), segments2.size(), n_groups, n,
                correct, 100.0 * correct / std::max(n, 1), 100.0 * correct / std::max(n_groups, 1),
                hit.size(), h_text, ms, gt_unusable ? "  (GT unusable, not summarised)" : "");
    if (gt_unusable) continue;
    all.add(n, correct, n_groups, static_cast<int>(hit.size()));
    if (has_h) with_h.add(n, correct, n_groups, static_cast<int>(hit.size()));
  }
  with_h.print("homography");
  all.print("all");
  return all.pairs > 0 ? 0 : 1;
}
