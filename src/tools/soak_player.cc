// hybrid_vo_soak_player: replays one camera of a bag to a running hybrid_vo node over and over,
// with stamps that keep increasing (one rendered lap becomes an hour-long walk), either at a
// fixed rate or in lock-step (each frame waits for the node's answer: the fastest rate the node
// keeps up with). Every --sample seconds it samples the node's RSS and CPU (/proc/PID) and the
// frames' latency (publication to the node's ~relative_pose) into a CSV, and at the end prints
//   summary: frames=... dropped=... rss_start_mb=... rss_end_mb=... rss_slope_mb_per_h=...
//            latency_p50_ms=... latency_p99_ms=... (and the rate, CPU and counters)
// The RSS slope is fitted from steady_from_s: after the warm-up, once the node's bounded buffers
// are full (--full-after answers), so that a buffer filling up to its bound is not read as a
// leak. scripts/soak drives it.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <hybrid_vo/MotionEstimate.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/exceptions.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <tf2_msgs/TFMessage.h>

namespace {

using Clock = std::chrono::steady_clock;

struct Options {
  std::string bag, camera = "left", csv, node = "hybrid_vo";
  int frames = 0;      // 0: one pass over the bag
  double rate = 0.0;   // frames per second; 0: lock-step
  int pid = 0;         // the node's process, sampled from /proc
  double sample_s = 10.0;
  double warmup_s = -1.0;  // < 0: 20 % of the run, at most 120 s
  int full_after = 0;      // answers after which the node's bounded buffers are full
  double answer_timeout_s = 5.0;
};

const char kUsage[] =
    "Usage: hybrid_vo_soak_player --bag LOOP.bag [options]\n"
    "Publishes /camera/<camera>/{image_raw,camera_info} from the bag in a loop with increasing\n"
    "stamps to a hybrid_vo node and measures it.\n"
    "  --camera NAME   camera of the bag (default left)\n"
    "  --frames N      frames to publish (default: the bag once)\n"
    "  --rate HZ       frames per second; 0 = lock-step, each frame waits for the answer\n"
    "  --pid PID       the node's process id, for RSS and CPU\n"
    "  --csv FILE      per-sample CSV\n"
    "  --sample S      sampling period in seconds (default 10)\n"
    "  --warmup S      seconds left out of the RSS slope and the latency percentiles\n"
    "                  (default 20 % of the run, at most 120)\n"
    "  --full-after N  answers after which the node's bounded buffers (its ~path) are full:\n"
    "                  the RSS slope starts there when that is after the warm-up\n"
    "  --node NAME     the node's name (default hybrid_vo)\n";

bool parse_args(int argc, char** argv, Options* o, std::string* error) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      *error = "";
      return false;
    }
    if (i + 1 >= argc) {
      *error = arg + " needs a value";
      return false;
    }
    const std::string v = argv[++i];
    char* end = nullptr;
    const double number = std::strtod(v.c_str(), &end);
    const bool numeric = !v.empty() && *end == '\0' && std::isfinite(number);
    if (arg == "--bag") {
      o->bag = v;
    } else if (arg == "--camera") {
      o->camera = v;
    } else if (arg == "--csv") {
      o->csv = v;
    } else if (arg == "--node") {
      o->node = v;
    } else if (arg == "--frames" && numeric && number >= 1) {
      o->frames = static_cast<int>(number);
    } else if (arg == "--rate" && numeric && number >= 0) {
      o->rate = number;
    } else if (arg == "--pid" && numeric && number >= 1) {
      o->pid = static_cast<int>(number);
    } else if (arg == "--sample" && numeric && number > 0) {
      o->sample_s = number;
    } else if (arg == "--warmup" && numeric && number >= 0) {
      o->warmup_s = number;
    } else if (arg == "--full-after" && numeric && number >= 0) {
      o->full_after = static_cast<int>(number);
    } else {
      *error = "bad argument '" + arg + " " + v + "'";
      return false;
    }
  }
  if (o->bag.empty()) {
    *error = "--bag is required";
    return false;
  }
  return true;
}

// Resident memory (MB) and CPU time (s) of a process; false when it is gone.
bool read_process(int pid, double* rss_mb, double* cpu_s) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  bool have_rss = false;
  while (std::getline(status, line)) {
    if (line.rfind("VmRSS:", 0) == 0) {
      *rss_mb = std::atof(line.c_str() + 6) / 1024.0;
      have_rss = true;
    }
  }
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string text((std::istreambuf_iterator<char>(stat)), std::istreambuf_iterator<char>());
  const size_t paren = text.rfind(')');  // the command name may hold spaces
  if (!have_rss || paren == std::string::npos) return false;
  std::istringstream fields(text.substr(paren + 2));
  std::string field;
  double utime = 0, stime = 0;
  for (int k = 3; fields >> field; ++k) {  // field 3 is the state
    if (k == 14) utime = std::atof(field.c_str());
    if (k == 15) {
      stime = std::atof(field.c_str());
      break;
    }
  }
  *cpu_s = (utime + stime) / static_cast<double>(sysconf(_SC_CLK_TCK));
  return true;
}

// The machine's 1-minute load average (other processes compete for the cores).
double load_average() {
  std::ifstream in("/proc/loadavg");
  double load = 0.0;
  in >> load;
  return load;
}

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  const size_t k = std::min(v.size() - 1, static_cast<size_t>(q * (v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[k];
}

// Least-squares slope of y over x.
double slope(const std::vector<double>& x, const std::vector<double>& y) {
  if (x.size() < 2) return 0.0;
  double mx = 0, my = 0;
  for (size_t i = 0; i < x.size(); ++i) {
    mx += x[i];
    my += y[i];
  }
  mx /= x.size();
  my /= y.size();
  double sxy = 0, sxx = 0;
  for (size_t i = 0; i < x.size(); ++i) {
    sxy += (x[i] - mx) * (y[i] - my);
    sxx += (x[i] - mx) * (x[i] - mx);
  }
  return sxx > 0 ? sxy / sxx : 0.0;
}

struct Frame {
  sensor_msgs::Image image;
  sensor_msgs::CameraInfo info;
};

class Player {
 public:
  explicit Player(const Options& options) : o_(options) {}

  bool load(std::string* error) {
    const std::string image_topic = "/camera/" + o_.camera + "/image_raw";
    const std::string info_topic = "/camera/" + o_.camera + "/camera_info";
    std::map<ros::Time, Frame> frames;
    try {
      rosbag::Bag bag(o_.bag, rosbag::bagmode::Read);
      for (const rosbag::MessageInstance& m : rosbag::View(bag)) {
        if (m.getTopic() == image_topic) {
          if (const auto image = m.instantiate<sensor_msgs::Image>())
            frames[image->header.stamp].image = *image;
        } else if (m.getTopic() == info_topic) {
          if (const auto info = m.instantiate<sensor_msgs::CameraInfo>())
            frames[info->header.stamp].info = *info;
        } else if (m.getTopic() == "/tf_static") {
          if (const auto tf = m.instantiate<tf2_msgs::TFMessage>()) statics_ = *tf;
        }
      }
    } catch (const rosbag::BagException& e) {
      *error = o_.bag + ": " + e.what();
      return false;
    }
    for (const auto& [stamp, frame] : frames)
      if (!frame.image.data.empty() && frame.info.width > 0) frames_.push_back(frame);
    if (frames_.size() < 2) {
      *error = o_.bag + ": fewer than 2 frames with image and camera_info on " + image_topic;
      return false;
    }
    // Replayed stamps advance by the bag's mean frame period, across the loop's seam too.
    period_ = (frames_.back().image.header.stamp - frames_.front().image.header.stamp).toSec() /
              (frames_.size() - 1);
    first_stamp_ = frames_.front().image.header.stamp;
    if (o_.frames == 0) o_.frames = static_cast<int>(frames_.size());
    return true;
  }

  int run() {
    ros::NodeHandle nh;
    const std::string prefix = "/camera/" + o_.camera;
    // rosbag play's outgoing queue (100): a short stall of the node's receiving thread under
    // overload must not lose frames in the player, where the node cannot count them.
    image_pub_ = nh.advertise<sensor_msgs::Image>(prefix + "/image_raw", 100);
    info_pub_ = nh.advertise<sensor_msgs::CameraInfo>(prefix + "/camera_info", 100);
    static_pub_ = nh.advertise<tf2_msgs::TFMessage>("/tf_static", 1, true);
    motion_sub_ = nh.subscribe("/" + o_.node + "/relative_pose", 1000, &Player::on_motion, this,
                               ros::TransportHints().tcpNoDelay());
    diagnostics_sub_ = nh.subscribe("/diagnostics", 10, &Player::on_diagnostics, this);
    ros::AsyncSpinner spinner(1);
    spinner.start();
    if (!statics_.transforms.empty()) static_pub_.publish(statics_);
    const Clock::time_point wait_end = Clock::now() + std::chrono::seconds(30);
    // Both ends of every topic: an answer sent before this subscription connects is lost, and
    // would count as a dropped frame.
    auto connected = [&] {
      return image_pub_.getNumSubscribers() > 0 && info_pub_.getNumSubscribers() > 0 &&
             motion_sub_.getNumPublishers() > 0;
    };
    while (ros::ok() && !connected()) {
      if (Clock::now() > wait_end) {
        std::cerr << "soak: the node does not subscribe " << prefix
                  << "/image_raw or does not publish ~relative_pose\n";
        return 1;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(500));

    const double expected_s = o_.rate > 0 ? o_.frames / o_.rate : o_.frames * 0.05;
    warmup_s_ = o_.warmup_s >= 0 ? o_.warmup_s : std::min(120.0, 0.2 * expected_s);
    std::ofstream csv;
    if (!o_.csv.empty()) {
      csv.open(o_.csv);
      csv << "time_s,frames_sent,frames_answered,queue_drops,rss_mb,cpu_percent,"
             "latency_p50_ms,latency_p99_ms,latency_max_ms,answers_per_s,load1\n";
    }
    start_ = Clock::now();
    Clock::time_point next_sample = start_;
    double last_cpu = 0.0, last_sample_t = 0.0;
    int last_answered = 0;
    bool have_cpu = false;
    auto sample = [&](double t) {
      double rss = 0.0, cpu = 0.0;
      const bool alive = o_.pid > 0 && read_process(o_.pid, &rss, &cpu);
      std::vector<double> window;
      int answered = 0;
      int drops = 0;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        window.swap(window_latencies_);
        answered = static_cast<int>(answers_.size());
        drops = queue_drops_;
      }
      const double dt = t - last_sample_t;
      const double cpu_percent = alive && have_cpu && dt > 0 ? 100.0 * (cpu - last_cpu) / dt : 0.0;
      const double rate = dt > 0 ? (answered - last_answered) / dt : 0.0;
      const double load = load_average();
      if (t > 0) {
        samples_t_.push_back(t);
        samples_rss_.push_back(rss);
        samples_cpu_.push_back(cpu_percent);
        samples_load_.push_back(load);
      }
      if (csv.is_open()) {
        char row[256];
        std::snprintf(row, sizeof(row), "%.1f,%d,%d,%d,%.2f,%.1f,%.2f,%.2f,%.2f,%.2f,%.2f\n", t,
                      sent_, answered, drops, rss, cpu_percent, quantile(window, 0.5),
                      quantile(window, 0.99), window.empty() ? 0.0 : quantile(window, 1.0), rate,
                      load);
        csv << row << std::flush;
      }
      last_cpu = cpu;
      have_cpu = alive;
      last_sample_t = t;
      last_answered = answered;
    };

    // At a rate, the first frame is answered before the second is sent: a node's first frame
    // (its first keyframe, OpenCV's and the thread pools' set-up) took 370 ms on a loaded
    // machine, which is no measure of keeping up. The schedule starts again from its answer.
    Clock::time_point schedule = start_;
    for (int k = 0; k < o_.frames && ros::ok(); ++k) {
      if (o_.rate > 0 && k == 1) {
        wait_for_answer(stamp_of(0));
        schedule = std::max(schedule, Clock::now() - std::chrono::duration_cast<Clock::duration>(
                                                         std::chrono::duration<double>(1.0 / o_.rate)));
      }
      if (o_.rate > 0) {
        std::this_thread::sleep_until(schedule + std::chrono::duration_cast<Clock::duration>(
                                                     std::chrono::duration<double>(k / o_.rate)));
      } else if (k > 0) {
        wait_for_answer(stamp_of(k - 1));
      }
      const Clock::time_point now = Clock::now();
      if (now >= next_sample) {
        sample(seconds_since_start(now));
        next_sample += std::chrono::duration_cast<Clock::duration>(
            std::chrono::duration<double>(o_.sample_s));
      }
      publish(k);
    }
    // The last answers, then a final sample.
    if (o_.frames > 0) wait_for_answer(stamp_of(o_.frames - 1));
    std::this_thread::sleep_for(std::chrono::milliseconds(1500));
    sample(seconds_since_start(Clock::now()));
    spinner.stop();
    print_summary();
    return 0;
  }

 private:
  ros::Time stamp_of(int k) const { return first_stamp_ + ros::Duration(k * period_); }
  double seconds_since_start(Clock::time_point t) const {
    return std::chrono::duration<double>(t - start_).count();
  }

  void publish(int k) {
    const Frame& f = frames_[k % frames_.size()];
    const ros::Time stamp = stamp_of(k);
    sensor_msgs::ImagePtr image(new sensor_msgs::Image(f.image));
    sensor_msgs::CameraInfoPtr info(new sensor_msgs::CameraInfo(f.info));
    image->header.stamp = info->header.stamp = stamp;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      sent_at_[stamp] = Clock::now();
      ++sent_;
    }
    image_pub_.publish(image);
    info_pub_.publish(info);
  }

  void wait_for_answer(const ros::Time& stamp) {
    std::unique_lock<std::mutex> lock(mutex_);
    answered_.wait_for(lock, std::chrono::duration<double>(o_.answer_timeout_s),
                       [&] { return answers_.count(stamp) > 0 || !ros::ok(); });
  }

  void on_motion(const hybrid_vo::MotionEstimate::ConstPtr& m) {
    const Clock::time_point now = Clock::now();
    std::lock_guard<std::mutex> lock(mutex_);
    const auto sent = sent_at_.find(m->header.stamp);
    if (sent == sent_at_.end()) return;
    const double ms = std::chrono::duration<double, std::milli>(now - sent->second).count();
    if (answers_.emplace(m->header.stamp, ms).second) {
      if (full_at_s_ < 0 && static_cast<int>(answers_.size()) >= o_.full_after)
        full_at_s_ = seconds_since_start(now);
      window_latencies_.push_back(ms);
      if (seconds_since_start(sent->second) >= warmup_s_) steady_latencies_.push_back(ms);
      ok_ += m->status == hybrid_vo::MotionEstimate::STATUS_OK;
    }
    sent_at_.erase(sent);
    answered_.notify_all();
  }

  void on_diagnostics(const diagnostic_msgs::DiagnosticArray::ConstPtr& d) {
    for (const auto& s : d->status) {
      if (s.name.find("odometry") == std::string::npos) continue;
      std::lock_guard<std::mutex> lock(mutex_);
      for (const auto& kv : s.values) {
        if (kv.key == "frames dropped (queue full)") queue_drops_ = std::atoi(kv.value.c_str());
        if (kv.key == "incomplete frames dropped") incomplete_drops_ = std::atoi(kv.value.c_str());
      }
    }
  }

  void print_summary() {
    // Growth while a bounded buffer fills is no leak: the slope is fitted once every one is
    // full (and the warm-up is over); never, when they never filled.
    const double steady_from =
        full_at_s_ < 0 ? std::numeric_limits<double>::infinity() : std::max(warmup_s_, full_at_s_);
    std::vector<double> t, rss;
    for (size_t i = 0; i < samples_t_.size(); ++i) {
      if (samples_t_[i] < steady_from) continue;
      t.push_back(samples_t_[i] / 3600.0);
      rss.push_back(samples_rss_[i]);
    }
    double cpu_mean = 0.0, load_mean = 0.0;
    for (double c : samples_cpu_) cpu_mean += c / std::max<size_t>(1, samples_cpu_.size());
    for (double l : samples_load_) load_mean += l / std::max<size_t>(1, samples_load_.size());
    const double duration = samples_t_.empty() ? 0.0 : samples_t_.back();
    std::lock_guard<std::mutex> lock(mutex_);
    const int answered = static_cast<int>(answers_.size());
    // A run shorter than its warm-up (a fast node in lock-step) has no steady latencies: all
    // answers count then, rather than reporting a latency of zero and an infinite rate.
    std::vector<double> latencies = steady_latencies_;
    if (latencies.empty())
      for (const auto& answer : answers_) latencies.push_back(answer.second);
    const double p99 = quantile(latencies, 0.99);
    // Fed at a rate: the latency in frame periods. In lock-step: the sustainable rate, at which
    // 95 % of the frames are done before the next one comes (each cycle is one latency).
    const std::string rate_field =
        o_.rate > 0 ? "latency_p99_periods=" + std::to_string(p99 * o_.rate / 1000.0)
                    : "sustainable_hz=" +
                          std::to_string(1000.0 / std::max(1e-3, quantile(latencies, 0.95)));
    std::printf(
        "summary: frames=%d dropped=%d rss_start_mb=%.1f rss_end_mb=%.1f "
        "rss_slope_mb_per_h=%.2f latency_p50_ms=%.1f latency_p99_ms=%.1f rate_hz=%.2f "
        "cpu_percent=%.1f ok=%d queue_drops=%d incomplete_drops=%d duration_s=%.0f warmup_s=%.0f "
        "steady_from_s=%.0f load1=%.1f %s\n",
        sent_, sent_ - answered, rss.empty() ? 0.0 : rss.front(), rss.empty() ? 0.0 : rss.back(),
        slope(t, rss), quantile(latencies, 0.5), p99,
        duration > 0 ? answered / duration : 0.0, cpu_mean, ok_, queue_drops_, incomplete_drops_, duration, warmup_s_,
        std::isfinite(steady_from) ? steady_from : -1.0, load_mean, rate_field.c_str());
    std::fflush(stdout);
  }

  Options o_;
  std::vector<Frame> frames_;
  tf2_msgs::TFMessage statics_;
  double period_ = 0.1, warmup_s_ = 0.0;
  double full_at_s_ = -1.0;  // when the node's bounded buffers were full (--full-after)
  ros::Time first_stamp_;
  ros::Publisher image_pub_, info_pub_, static_pub_;
  ros::Subscriber motion_sub_, diagnostics_sub_;
  Clock::time_point start_;

  std::mutex mutex_;
  std::condition_variable answered_;
  std::map<ros::Time, Clock::time_point> sent_at_;
  std::map<ros::Time, double> answers_;  // stamp -> latency (ms)
  std::vector<double> window_latencies_, steady_latencies_;
  int sent_ = 0, ok_ = 0, queue_drops_ = 0, incomplete_drops_ = 0;
  std::vector<double> samples_t_, samples_rss_, samples_cpu_, samples_load_;
};

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "hybrid_vo_soak_player", ros::init_options::AnonymousName);
  Options options;
  std::string error;
  if (!parse_args(argc, argv, &options, &error)) {
    if (error.empty()) {
      std::cout << kUsage;
      return 0;
    }
    std::cerr << "error: " << error << "\n" << kUsage;
    return 2;
  }
  Player player(options);
  if (!player.load(&error)) {
    std::cerr << "error: " << error << "\n";
    return 1;
  }
  return player.run();
}
