// hybrid_vo_bench_solvers: speed and numerical stability of the thirteen minimal solvers on the
// paper's random instances (Sec. 5.1), with OpenGV's five-point solvers timed in the same run.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "hybrid_vo/estimation/refine_relative_pose.h"
#include "hybrid_vo/evaluation/plot.h"
#include "hybrid_vo/evaluation/statistics.h"
#include "hybrid_vo/geometry/essential.h"
#include "hybrid_vo/geometry/pose_error.h"
#include "hybrid_vo/solvers/minimal_solver.h"
#include "hybrid_vo/solvers/relpose_homography.h"
#include "hybrid_vo/synthetic/minimal_instances.h"

#ifdef HYBRID_VO_HAVE_OPENGV
#include <opengv/relative_pose/CentralRelativeAdapter.hpp>
#include <opengv/relative_pose/methods.hpp>
#endif

namespace hybrid_vo {
namespace {

constexpr double kFailThreshold = 1e-6;  // rad
constexpr double kLog10Floor = -16.0;

struct Arguments {
  int instances = 100000;
  uint64_t seed = 42;
  std::string histograms_dir;
  std::string noise_dir;
  std::string only;  // one configuration code, e.g. 5-0-0; empty for all
  std::string vp_signs = "both";  // 3-0-1 rows: "unknown", "known" or "both"
};

void usage(const char* program) {
  std::cerr << "Usage: " << program
            << " [--instances N] [--seed S] [--only CONFIG] [--vp-signs unknown|known|both]\n"
               "       [--histograms DIR] [--noise-curve DIR]\n"
               "  Prints one CSV row per minimal configuration (paper Fig. 2), then OpenGV's\n"
               "  five-point solvers on the same 5-0-0 instances, and their speed ratio. 4-0-0 has a\n"
               "  second row, the homography DLT alone (before decomposition); its error columns\n"
               "  both hold the log10 distance of the unit-norm H to the true homography.\n"
               "  --only CONFIG      one configuration, e.g. 5-0-0 or 3-0-1 (peers run with 5-0-0);\n"
               "                     for profiling one solver under callgrind\n"
               "  --vp-signs WHICH   3-0-1 rows: VP sign unknown (both signs tried), known, or both\n"
               "                     rows (default); with --only 3-0-1, one setting under callgrind\n"
               "  --histograms DIR   log10 error histograms (CSV + PNG), as the paper's Fig. 3\n"
               "  --noise-curve DIR  median errors against pixel noise, raw and after local\n"
               "                     optimisation on 50 points (CSV + PNG), as its Figs. 4-5\n";
}

bool parse(int argc, char** argv, Arguments* args) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&](const char* name) -> const char* {
      if (i + 1 >= argc) {
        std::cerr << "error: " << name << " needs a value\n";
        return nullptr;
      }
      return argv[++i];
    };
    if (a == "--help" || a == "-h") {
      usage(argv[0]);
      std::exit(0);
    } else if (a == "--instances") {
      const char* v = value("--instances");
      if (!v) return false;
      char* end = nullptr;
      const long n = std::strtol(v, &end, 10);
      if (*end != '\0' || n < 100) {
        std::cerr << "error: --instances must be an integer >= 100, got '" << v << "'\n";
        return false;
      }
      args->instances = static_cast<int>(n);
    } else if (a == "--seed") {
      const char* v = value("--seed");
      if (!v) return false;
      args->seed = std::strtoull(v, nullptr, 10);
    } else if (a == "--only") {
      const char* v = value("--only");
      if (!v) return false;
      args->only = v;
    } else if (a == "--vp-signs") {
      const char* v = value("--vp-signs");
      if (!v) return false;
      args->vp_signs = v;
      if (args->vp_signs != "unknown" && args->vp_signs != "known" && args->vp_signs != "both") {
        std::cerr << "error: --vp-signs must be unknown, known or both, got '" << v << "'\n";
        return false;
      }
    } else if (a == "--histograms") {
      const char* v = value("--histograms");
      if (!v) return false;
      args->histograms_dir = v;
    } else if (a == "--noise-curve") {
      const char* v = value("--noise-curve");
      if (!v) return false;
      args->noise_dir = v;
    } else {
      std::cerr << "error: unknown argument '" << a << "'\n";
      usage(argv[0]);
      return false;
    }
  }
  return true;
}

using hybrid_vo::evaluation::median;

struct Row {
  SolverId id = SolverId::k5pt;
  std::string config, solver;
  int instances = 0;
  std::vector<double> log_rot, log_trans;
  double fail_rate = 0.0, us_per_call = 0.0, mean_solutions = 0.0;
  // The extra 3-0-1 row (VP sign known) and the DLT row; left out of the histograms.
  bool extra_row = false;
};

// Median over chunks of the mean time per call: robust to a noisy machine. A template rather
// than std::function: an indirect call per instance would be a sizeable share of the DLT row.
template <typename Call>
double time_per_call_us(int count, const Call& call) {
  const int chunk = std::max(10, std::min(1000, count / 50));
  std::vector<double> per_call;
  for (int start = 0; start + chunk <= count; start += chunk) {
    const auto t0 = std::chrono::steady_clock::now();
    for (int i = start; i < start + chunk; ++i) call(i);
    const auto t1 = std::chrono::steady_clock::now();
    per_call.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count() / chunk);
  }
  return median(per_call);
}

// Accuracy of the best solution per instance, given each instance's candidate poses.
void score(const std::vector<RelativePoses>& solutions, const std::vector<MinimalInstance>& data,
           Row* row) {
  int failures = 0;
  long total = 0;
  for (size_t i = 0; i < data.size(); ++i) {
    double best = INFINITY, rot = M_PI, trans = M_PI;
    for (const RelativePose& p : solutions[i]) {
      const double r = rotation_error(p.R, data[i].truth.R);
      const double t = translation_error(p.t, data[i].truth.t);
      if (std::max(r, t) < best) best = std::max(r, t), rot = r, trans = t;
    }
    total += static_cast<long>(solutions[i].size());
    if (!(best <= kFailThreshold)) ++failures;
    row->log_rot.push_back(std::max(kLog10Floor, std::log10(std::max(rot, 1e-300))));
    row->log_trans.push_back(std::max(kLog10Floor, std::log10(std::max(trans, 1e-300))));
  }
  row->instances = static_cast<int>(data.size());
  row->fail_rate = static_cast<double>(failures) / data.size();
  row->mean_solutions = static_cast<double>(total) / data.size();
}

void print_row(const Row& r) {
  std::printf("%s,%s,%d,%.2f,%.2f,%.5f,%.3f,%.2f\n", r.config.c_str(), r.solver.c_str(),
              r.instances, median(r.log_rot), median(r.log_trans), r.fail_rate, r.us_per_call,
              r.mean_solutions);
  std::fflush(stdout);
}

Row bench_solver(const SolverInfo& info, const std::vector<MinimalInstance>& data) {
  Row row;
  row.id = info.id;
  row.config = info.code;
  row.solver = info.function;
  RelativePoses scratch;
  scratch.reserve(32);
  long sink = 0;
  row.us_per_call = time_per_call_us(static_cast<int>(data.size()), [&](int i) {
    sink += solve_minimal(info.id, data[i].sample, &scratch);
  });
  // Capacity reserved before the calls, as for the timed ones: callgrind's count of solve_minimal
  // (doc/solvers.md) then holds the solvers' work, not the vectors' growth.
  std::vector<RelativePoses> solutions(data.size());
  for (size_t i = 0; i < data.size(); ++i) {
    solutions[i].reserve(16);
    solve_minimal(info.id, data[i].sample, &solutions[i]);
  }
  score(solutions, data, &row);
  if (sink < 0) std::puts("");  // keeps the timed calls observable
  return row;
}

// The plane's homography of a noiseless 4-0-0 instance from its truth: the first three points
// triangulated with (R, t), the plane n . X = d through them, H = R + t n^T / d.
Eigen::Matrix3d true_homography(const MinimalInstance& inst) {
  const Eigen::Matrix3d& R = inst.truth.R;
  const Eigen::Vector3d& t = inst.truth.t;
  Eigen::Vector3d X[3];
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d r = R * homogeneous(inst.sample.x1[i]), q = homogeneous(inst.sample.x2[i]);
    // lambda r + t ~ q: lambda (q x r) = -(q x t).
    const Eigen::Vector3d qr = q.cross(r), qt = q.cross(t);
    X[i] = -(qr.dot(qt) / qr.squaredNorm()) * homogeneous(inst.sample.x1[i]);
  }
  const Eigen::Vector3d n = (X[1] - X[0]).cross(X[2] - X[0]);
  return R + t * n.transpose() / n.dot(X[0]);
}

// The homography DLT alone on the 4-0-0 instances: homography_from_points_and_lines with four
// points, as relpose_homography calls it before orienting and decomposing H.
Row bench_homography_dlt(const std::vector<MinimalInstance>& data) {
  Row row;
  row.id = SolverId::kHomography4pt;
  row.config = solver_info(row.id).code;
  row.solver = "homography DLT alone (homography_from_points_and_lines)";
  row.extra_row = true;
  double sink = 0.0;
  row.us_per_call = time_per_call_us(static_cast<int>(data.size()), [&](int i) {
    Eigen::Matrix3d H;
    if (homography_from_points_and_lines(data[i].sample.x1.data(), data[i].sample.x2.data(), 4,
                                         nullptr, nullptr, 0, &H))
      sink += H(0, 0);
  });
  int failures = 0, found = 0;
  for (const MinimalInstance& inst : data) {
    Eigen::Matrix3d H;
    double error = M_PI;
    if (homography_from_points_and_lines(inst.sample.x1.data(), inst.sample.x2.data(), 4, nullptr,
                                         nullptr, 0, &H)) {
      ++found;
      Eigen::Matrix3d truth = true_homography(inst);
      truth /= truth.norm();
      error = std::min((H - truth).norm(), (H + truth).norm());
    }
    if (!(error <= kFailThreshold)) ++failures;
    const double log_error = std::max(kLog10Floor, std::log10(std::max(error, 1e-300)));
    row.log_rot.push_back(log_error);
    row.log_trans.push_back(log_error);
  }
  row.instances = static_cast<int>(data.size());
  row.fail_rate = static_cast<double>(failures) / data.size();
  row.mean_solutions = static_cast<double>(found) / data.size();
  if (sink == 12345.0) std::puts("");  // keeps the timed calls observable
  return row;
}

#ifdef HYBRID_VO_HAVE_OPENGV
// OpenGV returns E with f1^T E f2 = 0 (t and R map viewpoint 2 into 1): ours is its transpose.
std::vector<Row> bench_opengv(const std::vector<MinimalInstance>& data) {
  using opengv::bearingVectors_t;
  std::vector<bearingVectors_t> b1(data.size()), b2(data.size());
  std::vector<std::unique_ptr<opengv::relative_pose::CentralRelativeAdapter>> adapters;
  for (size_t i = 0; i < data.size(); ++i) {
    for (int k = 0; k < 5; ++k) {
      b1[i].push_back(homogeneous(data[i].sample.x1[k]).normalized());
      b2[i].push_back(homogeneous(data[i].sample.x2[k]).normalized());
    }
    adapters.push_back(
        std::make_unique<opengv::relative_pose::CentralRelativeAdapter>(b1[i], b2[i]));
  }
  const std::vector<int> indices = {0, 1, 2, 3, 4};
  auto to_poses = [&](const std::vector<Eigen::Matrix3d>& essentials, const MinimalInstance& inst) {
    MatchView view;
    view.x1 = inst.sample.x1.data();
    view.x2 = inst.sample.x2.data();
    view.num_points = 5;
    RelativePoses poses;
    for (const Eigen::Matrix3d& E : essentials) poses_from_essential(E.transpose(), view, &poses);
    return poses;
  };

  std::vector<Row> rows(2);
  size_t sink = 0;
  rows[0].config = "5-0-0";
  rows[0].solver = "opengv::fivept_nister";
  rows[0].us_per_call = time_per_call_us(static_cast<int>(data.size()), [&](int i) {
    sink += opengv::relative_pose::fivept_nister(*adapters[i], indices).size();
  });
  rows[1].config = "5-0-0";
  rows[1].solver = "opengv::fivept_stewenius";
  rows[1].us_per_call = time_per_call_us(static_cast<int>(data.size()), [&](int i) {
    sink += opengv::relative_pose::fivept_stewenius(*adapters[i], indices).size();
  });
  std::vector<RelativePoses> nister(data.size()), stewenius(data.size());
  for (size_t i = 0; i < data.size(); ++i) {
    const auto en = opengv::relative_pose::fivept_nister(*adapters[i], indices);
    nister[i] = to_poses(std::vector<Eigen::Matrix3d>(en.begin(), en.end()), data[i]);
    std::vector<Eigen::Matrix3d> real;
    for (const auto& E : opengv::relative_pose::fivept_stewenius(*adapters[i], indices)) {
      if (E.imag().norm() <= 1e-12 * E.real().norm()) real.push_back(E.real());
    }
    stewenius[i] = to_poses(real, data[i]);
  }
  score(nister, data, &rows[0]);
  score(stewenius, data, &rows[1]);
  if (sink == 0) std::puts("");
  return rows;
}
#endif

bool write_histograms(const std::string& dir, const std::vector<Row>& rows) {
  const double lo = -16.0, hi = 1.0, width = 0.25;
  const int bins = static_cast<int>((hi - lo) / width);
  std::ofstream csv(dir + "/stability_histograms.csv");
  if (!csv) return false;
  csv << "config,solver,error,bin_lo,bin_hi,count\n";
  std::vector<evaluation::PlotSeries> rot_series, trans_series;
  for (const Row& r : rows) {
    if (r.extra_row) continue;
    for (int kind = 0; kind < 2; ++kind) {
      const std::vector<double>& values = kind == 0 ? r.log_rot : r.log_trans;
      std::vector<int> counts(bins, 0);
      for (double v : values) counts[std::clamp(static_cast<int>((v - lo) / width), 0, bins - 1)]++;
      evaluation::PlotSeries s;
      s.label = ascii_code(solver_info(r.id));
      for (int b = 0; b < bins; ++b) {
        csv << r.config << ',' << r.solver << ',' << (kind == 0 ? "rotation" : "translation") << ','
            << lo + b * width << ',' << lo + (b + 1) * width << ',' << counts[b] << '\n';
        s.x.push_back(lo + (b + 0.5) * width);
        s.y.push_back(static_cast<double>(counts[b]) / std::max<size_t>(1, values.size()));
      }
      // 2-2-0 never yields a pose; its spike at log10(pi) would flatten the other curves.
      if (r.mean_solutions > 0.0) (kind == 0 ? rot_series : trans_series).push_back(s);
    }
  }
  evaluation::PlotOptions options;
  options.x_label = "log10 error [rad]";
  options.y_label = "fraction of instances";
  options.title = "Rotation error of the minimal solvers (noiseless, best solution)";
  bool ok = evaluation::write_line_plot(dir + "/stability_rotation.png", rot_series, options);
  options.title = "Translation error of the minimal solvers (noiseless, best solution)";
  ok &= evaluation::write_line_plot(dir + "/stability_translation.png", trans_series, options);
  return ok;
}

// Median pose errors against image noise: raw minimal solutions (best of them against the truth,
// as the paper's Fig. 4) and after local optimisation on 50 more points, keeping the refined
// solution of lowest cost (Fig. 5).
bool write_noise_curve(const std::string& dir, int instances, uint64_t seed) {
  const double levels_px[] = {0.0, 0.25, 0.5, 1.0, 1.5, 2.0};
  std::ofstream csv(dir + "/noise_curve.csv");
  if (!csv) return false;
  csv << "config,noise_px,median_rot_deg,median_trans_deg,median_rot_lo_deg,median_trans_lo_deg\n";
  std::vector<evaluation::PlotSeries> raw, refined;
  for (const SolverInfo& info : solver_table()) {
    if (!info.well_posed) continue;
    evaluation::PlotSeries s_raw{ascii_code(info), {}, {}}, s_lo{ascii_code(info), {}, {}};
    for (double px : levels_px) {
      MinimalInstanceOptions options;
      options.noise = px / 1000.0;
      options.lines_per_vp = 3;
      options.extra_points = 50;
      std::mt19937_64 rng(seed);
      std::vector<double> rot, trans, rot_lo, trans_lo;
      RelativePoses poses;
      for (int i = 0; i < instances; ++i) {
        const MinimalInstance inst = generate_minimal_instance(info.id, rng, options);
        solve_minimal(info.id, inst.sample, &poses);
        double best = INFINITY, r_best = M_PI, t_best = M_PI;
        double best_cost = INFINITY, r_lo = M_PI, t_lo = M_PI;
        std::vector<Eigen::Vector2d> x1 = inst.extra_x1, x2 = inst.extra_x2;
        for (int k = 0; k < info.num_points; ++k) {
          x1.push_back(inst.sample.x1[k]);
          x2.push_back(inst.sample.x2[k]);
        }
        const std::vector<Eigen::Vector3d> v1(inst.sample.v1.begin(),
                                              inst.sample.v1.begin() + info.num_vps);
        const std::vector<Eigen::Vector3d> v2(inst.sample.v2.begin(),
                                              inst.sample.v2.begin() + info.num_vps);
        for (RelativePose p : poses) {
          const double r = rotation_error(p.R, inst.truth.R), t = translation_error(p.t, inst.truth.t);
          if (std::max(r, t) < best) best = std::max(r, t), r_best = r, t_best = t;
          if (p.t.norm() == 0.0) continue;
          RelativePoseRefinementOptions refinement;
          refinement.vp_weight = 0.05;  // a 3-segment VP is ~20x less precise than a point
          const auto summary = refine_relative_pose(x1, x2, v1, v2, refinement, &p);
          if (summary.final_cost < best_cost) {
            best_cost = summary.final_cost;
            r_lo = rotation_error(p.R, inst.truth.R);
            t_lo = translation_error(p.t, inst.truth.t);
          }
        }
        rot.push_back(r_best);
        trans.push_back(t_best);
        rot_lo.push_back(r_lo);
        trans_lo.push_back(t_lo);
      }
      const double deg = 180.0 / M_PI;
      csv << info.code << ',' << px << ',' << median(rot) * deg << ',' << median(trans) * deg << ','
          << median(rot_lo) * deg << ',' << median(trans_lo) * deg << '\n';
      s_raw.x.push_back(px);
      s_raw.y.push_back(std::max(median(rot), median(trans)) * deg);
      s_lo.x.push_back(px);
      s_lo.y.push_back(std::max(median(rot_lo), median(trans_lo)) * deg);
    }
    raw.push_back(s_raw);
    refined.push_back(s_lo);
  }
  evaluation::PlotOptions options;
  options.x_label = "noise [px at f = 1000]";
  options.y_label = "median max(rot, trans) error [deg]";
  options.title = "Minimal solvers under noise (best solution, no refinement)";
  bool ok = evaluation::write_line_plot(dir + "/noise_raw.png", raw, options);
  options.title = "Minimal solvers under noise, then local optimisation on 50 points";
  ok = evaluation::write_line_plot(dir + "/noise_lo.png", refined, options) && ok;
  return ok;
}

}  // namespace
}  // namespace hybrid_vo

int main(int argc, char** argv) {
  using namespace hybrid_vo;
  Arguments args;
  if (!parse(argc, argv, &args)) return 2;

  std::printf("config,solver,instances,median_log10_rot_err,median_log10_trans_err,fail_rate,"
              "us_per_call,mean_solutions\n");
  std::vector<Row> rows;
  std::vector<MinimalInstance> five_point_data;
  if (!args.only.empty()) {
    SolverId id;
    if (!find_solver(args.only, &id)) {
      std::cerr << "error: unknown configuration '" << args.only << "'\n";
      return 2;
    }
  }
  double five_point_us = 0.0;
  for (const SolverInfo& info : solver_table()) {
    if (!args.only.empty() && args.only != info.code && args.only != ascii_code(info) &&
        args.only != info.function)
      continue;
    // The VP solvers run with unknown VP signs (both signs tried), and 3-0-1 once more with the
    // sign known, as a tracked VP gives it; that row compares with upright 3-point solvers.
    for (const bool signs_known : {false, true}) {
      if (signs_known && info.id != SolverId::k1vp3pt) continue;
      if (info.id == SolverId::k1vp3pt && args.vp_signs == (signs_known ? "unknown" : "known"))
        continue;
      std::mt19937_64 rng(args.seed + static_cast<int>(info.id));
      MinimalInstanceOptions options;
      options.orient_vps = signs_known;
      std::vector<MinimalInstance> data;
      data.reserve(args.instances);
      for (int i = 0; i < args.instances; ++i)
        data.push_back(generate_minimal_instance(info.id, rng, options));
      rows.push_back(bench_solver(info, data));
      if (signs_known) {
        rows.back().solver += " (VP sign known)";
        rows.back().extra_row = true;
      }
      print_row(rows.back());
      if (info.id == SolverId::kHomography4pt) {
        rows.push_back(bench_homography_dlt(data));
        print_row(rows.back());
      }
      if (info.id == SolverId::k5pt) five_point_data = std::move(data);
    }
    if (info.id == SolverId::k5pt) five_point_us = rows.back().us_per_call;
  }
#ifdef HYBRID_VO_HAVE_OPENGV
  if (five_point_us > 0.0) {
    const std::vector<Row> peers = bench_opengv(five_point_data);
    for (const Row& r : peers) print_row(r);
    for (const Row& r : peers)
      std::printf("# speed: %s takes %.2fx the time of relpose_5pt (median us per call, same "
                  "instances, same run)\n",
                  r.solver.c_str(), r.us_per_call / five_point_us);
  }
#else
  std::printf("# OpenGV was not found at build time: no peer timings\n");
#endif
  std::printf("# 2-2-0 is degenerate for every input (a one-parameter family of homographies fits "
              "two points and two lines); its solver returns no pose by design\n");

  int status = 0;
  if (!args.histograms_dir.empty()) {
    if (write_histograms(args.histograms_dir, rows)) {
      std::printf("# histograms written to %s\n", args.histograms_dir.c_str());
    } else {
      std::fprintf(stderr, "error: cannot write histograms to %s\n", args.histograms_dir.c_str());
      status = 1;
    }
  }
  if (!args.noise_dir.empty()) {
    if (write_noise_curve(args.noise_dir, std::min(args.instances, 2000), args.seed)) {
      std::printf("# noise curves written to %s\n", args.noise_dir.c_str());
    } else {
      std::fprintf(stderr, "error: cannot write noise curves to %s\n", args.noise_dir.c_str());
      status = 1;
    }
  }
  return status;
}
