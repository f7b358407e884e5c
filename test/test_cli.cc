// The command-line tools' error paths: bad arguments and unreadable inputs give a non-zero exit
// and a message that names the problem, never a crash or a made-up pose.
#include <array>
#include <cstdio>
#include <string>
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
}

TEST(EvalTrajectoryCli, MissingBag) {
  expect_error(run("hybrid_vo_eval_trajectory", "--bag /no/run.bag --gt /no/gt.bag"),
               "/no/run.bag");
}

}  // namespace
