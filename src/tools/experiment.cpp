// experiment: the offline Table II runner (in-process, deterministic, no roscore).
//   experiment --map FILE --scenario single|navigation|multi [--methods M1,M2,...] [--runs N] [--seed S]
//              [--duration SEC] --out DIR [--jobs J] [--sample-period SEC] [--leg-model FILE] [--tpf-config
//              FILE]
//              [--sim-config FILE] [--datum FILE] [--pickers FILE] [--gnss-config FILE] [--rfid-config FILE]
//              [--nbs-config FILE] [--vision-config FILE[,FILE...]] [--tracker-seed N]
// Exit status: 0 success, 2 bad arguments / map / output directory.
#include <cstdlib>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "picker_localisation/eval/experiment.h"

namespace {

void usage(std::ostream& o) {
  o << "usage: experiment --map FILE --scenario single|navigation|multi|calls [--methods M1,M2,...] [--runs "
       "N]\n"
       "                  [--seed S] [--duration SEC] --out DIR [--jobs J] [--sample-period SEC]\n"
       "                  [--leg-model FILE] [--tpf-config FILE] [--sim-config FILE] [--datum FILE]\n"
       "                  [--pickers FILE] [--gnss-config FILE] [--rfid-config FILE] [--nbs-config FILE]\n"
       "                  [--vision-config FILE[,FILE...]] [--tracker-seed N]\n"
       "                  [--pickers-count N] [--robots K] [--dispatcher-config FILE]\n"
       "                  [--idle-robots nbs|stay]   (scenario calls)\n"
       "config files default to the package's config/ (as the ROS graph uses them); 'none' = built-in "
       "defaults\n"
       "methods:";
  for (const auto& m : picker_localisation::eval::allMethodNames()) o << ' ' << m;
  o << "\ndefaults: methods = the scenario's Table II rows, runs 10, seed 1, duration 600 s, jobs 1\n";
}

std::vector<std::string> splitComma(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace picker_localisation::eval;
  ExperimentConfig cfg;
  std::string scenario;
  try {
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      if (a == "-h" || a == "--help") {
        usage(std::cout);
        return 0;
      }
      if (i + 1 >= argc) throw std::invalid_argument("missing value after " + a);
      const std::string v = argv[++i];
      if (a == "--map")
        cfg.map_path = v;
      else if (a == "--scenario")
        scenario = v;
      else if (a == "--methods")
        cfg.methods = splitComma(v);
      else if (a == "--runs")
        cfg.runs = std::stoul(v);
      else if (a == "--seed")
        cfg.seed = std::stoull(v);
      else if (a == "--duration")
        cfg.duration = std::stod(v);
      else if (a == "--out")
        cfg.out_dir = v;
      else if (a == "--jobs")
        cfg.jobs = std::stoul(v);
      else if (a == "--sample-period")
        cfg.run.sample_period = std::stod(v);
      else if (a == "--leg-model")
        cfg.run.leg_model = v;
      else if (a == "--tpf-config")
        cfg.run.tpf_config = v;
      else if (a == "--sim-config")
        cfg.run.sim_config = v;
      else if (a == "--datum")
        cfg.run.datum_file = v;
      else if (a == "--pickers")
        cfg.run.pickers_file = v;
      else if (a == "--gnss-config")
        cfg.run.gnss_config = v;
      else if (a == "--rfid-config")
        cfg.run.rfid_config = v;
      else if (a == "--nbs-config")
        cfg.run.nbs_config = v;
      else if (a == "--vision-config")
        cfg.run.vision_config = v;
      else if (a == "--tracker-seed")
        cfg.run.tracker_seed = std::stoull(v);
      else if (a == "--pickers-count")
        cfg.run.pickers = std::stoul(v);
      else if (a == "--robots")
        cfg.run.robots = std::stoul(v);
      else if (a == "--dispatcher-config")
        cfg.run.dispatcher_config = v;
      else if (a == "--idle-robots")
        cfg.run.idle_robots = v;
      else
        throw std::invalid_argument("unknown option " + a);
    }
    if (cfg.map_path.empty() || scenario.empty() || cfg.out_dir.empty())
      throw std::invalid_argument("--map, --scenario and --out are required");
    cfg.scenario = parseScenario(scenario);
    for (const auto& m : cfg.methods)
      if (!isKnownMethod(m)) throw std::invalid_argument("unknown method '" + m + "'");
    if (!(cfg.run.sample_period > 0.0)) throw std::invalid_argument("--sample-period must be > 0");
    if (cfg.run.idle_robots != "nbs" && cfg.run.idle_robots != "stay")
      throw std::invalid_argument("--idle-robots must be nbs or stay");
  } catch (const std::exception& e) {
    std::cerr << "experiment: " << e.what() << "\n";
    usage(std::cerr);
    return 2;
  }
  try {
    runExperiment(cfg, std::cout);
  } catch (const std::exception& e) {
    std::cerr << "experiment: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
