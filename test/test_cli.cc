// The command-line tools' error paths: bad arguments and unreadable inputs give a non-zero exit
// and a message that names the problem, never a crash or a made-up pose.
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>
#include <sys/wait.h>

#include <gtest/gtest.h>

namespace {

struct Outcome {
  int exit_code = -1;
  std::string output;  // stdout and stderr
};

Outcome run(const std::string& tool, const std::string& args) {
  const std::string command = std::string(HYBRID_VO_BIN_DIR) + "/" + tool + " " + args + " 2>&1";
  Outcome outcome;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return outcome;
  std::array<char, 512> buffer{};
  while (fgets(buffer.data(), buffer.size(), pipe)) outcome.output += buffer.data();
  const int status = pclose(pipe);
  outcome.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return outcome;
}

void expect_error(const Outcome& o, const std::string& message) {
  EXPECT_GT(o.exit_code, 0) << o.output;
  EXPECT_LT(o.exit_code, 128) << "crashed: " << o.output;
  EXPECT_NE(o.output.find(message), std::string::npos) << o.output;
  EXPECT_EQ(o.output.find("R: ["), std::string::npos) << "printed a pose: " << o.output;
}

const std::string kImage = std::string(HYBRID_VO_SOURCE_DIR) + "/doc/rviz_demo.png";

TEST(PairCli, NoArgumentsPrintsUsage) { expect_error(run("hybrid_vo_pair", ""), "Usage:"); }

TEST(PairCli, MissingImage) {
  expect_error(run("hybrid_vo_pair", "/no/such.png " + kImage + " --camera 500,500,320,240"),
               "cannot read image '/no/such.png'");
}

TEST(PairCli, NonFiniteCamera) {
  expect_error(run("hybrid_vo_pair", kImage + " " + kImage + " --camera nan,500,320,240"),
               "not a finite number");
}

TEST(PairCli, WrongNumberOfCameraValues) {
  expect_error(run("hybrid_vo_pair", kImage + " " + kImage + " --camera 500,500,320"),
               "3 values given");
}

TEST(PairCli, UnknownPreset) {
  expect_error(
      run("hybrid_vo_pair", kImage + " " + kImage + " --camera 500,500,320,240 --preset bogus"),
      "unknown preset 'bogus'");
}

TEST(PairCli, MissingCamera) { expect_error(run("hybrid_vo_pair", kImage + " " + kImage), "camera"); }

TEST(EvalPairsCli, MissingDataSet) {
  expect_error(run("hybrid_vo_eval_pairs", "--format kitti /no/such/dir"), "/no/such/dir");
}

TEST(EvalPairsCli, BadOptionValues) {
  expect_error(run("hybrid_vo_eval_pairs", "--format kitti /tmp --runs 0"), "--runs");
  expect_error(run("hybrid_vo_eval_pairs", "--format kitti /tmp --presets bogus"), "bogus");
  expect_error(run("hybrid_vo_eval_pairs", "--format kitti /tmp --max-points 0"), "--max-points");
  expect_error(run("hybrid_vo_eval_pairs", "--format kitti /tmp --max-points 2x"), "--max-points");
  expect_error(run("hybrid_vo_eval_pairs", "--format kitti /tmp --point-selection grid"),
               "--point-selection");
}

// A shared data set: ../shared/data from the checkout, as the data sets' README says, or
// $HYBRID_VO_DATA.
std::string shared_data(const std::string& name) {
  const char* env = std::getenv("HYBRID_VO_DATA");
  return (env ? std::string(env) : std::string(HYBRID_VO_SOURCE_DIR) + "/../shared/data") + "/" +
         name;
}
std::string shared_kitti() { return shared_data("kitti_seq0x_51"); }

// The number after `label` in a tool's output, or NaN.
double number_after(const std::string& output, const std::string& label) {
  const size_t at = output.find(label);
  return at == std::string::npos ? NAN : std::atof(output.c_str() + at + label.size());
}

// The rows of hybrid_vo_eval_pairs' CSV after the header, split at commas.
std::vector<std::vector<std::string>> csv_rows(const std::string& path) {
  std::vector<std::vector<std::string>> out;
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    std::vector<std::string> fields;
    std::stringstream row(line);
    for (std::string f; std::getline(row, f, ',');) fields.push_back(f);
    out.push_back(fields);
  }
  return out;
}

// On the shared KITTI frames when present: every run of every method sees exactly N points.
TEST(EvalPairsCli, MaxPointsKeepsExactlyNMatches) {
  const std::string data = shared_kitti();
  if (!std::ifstream(data + "/sequences/seq0x/times.txt")) GTEST_SKIP() << data << " not present";
  const std::string csv = testing::TempDir() + "/eval_pairs_max_points.csv";
  const Outcome o = run("hybrid_vo_eval_pairs", "--format kitti " + data +
                                                    " --max-pairs 2 --runs 2 --presets "
                                                    "5pc,hybrid,opencv_usac_magsac --max-points "
                                                    "20,all --point-selection random,clustered "
                                                    "--csv " + csv);
  ASSERT_EQ(o.exit_code, 0) << o.output;
  EXPECT_NE(o.output.find("max_points,selection,method,auc5"), std::string::npos) << o.output;
  EXPECT_NE(o.output.find("20,clustered,hybrid,"), std::string::npos) << o.output;
  // The ground truth check runs on the first preset, one value per pair.
  EXPECT_NE(o.output.find("# ground truth check: 5pc's point inliers fit the true pose to"),
            std::string::npos)
      << o.output;
  EXPECT_NE(o.output.find("over 2 pairs)"), std::string::npos) << o.output;
  int limited = 0, all = 0;
  for (const std::vector<std::string>& fields : csv_rows(csv)) {
    ASSERT_EQ(fields.size(), 14u) << fields[0];
    const int points = std::stoi(fields[7]);
    if (fields[11] == "20") {
      EXPECT_EQ(points, 20) << fields[0];
      ++limited;
    } else {
      EXPECT_GT(points, 100) << fields[0];
      ++all;
    }
  }
  EXPECT_EQ(limited, 2 * 2 * 2 * 3);  // pairs x runs x selections x methods
  EXPECT_EQ(all, 2 * 2 * 3);
}

// --held-out: the methods see half the points, and every run is scored on the other half.
TEST(EvalPairsCli, HeldOutScoresTheOtherHalf) {
  const std::string data = shared_kitti();
  if (!std::ifstream(data + "/sequences/seq0x/times.txt")) GTEST_SKIP() << data << " not present";
  const std::string csv = testing::TempDir() + "/eval_pairs_held_out.csv";
  const std::string common = "--format kitti " + data + " --max-pairs 2 --presets 5pc --csv ";
  const Outcome all = run("hybrid_vo_eval_pairs", common + csv);
  ASSERT_EQ(all.exit_code, 0) << all.output;
  const auto before = csv_rows(csv);
  const Outcome o = run("hybrid_vo_eval_pairs", common + csv + " --held-out");
  ASSERT_EQ(o.exit_code, 0) << o.output;
  EXPECT_NE(o.output.find("held-out cost (0 best, 1 worst), mean over pairs and runs: 5pc "),
            std::string::npos)
      << o.output;
  EXPECT_NE(o.output.find(", true pose "), std::string::npos) << o.output;
  const auto after = csv_rows(csv);
  ASSERT_EQ(before.size(), 2u);
  ASSERT_EQ(after.size(), 2u);
  for (size_t i = 0; i < after.size(); ++i) {
    ASSERT_EQ(after[i].size(), 14u);
    EXPECT_EQ(before[i][13], "nan");
    EXPECT_EQ(std::stoi(after[i][7]), std::stoi(before[i][7]) / 2);  // the estimation half
    const double cost = std::stod(after[i][13]);
    EXPECT_GE(cost, 0.0);
    EXPECT_LT(cost, 0.5);  // KITTI's 5pc explains most held-out matches
  }
  // With --max-points the methods keep their N matches and are scored on all the others.
  const Outcome few = run("hybrid_vo_eval_pairs", common + csv + " --held-out --max-points 20");
  ASSERT_EQ(few.exit_code, 0) << few.output;
  EXPECT_NE(few.output.find("# 20,random: held-out cost"), std::string::npos) << few.output;
  const auto limited = csv_rows(csv);
  ASSERT_EQ(limited.size(), 2u);
  for (const auto& row : limited) {
    ASSERT_EQ(row.size(), 14u);
    EXPECT_EQ(std::stoi(row[7]), 20);
    const double cost = std::stod(row[13]);
    EXPECT_GE(cost, 0.0);
    EXPECT_LE(cost, 1.0);
  }
}

// Reads "<label> - direct: median X deg" from bench_frontend's --direct-gap lines; NaN if absent.
double direct_median(const std::string& output, const std::string& label) {
  const std::string key = label + " - direct: median ";
  const size_t at = output.find(key);
  return at == std::string::npos ? std::nan("") : std::atof(output.c_str() + at + key.size());
}

// On the shared KITTI frames when present: --trajectory writes every frame's pose, and
// --direct-gap compares the odometry's and the truth's rotations over G frames with direct
// two-view estimates. KITTI's truth is known to be 3-5 times further from them than the
// odometry (doc/vanishing_points.md, "Through the node").
TEST(BenchFrontendCli, TrajectoryAndDirectCheck) {
  const std::string data = shared_kitti();
  if (!std::ifstream(data + "/sequences/seq0x/times.txt")) GTEST_SKIP() << data << " not present";
  const std::string path = testing::TempDir() + "/bench_frontend_trajectory.txt";
  const Outcome o = run("hybrid_vo_bench_frontend", data + "/sequences/seq0x --frames 12 "
                                                        "--preset 5pc --direct-gap 2 "
                                                        "--trajectory " + path);
  ASSERT_EQ(o.exit_code, 0) << o.output;
  EXPECT_NE(o.output.find("rotation over 2 frames against a direct two-view estimate (10 of 10 "
                          "pairs estimated)"),
            std::string::npos)
      << o.output;
  const double odometry = direct_median(o.output, "odometry");
  const double truth = direct_median(o.output, "truth");
  EXPECT_GT(odometry, 0.0) << o.output;
  EXPECT_GT(truth, 3.0 * odometry) << o.output;
  // The fitted offset is a larger rotation in the truth, about tilted axes.
  const std::string fitted = "truth - direct, fitted: the truth turns +";
  const size_t at = o.output.find(fitted);
  ASSERT_NE(at, std::string::npos) << o.output;
  EXPECT_GT(std::atof(o.output.c_str() + at + fitted.size()), 0.1) << o.output;
  std::ifstream in(path);
  std::string line;
  int poses = 0;
  while (std::getline(in, line))
    if (!line.empty() && line[0] != '#') ++poses;
  EXPECT_EQ(poses, 12);
  expect_error(run("hybrid_vo_bench_frontend", data + "/sequences/seq0x --frames 2 --trajectory "
                                                      "/no/such/folder/t.txt"),
               "/no/such/folder/t.txt: cannot write");
}

// Issue 30, on the shared white panels when present (TUM fr3 structure_notexture_far): segments,
// junctions and VPs are found, and the orientation after 126 frames drifts less than half as
// far with them as with points alone (15.4 deg before segments tracked there).
TEST(BenchFrontendCli, LowTextureLinesHoldTheOrientation) {
  const std::string data = shared_data("tum_fr3_structure_notexture_far");
  if (!std::ifstream(data + "/sequences/00/times.txt")) GTEST_SKIP() << data << " not present";
  const std::string args = data + "/sequences/00 --max-features 1000 --sequential --preset ";
  const Outcome lines = run("hybrid_vo_bench_frontend", args + "hybrid+junc");
  const Outcome points = run("hybrid_vo_bench_frontend", args + "5pc");
  ASSERT_EQ(lines.exit_code, 0) << lines.output;
  ASSERT_EQ(points.exit_code, 0) << points.output;
  EXPECT_GE(number_after(lines.output, "per estimated frame: line matches "), 6.0) << lines.output;
  EXPECT_GE(number_after(lines.output, "per estimated frame: junctions "), 1.0) << lines.output;
  EXPECT_GE(number_after(lines.output, " inliers), VPs "), 1.0) << lines.output;
  const std::string last = "orientation against the first frame ";
  const double with_lines = number_after(lines.output, last);
  const double with_points = number_after(points.output, last);
  EXPECT_LT(with_lines, 0.6 * with_points) << lines.output << points.output;
  EXPECT_LT(with_lines, 10.0) << lines.output;
}

// Issue 52, on the shared KITTI 06 street when present: its facades are not parallel to each
// other, and the map of directions once re-acquired the wrong one (2.07 degrees at the last frame
// against 0.94 without the map). Now the map is never worse than the pairs alone, as the issue's
// acceptance asks: over 1 s at most 1.05x + 0.01 degrees, the last frame 1.1x + 0.02, the
// largest 1.1x + 0.05.
TEST(BenchFrontendCli, KittiStreetTheMapIsNeverWorse) {
  const std::string data = shared_data("kitti06_stereo_51");
  if (!std::ifstream(data + "/sequences/06/times.txt")) GTEST_SKIP() << data << " not present";
  const std::string args = data + "/sequences/06 --sequential --seed 1";
  const Outcome with = run("hybrid_vo_bench_frontend", args);
  const Outcome without = run("hybrid_vo_bench_frontend", args + " --no-direction-map");
  ASSERT_EQ(with.exit_code, 0) << with.output;
  ASSERT_EQ(without.exit_code, 0) << without.output;
  // Over 1 s, at the last frame, at most.
  const std::regex line(R"(([\d.]+) over [\d.]+ s windows \(\d+\), orientation against the first )"
                        R"(frame ([\d.]+) at the last frame and ([\d.]+) at most)");
  std::smatch a, b;
  ASSERT_TRUE(std::regex_search(with.output, a, line)) << with.output;
  ASSERT_TRUE(std::regex_search(without.output, b, line)) << without.output;
  const double factor[] = {1.05, 1.1, 1.1}, offset[] = {0.01, 0.02, 0.05};
  for (int k = 0; k < 3; ++k)
    EXPECT_LE(std::stod(a[k + 1]), factor[k] * std::stod(b[k + 1]) + offset[k])
        << a[0] << "\nwithout the map: " << b[0];
}

TEST(BenchFrontendCli, BadDirectGap) {
  for (const char* gap : {"0", "-3", "four"})
    expect_error(run("hybrid_vo_bench_frontend", std::string("/no/sequence --direct-gap ") + gap),
                 "--direct-gap: expected a number of frames >= 1");
}

TEST(BenchFrontendCli, BadTruthSigma) {
  for (const char* option : {"--truth-rotation-sigma-deg", "--truth-direction-sigma-deg",
                             "--truth-orientation-sigma-deg"})
    for (const char* sigma : {"-1", "nan", "0.1deg"})
      expect_error(run("hybrid_vo_bench_frontend",
                       std::string("/no/sequence ") + option + " " + sigma),
                   std::string(option) + ": expected a number of degrees >= 0");
}

// hybrid_vo_render_pan with doc/rviz_demo.png (1600 x 900) as the photograph.
TEST(RenderPanCli, BadInputsAreNamed) {
  const std::string out = testing::TempDir() + "/render_pan_cli";
  expect_error(run("hybrid_vo_render_pan", "--kitti-dir " + out), "--photo");
  expect_error(run("hybrid_vo_render_pan", "--photo /no/such.jpg --K 800,800,799.5,449.5 "
                                           "--kitti-dir " + out),
               "/no/such.jpg");
  expect_error(run("hybrid_vo_render_pan", "--photo " + kImage + " --kitti-dir " + out),
               "no intrinsics for " + kImage);
  const std::string camera = testing::TempDir() + "/render_pan_cli.camera";
  std::ofstream(camera) << "2759.48 0 1520.69\n0 2764.16 1006.81\n";
  expect_error(run("hybrid_vo_render_pan",
                   "--photo " + kImage + " --camera " + camera + " --kitti-dir " + out),
               camera + ":2: expected 26 numbers");
  expect_error(run("hybrid_vo_render_pan", "--photo " + kImage +
                                               " --camera /no/such.camera --kitti-dir " + out),
               "/no/such.camera");
  // f 2000 in the photograph (22 degrees to its sides) and 1000 in the view (18 to its own):
  // an 8-degree yaw leaves the photograph.
  expect_error(run("hybrid_vo_render_pan", "--photo " + kImage +
                                               " --K 2000,2000,799.5,449.5 --kitti-dir " + out),
               "view leaves the 1600x900 photograph");
}

TEST(RenderPanCli, WritesTheKeptFrames) {
  const std::string out = testing::TempDir() + "/render_pan_cli_ok";
  std::system(("rm -rf " + out).c_str());
  const Outcome o = run("hybrid_vo_render_pan",
                        "--photo " + kImage + " --K 1200,1200,799.5,449.5 --width 320 --height 240 "
                        "--focal 500 --frames 20 --drop-every 4 --kitti-name pan --kitti-dir " +
                            out);
  ASSERT_EQ(o.exit_code, 0) << o.output;
  EXPECT_NE(o.output.find("rendered 15 of 20 frames (5 dropped)"), std::string::npos) << o.output;
  std::ifstream times(out + "/sequences/pan/times.txt"), poses(out + "/poses/pan.txt");
  std::vector<double> stamps;
  for (double t; times >> t;) stamps.push_back(t);
  ASSERT_EQ(stamps.size(), 15u);
  EXPECT_NEAR(stamps[3], 4.0 / 30.0, 1e-8);  // frame 3 left out
  int lines = 0;
  for (std::string line; std::getline(poses, line);) ++lines;
  EXPECT_EQ(lines, 15);
  EXPECT_TRUE(std::ifstream(out + "/sequences/pan/image_0/000014.png").good());
}

TEST(EvalTrajectoryCli, MissingBag) {
  expect_error(run("hybrid_vo_eval_trajectory", "--bag /no/run.bag --gt /no/gt.bag"),
               "/no/run.bag");
}

// The value of "key=" on the summary line; NaN when absent.
double summary_value(const std::string& output, const std::string& key) {
  const size_t line = output.rfind("summary:");
  if (line == std::string::npos) return std::nan("");
  const size_t at = output.find(" " + key + "=", line);
  return at == std::string::npos ? std::nan("") : std::atof(output.c_str() + at + key.size() + 2);
}

// Two TUM files: a camera moving along x at 25 Hz, and an estimate that turns 0.1 degrees per
// frame too many about z. The rotation measures read 0.1 per pair, 2.5 over 1 s (25 frames), 6
// at the last frame (60 frames) and at most; seen from camera i the path is i * 0.1 degrees
// off, so the median translation direction error is that of the middle pair, 3.
TEST(EvalTrajectoryCli, TumRotationMeasures) {
  const std::string dir = testing::TempDir();
  const std::string truth = dir + "/eval_trajectory_truth.txt";
  const std::string estimate = dir + "/eval_trajectory_estimate.txt";
  {
    std::ofstream t(truth), e(estimate);
    for (int k = 0; k <= 60; ++k) {
      const double stamp = 10.0 + k / 25.0, half = 0.5 * 0.1 * k * M_PI / 180.0;
      char line[256];
      std::snprintf(line, sizeof(line), "%.6f %.3f 0 0 0 0 0 1\n", stamp, 0.1 * k);
      t << line;
      std::snprintf(line, sizeof(line), "%.6f %.3f 0 0 0 0 %.12f %.12f\n", stamp, 0.1 * k,
                    std::sin(half), std::cos(half));
      e << line;
    }
  }
  const Outcome o = run("hybrid_vo_eval_trajectory", "--tum " + estimate + " " + truth);
  ASSERT_EQ(o.exit_code, 0) << o.output;
  // 36 windows of 1 s, and 2 ending at the last pose within 10 % of a second.
  EXPECT_NE(o.output.find("# rotation error (deg): median 0.100 per pair (60 pairs of "
                          "consecutive poses), 2.500 over 1 s windows (38)"),
            std::string::npos)
      << o.output;
  EXPECT_NEAR(summary_value(o.output, "pairs"), 60.0, 1e-9) << o.output;
  EXPECT_NEAR(summary_value(o.output, "rot_pair_deg"), 0.1, 1e-3) << o.output;
  EXPECT_NEAR(summary_value(o.output, "rot_window_deg"), 2.5, 1e-3) << o.output;
  EXPECT_NEAR(summary_value(o.output, "window_s"), 1.0, 1e-9) << o.output;
  EXPECT_NEAR(summary_value(o.output, "orient_last_deg"), 6.0, 1e-3) << o.output;
  EXPECT_NEAR(summary_value(o.output, "orient_max_deg"), 6.0, 1e-3) << o.output;
  EXPECT_NEAR(summary_value(o.output, "dir_deg"), 3.0, 1e-3) << o.output;
  // TUM files carry no covariances: the NEES fields close the line, without a value.
  for (const char* key : {"nees_rot_pair", "in95_rot_pair", "nees_orient", "in95_orient"})
    EXPECT_TRUE(std::isnan(summary_value(o.output, key))) << key << ": " << o.output;
  EXPECT_NE(o.output.find("dir_deg=3.000 nees_rot_pair=nan in95_rot_pair=nan nees_orient=nan "
                          "in95_orient=nan\n"),
            std::string::npos)
      << o.output;
  // Windows of 0.6 s: 15 frames.
  const Outcome shorter =
      run("hybrid_vo_eval_trajectory", "--tum " + estimate + " " + truth + " --window 0.6");
  ASSERT_EQ(shorter.exit_code, 0) << shorter.output;
  EXPECT_NEAR(summary_value(shorter.output, "rot_window_deg"), 1.5, 1e-3) << shorter.output;
  EXPECT_NEAR(summary_value(shorter.output, "window_s"), 0.6, 1e-9) << shorter.output;
  for (const char* bad : {"0", "-1", "nan", "1s"})
    expect_error(run("hybrid_vo_eval_trajectory",
                     "--tum " + estimate + " " + truth + " --window " + bad),
                 "--window: expected a positive number of seconds");
  for (const char* option : {"--truth-rotation-sigma-deg", "--truth-direction-sigma-deg",
                             "--truth-orientation-sigma-deg"})
    expect_error(run("hybrid_vo_eval_trajectory",
                     "--tum " + estimate + " " + truth + " " + option + " -0.5"),
                 std::string(option) + ": expected a number of degrees >= 0");
}

}  // namespace
