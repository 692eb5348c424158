// bench_fleet: a whole farm through the real nodes, on their own ROS master (every picker of a farm in one
// process). Starts rosmaster on a free port, gnss_ingest (config/gnss_ingest.yaml) and the tracker
// (config/tpf.yaml, --particles), N simulated pickers walking their lanes and publishing
// sensor_msgs/NavSatFix at R Hz (evenly spread in time, 1 m white noise, seeded), and listens to every
// /pickers/<id>/belief. Measured over the window after --warmup: CPU of the tracker and gnss_ingest processes
// (from /proc, in cores), their total resident memory, latency from a fix's stamp (its wall publish time) to
// the belief of that fix, and how many fixes became a belief. Human-readable lines go to stderr; the last
// line of stdout is one JSON object: pickers, rate_hz, duration_s, particles, trackers, cpu_cores,
// cpu_cores_tracker, cpu_cores_ingest, rss_mb, latency_p50_ms, latency_p99_ms, latency_max_ms, observations,
// beliefs, startup_s.
//
//   bench_fleet --pickers 1000 --rate 1 --duration 30 --particles 1000
//   bench_fleet --pickers 100 --trackers per_picker   # one tpf_tracker process per picker (ordering 0.5 s),
//   as
//                                                     # before one node tracked them all
//
// Wall time is what is measured here (a live deployment); nothing in the nodes reads it.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <ros/ros.h>
#include <sensor_msgs/NavSatFix.h>

#include <picker_localisation/PickerBelief.h>
#include <picker_localisation/PickerBeliefArray.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <mutex>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

#include "picker_localisation/ros/ranging_nodes.h"
#include "picker_localisation/core/geodetic_datum.h"
#include "picker_localisation/topology/map_io.h"

namespace fs = std::filesystem;
namespace pl = picker_localisation;

namespace {

struct Args {
  int pickers = 100;
  double rate = 1.0, duration = 20.0, warmup = 5.0;
  int particles = 1000;
  std::string trackers = "one";  // one | per_picker
  std::string listen = "per_picker";  // per_picker (/pickers/<id>/belief) | fleet (/pickers/beliefs)
  std::string map = PL_SOURCE_DIR "/config/maps/riseholme.tmap2";
  std::string datum = PL_SOURCE_DIR "/config/datum.yaml";
  std::string gnss_config = PL_SOURCE_DIR "/config/gnss_ingest.yaml";
  std::string tpf_config = PL_SOURCE_DIR "/config/tpf.yaml";
  unsigned seed = 1;
  bool keep = false;
};

void usage() {
  std::cerr << "usage: bench_fleet [--pickers N] [--rate HZ] [--duration S] [--warmup S] [--particles P]\n"
               "                   [--trackers one|per_picker] [--listen per_picker|fleet] [--map F] [--datum F]\n"
               "                   [--gnss-config F]"
               " [--tpf-config F] [--seed K] [--keep-logs]\n"
               "  --listen: where beliefs are received: every picker's /pickers/<id>/belief (default), or the\n"
               "            tracker's fleet stream /pickers/beliefs (one connection, as gnss_ingest listens)\n";
}

bool parseArgs(int argc, char** argv, Args& a) {
  for (int i = 1; i < argc; ++i) {
    const std::string k = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) throw std::runtime_error(k + " needs a value");
      return argv[++i];
    };
    if (k == "--pickers") a.pickers = std::stoi(next());
    else if (k == "--rate") a.rate = std::stod(next());
    else if (k == "--duration") a.duration = std::stod(next());
    else if (k == "--warmup") a.warmup = std::stod(next());
    else if (k == "--particles") a.particles = std::stoi(next());
    else if (k == "--trackers") a.trackers = next();
    else if (k == "--listen") a.listen = next();
    else if (k == "--map") a.map = next();
    else if (k == "--datum") a.datum = next();
    else if (k == "--gnss-config") a.gnss_config = next();
    else if (k == "--tpf-config") a.tpf_config = next();
    else if (k == "--seed") a.seed = static_cast<unsigned>(std::stoul(next()));
    else if (k == "--keep-logs") a.keep = true;
    else if (k == "-h" || k == "--help") return false;
    else throw std::runtime_error("unknown argument " + k);
  }
  if (a.pickers < 1 || a.rate <= 0.0 || a.duration <= 0.0 || a.warmup < 0.0 || a.particles < 1)
    throw std::runtime_error("--pickers, --rate, --duration, --particles must be positive");
  if (a.trackers != "one" && a.trackers != "per_picker" && a.trackers != "in_process")
    throw std::runtime_error("--trackers: one, per_picker or in_process");
  if (a.listen != "per_picker" && a.listen != "fleet") throw std::runtime_error("--listen: per_picker or fleet");
  if (a.listen == "fleet" && a.trackers == "per_picker") throw std::runtime_error("--listen fleet needs one tracker");
  return true;
}

int freePort() {
  const int s = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  addr.sin_port = 0;
  socklen_t len = sizeof addr;
  if (bind(s, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0 ||
      getsockname(s, reinterpret_cast<sockaddr*>(&addr), &len) != 0) {
    close(s);
    throw std::runtime_error("no free TCP port");
  }
  const int port = ntohs(addr.sin_port);
  close(s);
  return port;
}

// fork + exec with stdout / stderr to `log`.
pid_t spawn(const std::vector<std::string>& argv, const fs::path& log) {
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("fork failed");
  if (pid == 0) {
    FILE* f = std::fopen(log.c_str(), "w");
    if (f) {
      dup2(fileno(f), 1);
      dup2(fileno(f), 2);
    }
    setpgid(0, 0);
    signal(SIGINT, SIG_DFL);  // a shell's background job inherits SIGINT ignored
    signal(SIGTERM, SIG_DFL);
    std::vector<char*> args;
    for (const auto& s : argv) args.push_back(const_cast<char*>(s.c_str()));
    args.push_back(nullptr);
    execvp(args[0], args.data());
    std::perror(args[0]);
    _exit(127);
  }
  return pid;
}

// SIGINT, then SIGKILL when it has not ended within `grace` s.
void stopProcess(pid_t pid, double grace = 10.0) {
  kill(pid, SIGINT);
  for (double waited = 0.0; waited < grace; waited += 0.05) {
    if (waitpid(pid, nullptr, WNOHANG) == pid) return;
    usleep(50000);
  }
  kill(pid, SIGKILL);
  waitpid(pid, nullptr, 0);
}

// utime + stime of a process (s) and its resident memory (MB), from /proc.
double cpuSeconds(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string s((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto close_paren = s.rfind(')');
  if (close_paren == std::string::npos) return 0.0;
  std::istringstream rest(s.substr(close_paren + 2));
  std::string field;
  std::vector<std::string> f;
  while (rest >> field) f.push_back(field);
  if (f.size() < 13) return 0.0;
  return (std::stod(f[11]) + std::stod(f[12])) / static_cast<double>(sysconf(_SC_CLK_TCK));  // utime, stime
}

double rssMb(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("VmRSS:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  return 0.0;
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const std::size_t k = std::min(v.size() - 1, static_cast<std::size_t>(std::ceil(q * v.size())) - (q > 0 ? 1 : 0));
  return v[k];
}

// A picker walking up and down one lane at 0.6 m/s.
struct Walker {
  std::vector<Eigen::Vector2d> path;
  double speed = 0.6, offset = 0.0;
  Eigen::Vector2d at(double t) const {
    if (path.size() < 2) return path.empty() ? Eigen::Vector2d::Zero() : path.front();
    std::vector<double> cum{0.0};
    for (std::size_t k = 1; k < path.size(); ++k) cum.push_back(cum.back() + (path[k] - path[k - 1]).norm());
    const double total = cum.back();
    double s = std::fmod(offset + speed * t, 2.0 * total);
    if (s > total) s = 2.0 * total - s;
    const std::size_t k = std::min<std::size_t>(
        path.size() - 2, std::upper_bound(cum.begin(), cum.end(), s) - cum.begin() - 1);
    const double u = cum[k + 1] > cum[k] ? (s - cum[k]) / (cum[k + 1] - cum[k]) : 0.0;
    return path[k] + u * (path[k + 1] - path[k]);
  }
};

struct PickerState {
  std::mutex m;
  std::deque<double> pending;  // stamps of fixes published, not yet seen as a belief
  std::uint32_t last_observations = 0;
};

}  // namespace

int main(int argc, char** argv) {
  Args a;
  try {
    if (!parseArgs(argc, argv, a)) {
      usage();
      return 0;
    }
  } catch (const std::exception& e) {
    std::cerr << "bench_fleet: " << e.what() << "\n";
    usage();
    return 2;
  }
  const fs::path bin = fs::canonical("/proc/self/exe").parent_path();
  const fs::path dir = fs::temp_directory_path() / ("bench_fleet_" + std::to_string(getpid()));
  fs::create_directories(dir);
  pl::topology::TopologicalMap map;
  pl::core::GeodeticDatum datum = pl::core::GeodeticDatum::load(a.datum);
  try {
    map = pl::topology::loadMap(a.map);
  } catch (const std::exception& e) {
    std::cerr << "bench_fleet: " << e.what() << "\n";
    return 2;
  }
  // The fleet: picker_<k> walks lane k mod lanes.
  std::vector<std::string> ids;
  {
    std::ofstream f(dir / "pickers.yaml");
    f << "pickers:\n";
    for (int k = 0; k < a.pickers; ++k) {
      ids.push_back("picker_" + std::to_string(k + 1));
      f << "  - id: " << ids.back() << "\n    gnss_topic: /pickers/" << ids.back() << "/fix\n";
    }
  }
  std::mt19937 rng(a.seed);
  std::vector<Walker> walkers(ids.size());
  for (std::size_t k = 0; k < ids.size(); ++k) {
    if (map.numLanes() > 0) {
      for (auto n : map.laneNodes(static_cast<pl::topology::LaneIndex>(k % map.numLanes())))
        walkers[k].path.push_back(map.position2d(n));
    } else {
      walkers[k].path.push_back(map.position2d(static_cast<pl::topology::NodeIndex>(k % map.numNodes())));
    }
    walkers[k].offset = std::uniform_real_distribution<double>(0.0, 50.0)(rng);
  }

  const int port = freePort();
  const std::string master_uri = "http://localhost:" + std::to_string(port);
  setenv("ROS_MASTER_URI", master_uri.c_str(), 1);
  setenv("ROS_HOSTNAME", "localhost", 1);
  std::vector<pid_t> tracker_pids;
  pid_t master = -1, ingest = -1;
  auto stopAll = [&]() {
    std::vector<pid_t> all = tracker_pids;
    if (ingest > 0) all.push_back(ingest);
    for (pid_t p : all) kill(p, SIGINT);
    for (pid_t p : all) stopProcess(p);
    ros::shutdown();  // unregister from the master while it still runs
    if (master > 0) stopProcess(master);
    if (!a.keep) fs::remove_all(dir);
  };
  master = spawn({"rosmaster", "--core", "-p", std::to_string(port)}, dir / "rosmaster.log");
  ros::init(argc, argv, "bench_fleet", ros::init_options::NoSigintHandler);
  const ros::WallTime t_start = ros::WallTime::now();
  for (int i = 0; i < 200 && !ros::master::check(); ++i) ros::WallDuration(0.05).sleep();
  if (!ros::master::check()) {
    std::cerr << "bench_fleet: rosmaster did not start (" << (dir / "rosmaster.log") << ")\n";
    stopAll();
    return 1;
  }
  // gnss_ingest's parameters: its own node, or ~gnss_ingest/ of the one process (--trackers in_process).
  const std::string ingest_ns = a.trackers == "in_process" ? "/tpf_tracker/gnss_ingest" : "/gnss_ingest";
  ros::param::set(ingest_ns + "/pickers_file", (dir / "pickers.yaml").string());
  ros::param::set(ingest_ns + "/datum_file", a.datum);
  ros::param::set(ingest_ns + "/map_file", a.map);
  if (std::system(("rosparam load '" + a.gnss_config + "' " + ingest_ns).c_str()) != 0) {
    std::cerr << "bench_fleet: rosparam load " << a.gnss_config << " failed\n";
    stopAll();
    return 1;
  }
  const std::string tracker = (bin / "tpf_tracker").string();
  const std::vector<std::string> common{"_map_file:=" + a.map, "_tpf_params_file:=" + a.tpf_config,
                                        "_num_particles:=" + std::to_string(a.particles)};
  if (a.trackers == "in_process") {
    std::vector<std::string> cmd{(bin / "picker_fleet").string(), "__name:=tpf_tracker",
                                 "_pickers_file:=" + (dir / "pickers.yaml").string()};
    cmd.insert(cmd.end(), common.begin(), common.end());
    tracker_pids.push_back(spawn(cmd, dir / "picker_fleet.log"));
  } else {
    ingest = spawn({(bin / "gnss_ingest").string(), "__name:=gnss_ingest"}, dir / "gnss_ingest.log");
  }
  if (a.trackers == "one") {
    std::vector<std::string> cmd{tracker, "__name:=tpf_tracker", "_pickers_file:=" + (dir / "pickers.yaml").string()};
    cmd.insert(cmd.end(), common.begin(), common.end());
    tracker_pids.push_back(spawn(cmd, dir / "tpf_tracker.log"));
  } else if (a.trackers == "per_picker") {
    for (const std::string& id : ids) {
      // As the trackers ran before one node tracked them all: stamp order 0.5 s (the old default).
      std::vector<std::string> cmd{tracker, "__name:=tpf_tracker_" + id, "_picker_id:=" + id, "_ordering_latency:=0.5"};
      cmd.insert(cmd.end(), common.begin(), common.end());
      tracker_pids.push_back(spawn(cmd, dir / ("tpf_tracker_" + id + ".log")));
    }
  }

  ros::NodeHandle nh;
  std::vector<PickerState> state(ids.size());
  std::vector<ros::Publisher> fix_pubs;
  std::vector<ros::Subscriber> belief_subs;
  std::mutex lat_mutex;
  std::vector<double> latencies_ms;
  std::atomic<bool> measuring{false};
  std::atomic<std::uint64_t> matched{0}, beliefs_total{0};
  // A belief of picker k: matched with the oldest fix of k not yet seen (older unmatched ones were lost).
  auto onBelief = [&](std::size_t k, const pl::PickerBelief& m) {
    const double now = ros::WallTime::now().toSec();
    ++beliefs_total;
    const double stamp = m.header.stamp.toSec();
    PickerState& s = state[k];
    std::lock_guard<std::mutex> lock(s.m);
    while (!s.pending.empty() && s.pending.front() < stamp - 1e-6) s.pending.pop_front();
    if (!s.pending.empty() && std::abs(s.pending.front() - stamp) <= 1e-6) {
      s.pending.pop_front();
      ++matched;
      if (measuring) {
        std::lock_guard<std::mutex> l2(lat_mutex);
        latencies_ms.push_back(1e3 * (now - stamp));
      }
    }
  };
  std::unordered_map<std::string, std::size_t> index_of;
  for (std::size_t k = 0; k < ids.size(); ++k) {
    index_of[ids[k]] = k;
    fix_pubs.push_back(nh.advertise<sensor_msgs::NavSatFix>("/pickers/" + ids[k] + "/fix", 100));
    if (a.listen == "per_picker")
      belief_subs.push_back(nh.subscribe<pl::PickerBelief>(
          "/pickers/" + ids[k] + "/belief", 100, [&, k](const pl::PickerBelief::ConstPtr& m) { onBelief(k, *m); },
          ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay()));
  }
  if (a.listen == "fleet")
    belief_subs.push_back(nh.subscribe<pl::PickerBeliefArray>(
        "/pickers/beliefs", 1000,
        [&](const pl::PickerBeliefArray::ConstPtr& m) {
          for (const auto& b : m->beliefs) {
            const auto it = index_of.find(b.picker_id);
            if (it != index_of.end()) onBelief(it->second, b);
          }
        },
        ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay()));
  ros::AsyncSpinner spinner(1);
  spinner.start();
  // Ready: every fix topic has gnss_ingest subscribed, every belief topic a publisher.
  std::size_t ready = 0;
  for (int i = 0; i < 3000 && ros::ok(); ++i) {
    ready = 0;
    for (std::size_t k = 0; k < ids.size(); ++k)
      ready += fix_pubs[k].getNumSubscribers() > 0 &&
               belief_subs[a.listen == "fleet" ? 0 : k].getNumPublishers() > 0;
    if (ready == ids.size()) break;
    ros::WallDuration(0.1).sleep();
  }
  const double startup = (ros::WallTime::now() - t_start).toSec();
  std::cerr << "bench_fleet: " << ready << "/" << ids.size() << " pickers connected after " << startup << " s\n";
  if (ready != ids.size()) {
    std::cerr << "bench_fleet: not every picker connected (logs in " << dir << ")\n";
    a.keep = true;
    stopAll();
    return 1;
  }
  ros::WallDuration(1.0).sleep();

  // Publish: picker k's fixes at t0 + (j + k / N) / R, stamped with the wall time of publishing.
  std::normal_distribution<double> noise(0.0, 1.0);
  const double t0 = ros::WallTime::now().toSec();
  const double t_measure = t0 + a.warmup, t_end = t_measure + a.duration;
  const double slot = 1.0 / (a.rate * ids.size());
  double cpu0 = 0.0, cpu0_ingest = 0.0, wall0 = 0.0;
  std::uint64_t published_window = 0, matched_at_measure = 0;
  auto cpuOf = [](pid_t p) { return p > 0 ? cpuSeconds(p) : 0.0; };
  auto cpuTrackers = [&] {
    double c = 0.0;
    for (pid_t p : tracker_pids) c += cpuSeconds(p);
    return c;
  };
  for (std::uint64_t j = 0;; ++j) {
    const double due = t0 + j * slot;
    if (due >= t_end) break;
    const double now = ros::WallTime::now().toSec();
    if (due > now) ros::WallDuration(due - now).sleep();
    if (!measuring && due >= t_measure) {
      cpu0 = cpuTrackers();
      cpu0_ingest = cpuOf(ingest);
      wall0 = ros::WallTime::now().toSec();
      matched_at_measure = matched;
      measuring = true;
    }
    const std::size_t k = j % ids.size();
    const ros::WallTime stamp = ros::WallTime::now();
    const Eigen::Vector2d p = walkers[k].at(stamp.toSec() - t0) + Eigen::Vector2d(noise(rng), noise(rng));
    const sensor_msgs::NavSatFix f = pl::ros_adapter::navSatFixAt(datum, p, ros::Time(stamp.sec, stamp.nsec));
    {
      std::lock_guard<std::mutex> lock(state[k].m);
      state[k].pending.push_back(f.header.stamp.toSec());
    }
    fix_pubs[k].publish(f);
    if (measuring) ++published_window;
  }
  const double wall1 = ros::WallTime::now().toSec();
  const double cpu1 = cpuTrackers(), cpu1_ingest = cpuOf(ingest);
  double rss = ingest > 0 ? rssMb(ingest) : 0.0;
  for (pid_t p : tracker_pids) rss += rssMb(p);
  // Let the last beliefs arrive.
  for (int i = 0; i < 50 && matched - matched_at_measure < published_window; ++i) ros::WallDuration(0.1).sleep();
  measuring = false;
  spinner.stop();
  const std::uint64_t beliefs_window = std::min<std::uint64_t>(matched - matched_at_measure, published_window);
  const double wall = wall1 - wall0;
  const double cpu_tracker = (cpu1 - cpu0) / wall, cpu_ingest = (cpu1_ingest - cpu0_ingest) / wall;
  std::vector<double> lat;
  {
    std::lock_guard<std::mutex> l(lat_mutex);
    lat = latencies_ms;
  }
  stopAll();
  char json[1024];
  std::snprintf(json, sizeof json,
                "{\"pickers\": %d, \"rate_hz\": %g, \"duration_s\": %g, \"particles\": %d, \"trackers\": \"%s\", "
                "\"listen\": \"%s\", "
                "\"tracker_processes\": %zu, \"cpu_cores\": %.4f, \"cpu_cores_tracker\": %.4f, "
                "\"cpu_cores_ingest\": %.4f, \"rss_mb\": %.1f, \"latency_p50_ms\": %.3f, \"latency_p99_ms\": %.3f, "
                "\"latency_max_ms\": %.3f, \"observations\": %llu, \"beliefs\": %llu, \"startup_s\": %.1f}",
                a.pickers, a.rate, a.duration, a.particles, a.trackers.c_str(), a.listen.c_str(), tracker_pids.size(),
                cpu_tracker + cpu_ingest, cpu_tracker, cpu_ingest, rss, percentile(lat, 0.5), percentile(lat, 0.99),
                lat.empty() ? NAN : *std::max_element(lat.begin(), lat.end()),
                static_cast<unsigned long long>(published_window), static_cast<unsigned long long>(beliefs_window),
                startup);
  std::cerr << "bench_fleet: " << published_window << " fixes in " << wall << " s, " << beliefs_window
            << " became beliefs; CPU " << cpu_tracker << " (tracker) + " << cpu_ingest << " (gnss_ingest) cores, RSS "
            << rss << " MB\n";
  std::cout << json << std::endl;
  return 0;
}
