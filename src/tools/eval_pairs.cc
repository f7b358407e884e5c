// hybrid_vo_eval_pairs: the paper's real-data protocol on image pairs with ground truth. Every
// method sees identical features per pair; the table has one row per method.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "hybrid_vo/datasets/point_subset.h"
#include "hybrid_vo/datasets/readers.h"
#include "hybrid_vo/evaluation/command_line.h"
#include "hybrid_vo/evaluation/ground_truth_check.h"
#include "hybrid_vo/evaluation/opencv_baseline.h"
#include "hybrid_vo/evaluation/statistics.h"
#include "hybrid_vo/features/frontend.h"
#include "hybrid_vo/geometry/pose_error.h"
#include "hybrid_vo/lines/two_view.h"

namespace hybrid_vo {
namespace {

constexpr double kDeg = 180.0 / M_PI;
constexpr double kFailed = 180.0;

struct Arguments {
  std::string format, path, images;
  int gap = 1;
  double resize = 1.0;
  std::vector<std::string> presets = preset_names();
  bool opencv = true;
  bool vp_modes = false;
  bool held_out = false;  // estimate on half the points, score on the other half
  std::string csv;
  int max_pairs = 0;
  uint64_t seed = 0;
  int runs = 1;                   // RANSAC repetitions per pair and method, pooled into one AUC
  int min_iterations = -1;        // overrides of the presets' RANSAC settings (-1: preset's own)
  double point_threshold = -1.0;  // also used for OpenCV (default 1 px)
  double five_point_share = -1.0;  // -1: the preset's own
  int vp_min_inliers = -1;         // -1: TwoViewOptions' own
  // The few-points regime: every value of max_points (-1: all) with every selection.
  std::vector<int> max_points;
  std::vector<datasets::PointSelection> selections = {datasets::PointSelection::kRandom};
  FrontendOptions frontend;
};

// One way of thinning the point matches: the first N under a selection, or all of them.
struct PointSubset {
  int max_points = -1;
  datasets::PointSelection selection = datasets::PointSelection::kRandom;
  std::string label() const {
    return max_points < 0 ? "all,all"
                          : std::to_string(max_points) + "," + datasets::to_string(selection);
  }
};

void usage(const char* program) {
  std::cerr
      << "Usage: " << program << " --format {kitti,tum,strecha,superglue} PATH\n"
      << "         [--images DIR] [--gap K] [--resize S] [--presets a,b,...] [--csv FILE]\n"
      << "         [--vp-modes] [--max-pairs N] [--points sift|orb] [--lines lsd|fld] [--seed S]\n"
      << "         [--runs N] [--min-iterations N] [--point-threshold PX]\n"
      << "         [--five-point-share S] [--vp-min-inliers N] (knobs of the hybrid RANSAC)\n"
      << "         [--max-points N[,N...|all]] [--point-selection random|clustered[,...]]\n"
      << "         [--held-out]\n"
      << "  Pairs are frames i and i+K (superglue: the pairs file, images under --images).\n"
      << "  Prints method,auc5,auc10,auc20,median_err_deg,estimator_ms,frontend_ms (AUC in %),\n"
      << "  one row per preset plus opencv_usac_magsac (findEssentialMat + recoverPose on the same\n"
      << "  points, seeded like the presets). --vp-modes adds the VP ablation: standard, joint,\n"
      << "  joint+refined.\n"
      << "  --runs N repeats every estimator N times per pair with different seeds and pools the\n"
      << "  errors, so that one unlucky RANSAC run does not decide a small data set's AUC.\n"
      << "  --max-points N keeps N point matches per pair and run (all line matches), chosen with\n"
      << "  the run's seed: random (uniformly) or clustered (the N nearest to a random match, as\n"
      << "  in a low-texture image). Every method sees the same subset. With --max-points the\n"
      << "  table starts with max_points,selection columns, one block per value and selection.\n"
      << "  Comment lines after the table give every method's AUC@10 minus the first preset's\n"
      << "  with a 95 % paired bootstrap interval over the pairs (each pair with all its runs),\n"
      << "  and the ground truth check: how well the first preset's point inliers fit the true\n"
      << "  pose and their estimate. Several times worse under the truth means the ground truth\n"
      << "  shares in every pose error, and small AUC differences are not the methods'.\n"
      << "  --held-out: a score without ground truth. Every run splits the point matches at\n"
      << "  random into halves (with --max-points: the N kept and the rest); the methods\n"
      << "  estimate from the first (and all lines) and are scored on the second: the mean of\n"
      << "  min(e, t)^2 / t^2 over its matches, e the Sampson error and t the point threshold\n"
      << "  (0: all on their epipolar lines; 1: none within t; a failure scores 1). Printed per\n"
      << "  method with the baseline difference and for the true pose; pairs with no match left\n"
      << "  out are not scored.\n";
}

bool parse(int argc, char** argv, Arguments* a) {
  std::vector<std::string> positional;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      usage(argv[0]);
      std::exit(0);
    }
    if (arg == "--vp-modes") {
      a->vp_modes = true;
      continue;
    }
    if (arg == "--held-out") {
      a->held_out = true;
      continue;
    }
    if (arg.rfind("--", 0) != 0) {
      positional.push_back(arg);
      continue;
    }
    if (i + 1 >= argc) return std::cerr << "error: " << arg << " needs a value\n", false;
    const std::string v = argv[++i];
    char* end = nullptr;
    if (arg == "--format") {
      a->format = v;
    } else if (arg == "--images") {
      a->images = v;
    } else if (arg == "--gap") {
      a->gap = static_cast<int>(std::strtol(v.c_str(), &end, 10));
      if (*end || a->gap < 1) return std::cerr << "error: --gap must be >= 1\n", false;
    } else if (arg == "--resize") {
      a->resize = std::strtod(v.c_str(), &end);
      if (*end || !(a->resize > 0.0 && a->resize <= 4.0))
        return std::cerr << "error: --resize must be in (0, 4]\n", false;
    } else if (arg == "--presets") {
      a->presets.clear();
      a->opencv = false;
      for (const std::string& p : evaluation::split_list(v)) {
        RelativePoseEstimatorOptions unused;
        if (p == "opencv_usac_magsac") a->opencv = true;
        else if (preset_options(p, &unused)) a->presets.push_back(p);
        else return std::cerr << "error: unknown method '" << p << "'\n", false;
      }
    } else if (arg == "--csv") {
      a->csv = v;
    } else if (arg == "--max-pairs") {
      a->max_pairs = static_cast<int>(std::strtol(v.c_str(), &end, 10));
      if (*end || a->max_pairs < 0) return std::cerr << "error: bad --max-pairs\n", false;
    } else if (arg == "--seed") {
      a->seed = std::strtoull(v.c_str(), &end, 10);
    } else if (arg == "--runs") {
      a->runs = static_cast<int>(std::strtol(v.c_str(), &end, 10));
      if (*end || a->runs < 1) return std::cerr << "error: --runs must be >= 1\n", false;
    } else if (arg == "--min-iterations") {
      a->min_iterations = static_cast<int>(std::strtol(v.c_str(), &end, 10));
      if (*end || a->min_iterations < 1)
        return std::cerr << "error: --min-iterations must be >= 1\n", false;
    } else if (arg == "--point-threshold") {
      a->point_threshold = std::strtod(v.c_str(), &end);
      if (*end || !(a->point_threshold > 0.0))
        return std::cerr << "error: --point-threshold must be > 0\n", false;
    } else if (arg == "--vp-min-inliers") {
      a->vp_min_inliers = static_cast<int>(std::strtol(v.c_str(), &end, 10));
      if (*end || a->vp_min_inliers < 2)
        return std::cerr << "error: --vp-min-inliers must be >= 2\n", false;
    } else if (arg == "--five-point-share") {
      a->five_point_share = std::strtod(v.c_str(), &end);
      if (*end || !(a->five_point_share >= 0.0 && a->five_point_share <= 1.0))
        return std::cerr << "error: --five-point-share must be in [0, 1]\n", false;
    } else if (arg == "--max-points") {
      a->max_points.clear();
      for (const std::string& item : evaluation::split_list(v)) {
        if (item == "all") {
          a->max_points.push_back(-1);
          continue;
        }
        const long n = std::strtol(item.c_str(), &end, 10);
        if (*end || n < 1 || n > 1000000)
          return std::cerr << "error: --max-points takes positive counts or 'all'\n", false;
        a->max_points.push_back(static_cast<int>(n));
      }
      if (a->max_points.empty()) return std::cerr << "error: --max-points needs a value\n", false;
    } else if (arg == "--point-selection") {
      a->selections.clear();
      for (const std::string& item : evaluation::split_list(v)) {
        datasets::PointSelection selection;
        if (!datasets::parse_point_selection(item, &selection))
          return std::cerr << "error: --point-selection must be random or clustered\n", false;
        a->selections.push_back(selection);
      }
      if (a->selections.empty()) return std::cerr << "error: --point-selection needs a value\n", false;
    } else if (arg == "--points") {
      if (v == "orb") a->frontend.points.type = PointFeatureType::kOrb;
      else if (v != "sift") return std::cerr << "error: --points must be sift or orb\n", false;
    } else if (arg == "--lines") {
      if (v == "fld") a->frontend.lines.detection.detector = LineDetector::kFld;
      else if (v != "lsd") return std::cerr << "error: --lines must be lsd or fld\n", false;
    } else {
      std::cerr << "error: unknown option " << arg << "\n";
      return false;
    }
  }
  if (positional.size() != 1 || a->format.empty()) return usage(argv[0]), false;
  a->path = positional[0];
  return true;
}

using hybrid_vo::evaluation::median;
using hybrid_vo::evaluation::DifferenceInterval;
using hybrid_vo::evaluation::paired_bootstrap_difference;

struct MethodStats {
  std::vector<double> errors, estimator_ms;
  std::vector<double> offset_x, offset_y;  // translation direction against the truth, degrees
  std::vector<double> held_out;  // truncated_sampson_cost on the held-out half (--held-out)
};

// Where the estimated translation direction lies relative to the true one, in degrees along the
// image x and y axes (the tangent plane at the true direction). Its median over the pairs shows a
// constant offset, the mark of a calibration or ground-truth bias rather than estimation noise.
void translation_offset(const Eigen::Vector3d& estimate, const Eigen::Vector3d& truth,
                        double* x, double* y) {
  const Eigen::Vector3d g = truth.normalized(), t = estimate.normalized();
  Eigen::Vector3d bx = Eigen::Vector3d::UnitX() - g.x() * g;
  if (bx.norm() < 1e-6) bx = Eigen::Vector3d::UnitY() - g.y() * g;
  bx.normalize();
  Eigen::Vector3d by = Eigen::Vector3d::UnitY() - g.y() * g - bx.y() * bx;
  by = by.norm() < 1e-6 ? Eigen::Vector3d(g.cross(bx)) : Eigen::Vector3d(by.normalized());
  *x = std::atan2(t.dot(bx), t.dot(g)) * kDeg;
  *y = std::atan2(t.dot(by), t.dot(g)) * kDeg;
}

// --held-out: moves a random half of `points` (by the run's seed) into `held_out`, keeping the
// order within each half.
void split_held_out(uint64_t seed, std::vector<PointMatch>* points,
                    std::vector<PointMatch>* held_out) {
  std::vector<int> order(points->size());
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), std::mt19937_64(seed ^ 0x9e3779b97f4a7c15ull));
  std::vector<char> out(points->size(), 0);
  for (size_t k = order.size() / 2; k < order.size(); ++k) out[order[k]] = 1;
  std::vector<PointMatch> kept;
  held_out->clear();
  for (size_t i = 0; i < points->size(); ++i)
    (out[i] ? held_out : &kept)->push_back((*points)[i]);
  *points = std::move(kept);
}

// Feature extraction, once per image (consecutive pairs share images).
class FeatureCache {
 public:
  FeatureCache(const Arguments& args) : args_(args) {}
  const ImageFeatures* get(const std::string& path, double* ms, cv::Mat* image_out) {
    auto it = cache_.find(path);
    if (it == cache_.end()) {
      cv::Mat image = cv::imread(path, cv::IMREAD_GRAYSCALE);
      if (image.empty()) return nullptr;
      if (args_.resize != 1.0)
        cv::resize(image, image, cv::Size(), args_.resize, args_.resize, cv::INTER_AREA);
      Entry e;
      const auto start = std::chrono::steady_clock::now();
      e.features = extract_features(image, args_.frontend);
      e.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                 .count();
      e.image = image;
      if (cache_.size() > 4) cache_.erase(cache_.begin());
      it = cache_.emplace(path, std::move(e)).first;
    }
    *ms = it->second.ms;
    if (image_out) *image_out = it->second.image;
    return &it->second.features;
  }

 private:
  struct Entry {
    ImageFeatures features;
    cv::Mat image;
    double ms = 0.0;
  };
  const Arguments& args_;
  std::map<std::string, Entry> cache_;
};

// OpenCV's USAC_MAGSAC plus recoverPose (opencv_baseline.h) on the same points.
bool run_opencv(const TwoViewMatches& m, const PinholeCamera& c1, const PinholeCamera& c2,
                double threshold_px, uint64_t seed, double* ms, RelativePose* pose) {
  const auto start = std::chrono::steady_clock::now();
  const evaluation::OpenCvPose result =
      evaluation::opencv_usac_magsac(m.points, c1, c2, threshold_px, seed);
  *ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  if (result.ok) *pose = result.pose;
  return result.ok;
}

void print_row(const std::string& method, const MethodStats& s, double frontend_ms) {
  std::printf("%s,%.2f,%.2f,%.2f,%.3f,%.2f,%.2f\n", method.c_str(), 100.0 * pose_auc(s.errors, 5.0),
              100.0 * pose_auc(s.errors, 10.0), 100.0 * pose_auc(s.errors, 20.0),
              median(s.errors), median(s.estimator_ms), frontend_ms);
}

}  // namespace
}  // namespace hybrid_vo

int main(int argc, char** argv) {
  using namespace hybrid_vo;
  Arguments args;
  if (!parse(argc, argv, &args)) return 2;
  cv::setNumThreads(1);

  std::vector<datasets::PairWithGt> pairs;
  std::string error;
  if (args.format == "superglue") {
    if (!datasets::read_superglue(args.path, args.images, &pairs, &error)) {
      std::cerr << "error: " << error << "\n";
      return 1;
    }
  } else if (args.format == "kitti" || args.format == "tum" || args.format == "strecha") {
    datasets::Sequence sequence;
    if (!datasets::read_sequence(args.format, args.path, &sequence, &error)) {
      std::cerr << "error: " << error << "\n";
      return 1;
    }
    pairs = datasets::make_pairs(sequence, args.gap);
  } else {
    std::cerr << "error: --format must be kitti, tum, strecha or superglue\n";
    return 2;
  }
  if (args.max_pairs > 0 && static_cast<int>(pairs.size()) > args.max_pairs)
    pairs.resize(args.max_pairs);
  if (pairs.empty()) {
    std::cerr << "error: no pairs (too few frames for --gap " << args.gap << "?)\n";
    return 1;
  }

  std::ofstream csv;
  if (!args.csv.empty()) {
    csv.open(args.csv);
    if (!csv) {
      std::cerr << "error: cannot write " << args.csv << "\n";
      return 1;
    }
    csv << "pair,image0,image1,method,rot_err_deg,trans_err_deg,pose_err_deg,points,lines,vps,"
           "estimator_ms,max_points,selection,held_out_cost\n";
  }

  FeatureCache cache(args);
  std::vector<PointSubset> subsets;
  if (args.max_points.empty()) subsets.push_back(PointSubset());
  for (const int n : args.max_points) {
    if (n < 0) {
      subsets.push_back(PointSubset());
      continue;
    }
    for (const datasets::PointSelection selection : args.selections)
      subsets.push_back({n, selection});
  }
  // Per subset (label) and method.
  std::map<std::string, std::map<std::string, MethodStats>> stats;
  std::map<std::string, int> short_pairs;  // pairs with fewer point matches than asked for
  std::vector<double> frontend_ms;
  // Per pair: the median Sampson error (px) of the baseline's point inliers under the true pose
  // and under its estimate (evaluation/ground_truth_check.h).
  std::vector<double> gt_fit_px, estimate_fit_px;
  // Per subset: the true pose's held-out cost, per pair and run.
  std::map<std::string, std::vector<double>> truth_held_out;
  const double threshold_px = args.point_threshold > 0.0 ? args.point_threshold : 1.0;
  // VP ablation: per mode, VP matches per pair, consistent matches, and the VP solvers alone.
  const std::vector<std::string> vp_modes = {"standard", "joint", "joint+refined"};
  const std::vector<SolverId> vp_solvers = {SolverId::k1vp3pt, SolverId::k2vp2pt,
                                            SolverId::k1vpOrthline2pt};
  std::map<std::string, std::vector<double>> vp_counts, vp_consistent;
  std::map<std::string, std::map<int, std::vector<double>>> vp_solver_errors;

  for (size_t p = 0; p < pairs.size(); ++p) {
    const datasets::PairWithGt& pair = pairs[p];
    double ms0 = 0.0, ms1 = 0.0;
    const ImageFeatures* f0 = cache.get(pair.image_path0, &ms0, nullptr);
    const ImageFeatures* f1 = f0 ? cache.get(pair.image_path1, &ms1, nullptr) : nullptr;
    if (!f0 || !f1) {
      std::cerr << "error: cannot read " << (f0 ? pair.image_path1 : pair.image_path0) << "\n";
      return 1;
    }
    const CameraModel c0 = datasets::scaled(pair.camera0, args.resize);
    const CameraModel c1 = datasets::scaled(pair.camera1, args.resize);
    double match_ms = 0.0;
    const TwoViewMatches all_matches = match_features(*f0, *f1, c0, c1, args.frontend, &match_ms);
    frontend_ms.push_back(ms0 + ms1 + match_ms);
    RelativePose truth = pair.pose;
    truth.t.normalize();

    for (const PointSubset& subset : subsets) {
      const std::string label = subset.label();
      if (subset.max_points > static_cast<int>(all_matches.points.size())) ++short_pairs[label];
      for (int run = 0; run < args.runs; ++run) {
        const uint64_t seed = args.seed + p + 1000003ull * run;
        TwoViewMatches matches = all_matches;
        // --held-out: the matches left out of the subset, or half of all of them. A pair with
        // none left out (fewer matches than asked for) is not scored, in every run and method.
        std::vector<PointMatch> held_out;
        if (subset.max_points >= 0) {
          matches.points.clear();
          std::vector<char> selected(all_matches.points.size(), 0);
          for (const int i : datasets::select_point_matches(all_matches.points, subset.max_points,
                                                            subset.selection, seed)) {
            matches.points.push_back(all_matches.points[i]);
            selected[i] = 1;
          }
          for (size_t i = 0; args.held_out && i < selected.size(); ++i)
            if (!selected[i]) held_out.push_back(all_matches.points[i]);
        } else if (args.held_out) {
          split_held_out(seed, &matches.points, &held_out);
        }
        const bool scored = args.held_out && !held_out.empty();
        if (scored)
          truth_held_out[label].push_back(evaluation::truncated_sampson_cost(
              c0.pinhole, c1.pinhole, truth, held_out, threshold_px));
        // `pose`: the estimate, nullptr when it failed; `offset`: record its translation offset.
        auto record = [&](const std::string& method, double rot, double trans, double ms,
                          int vps, const RelativePose* pose, bool offset) {
          MethodStats& s = stats[label][method];
          s.errors.push_back(std::max(rot, trans));
          s.estimator_ms.push_back(ms);
          const double cost =
              !scored ? NAN
              : pose  ? evaluation::truncated_sampson_cost(c0.pinhole, c1.pinhole, *pose, held_out,
                                                           threshold_px)
                      : 1.0;
          if (scored) s.held_out.push_back(cost);
          if (pose && offset) {
            double x = 0.0, y = 0.0;
            translation_offset(pose->t, truth.t, &x, &y);
            s.offset_x.push_back(x);
            s.offset_y.push_back(y);
          }
          if (csv)
            csv << p << ',' << pair.image_path0 << ',' << pair.image_path1 << ',' << method << ','
                << rot << ',' << trans << ',' << std::max(rot, trans) << ','
                << matches.points.size() << ',' << matches.lines.size() << ',' << vps << ','
                << ms << ',' << label << ',' << cost << '\n';
        };
        for (const std::string& preset : args.presets) {
          TwoViewOptions options;
          preset_options(preset, &options);
          if (args.min_iterations > 0) options.ransac.min_iterations = args.min_iterations;
          if (args.point_threshold > 0.0)
            options.ransac.point_threshold_px = args.point_threshold;
          if (args.vp_min_inliers > 0) options.vp_detection.min_inliers = args.vp_min_inliers;
          if (args.five_point_share >= 0.0)
            options.ransac.five_point_share = args.five_point_share;
          options.ransac.seed = seed;
          const auto start = std::chrono::steady_clock::now();
          const TwoViewEstimate result =
              estimate_two_view(c0.pinhole, c1.pinhole, matches, options);
          const double ms =
              std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                  .count();
          const bool ok = result.estimate.status == EstimationStatus::kOk;
          const RelativePose* pose = ok ? &result.estimate.pose : nullptr;
          // The ground-truth check, on the baseline's first run with the last point subset.
          if (pose && run == 0 && preset == args.presets.front() &&
              &subset == &subsets.back()) {
            const std::vector<char>& inliers = result.estimate.point_inliers;
            gt_fit_px.push_back(evaluation::median_sampson_px(c0.pinhole, c1.pinhole, truth,
                                                              matches.points, inliers));
            estimate_fit_px.push_back(evaluation::median_sampson_px(
                c0.pinhole, c1.pinhole, *pose, matches.points, inliers));
          }
          record(preset, pose ? rotation_error(pose->R, truth.R) * kDeg : kFailed,
                 pose ? translation_error(pose->t, truth.t) * kDeg : kFailed, ms,
                 static_cast<int>(result.vps.matches.size()), pose, true);
        }
        if (args.opencv) {
          double ms = 0.0;
          RelativePose pose;
          const bool ok =
              run_opencv(matches, c0.pinhole, c1.pinhole, threshold_px, seed, &ms, &pose);
          record("opencv_usac_magsac", ok ? rotation_error(pose.R, truth.R) * kDeg : kFailed,
                 ok ? translation_error(pose.t, truth.t) * kDeg : kFailed, ms, 0,
                 ok ? &pose : nullptr, false);
        }
      }
    }
    const TwoViewMatches& matches = all_matches;

    if (args.vp_modes) {
      for (const std::string& mode : vp_modes) {
        VpDetectionOptions vp_options;
        vp_options.refine = mode == "joint+refined";
        vp_options.seed = args.seed + p;
        const MatchedVps vps =
            mode == "standard"
                ? detect_vanishing_points_standard(c0.pinhole, c1.pinhole, matches.lines, vp_options)
                : detect_vanishing_points_joint(c0.pinhole, c1.pinhole, matches.lines, vp_options);
        vp_counts[mode].push_back(vps.matches.size());
        for (const VpMatch& v : vps.matches) {
          const Eigen::Vector3d a = truth.R * v.d1.normalized();
          const double angle =
              std::acos(std::min(1.0, std::abs(a.dot(v.d2.normalized())))) * kDeg;
          vp_consistent[mode].push_back(angle < 2.0 ? 1.0 : 0.0);
        }
        TwoViewMatches with_vps = matches;
        with_vps.vps = vps.matches;
        with_vps.line_vp = vps.labels;
        for (SolverId id : vp_solvers) {
          RelativePoseEstimatorOptions only;
          only.ransac.enabled.fill(false);
          only.ransac.enabled[static_cast<int>(id)] = true;
          only.ransac.seed = args.seed + p;
          const RelativePoseEstimate est =
              estimate_relative_pose(c0.pinhole, c1.pinhole, with_vps, only);
          vp_solver_errors[mode][static_cast<int>(id)].push_back(
              est.status == EstimationStatus::kOk ? pose_error(est.pose, truth) * kDeg : kFailed);
        }
      }
    }
  }

  const bool subset_columns = !args.max_points.empty();
  std::printf("%smethod,auc5,auc10,auc20,median_err_deg,estimator_ms,frontend_ms\n",
              subset_columns ? "max_points,selection," : "");
  const double fe = median(frontend_ms);
  std::vector<std::string> methods = args.presets;
  if (args.opencv) methods.push_back("opencv_usac_magsac");
  for (const PointSubset& subset : subsets) {
    const std::string label = subset.label();
    for (const std::string& method : methods)
      print_row((subset_columns ? label + "," : "") + method, stats[label][method], fe);
  }
  std::printf("# %zu pairs, gap %d, resize %.2f\n", pairs.size(), args.gap, args.resize);
  for (const auto& [label, count] : short_pairs)
    std::printf("# %s: %d pairs had fewer point matches and kept them all\n", label.c_str(), count);
  // Whether a difference to the baseline (the first preset) is more than the pair set's luck.
  for (const PointSubset& subset : subsets) {
    if (args.presets.empty()) break;
    const std::string label = subset.label();
    const std::string& baseline = args.presets.front();
    for (const std::string& method : methods) {
      if (method == baseline) continue;
      const DifferenceInterval d = paired_bootstrap_difference(
          stats[label][baseline].errors, stats[label][method].errors, args.runs,
          [](const std::vector<double>& e) { return 100.0 * pose_auc(e, 10.0); }, 2000, args.seed);
      std::printf("# %s%s - %s AUC@10: %+.2f, 95 %% interval [%+.2f, %+.2f] (paired bootstrap over "
                  "%d pairs)\n",
                  subset_columns ? (label + ": ").c_str() : "", method.c_str(), baseline.c_str(),
                  d.difference, d.low, d.high, d.groups);
    }
  }
  for (const PointSubset& subset : subsets) {
    if (!args.held_out || args.presets.empty()) break;
    const std::string label = subset.label();
    const std::string prefix = subset_columns ? label + ": " : "";
    std::printf("# %sheld-out cost (0 best, 1 worst), mean over pairs and runs:", prefix.c_str());
    auto mean = [](const std::vector<double>& v) {
      double sum = 0.0;
      for (double x : v) sum += x;
      return v.empty() ? NAN : sum / v.size();
    };
    for (const std::string& method : methods)
      std::printf(" %s %.4f,", method.c_str(), mean(stats[label][method].held_out));
    std::printf(" true pose %.4f\n", mean(truth_held_out[label]));
    const std::string& baseline = args.presets.front();
    for (const std::string& method : methods) {
      if (method == baseline) continue;
      const DifferenceInterval d =
          paired_bootstrap_difference(stats[label][baseline].held_out,
                                      stats[label][method].held_out, args.runs, mean, 2000,
                                      args.seed);
      std::printf("# %s%s - %s held-out cost: %+.4f, 95 %% interval [%+.4f, %+.4f]\n",
                  prefix.c_str(), method.c_str(), baseline.c_str(), d.difference, d.low, d.high);
    }
  }
  if (!args.presets.empty()) {
    const MethodStats& s = stats[subsets.back().label()][args.presets.front()];
    std::printf("# %s: median translation offset from the truth along image x / y: %.3f / %.3f deg\n",
                args.presets.front().c_str(), median(s.offset_x), median(s.offset_y));
    std::printf("# ground truth check: %s's point inliers fit the true pose to %.2f px and its "
                "estimate to %.2f px (median Sampson error, median over %zu pairs)\n",
                args.presets.front().c_str(), median(gt_fit_px), median(estimate_fit_px),
                gt_fit_px.size());
  }
  if (args.vp_modes) {
    std::printf("\nvp_mode,vp_matches_per_pair,consistent_fraction,auc10_3-0-1,auc10_2-0-2,"
                "auc10_2-1-1p\n");
    for (const std::string& mode : vp_modes) {
      double count = 0.0, consistent = 0.0;
      for (double c : vp_counts[mode]) count += c;
      for (double c : vp_consistent[mode]) consistent += c;
      const double consistent_fraction =
          vp_consistent[mode].empty() ? 0.0 : consistent / vp_consistent[mode].size();
      std::printf("%s,%.2f,%.3f", mode.c_str(), count / pairs.size(), consistent_fraction);
      for (SolverId id : vp_solvers)
        std::printf(",%.2f", 100.0 * pose_auc(vp_solver_errors[mode][static_cast<int>(id)], 10.0));
      std::printf("\n");
    }
  }
  return 0;
}
