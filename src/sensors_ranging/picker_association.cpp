#include "picker_localisation/sensors_ranging/picker_association.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <functional>

namespace picker_localisation {
namespace sensors {

namespace {

double gaussian(const Eigen::Vector2d& d, const Eigen::Matrix2d& S) {
  const double det = S.determinant();
  if (!(det > 0.0)) return 0.0;
  return std::exp(-0.5 * d.dot(S.inverse() * d)) / (2.0 * M_PI * std::sqrt(det));
}

// b_i(z): the belief's node masses spread isotropically (sigma^2 I + R_z), beyond 4 sigma left out.
double beliefDensity(const BeliefView& b, const topology::TopologicalMap& map, const Eigen::Vector2d& z,
                     const Eigen::Matrix2d& R, double sigma) {
  const Eigen::Matrix2d S = sigma * sigma * Eigen::Matrix2d::Identity() + R;
  const double reach2 = 16.0 * S.trace();
  double sum = 0.0;
  for (std::size_t k = 0; k < b.nodes->size(); ++k) {
    const Eigen::Vector2d d = z - map.position2d((*b.nodes)[k]);
    if (d.squaredNorm() > reach2) continue;
    sum += (*b.masses)[k] * gaussian(d, S);
  }
  return sum;
}

}  // namespace

void BeliefHistory::push(double stamp, const std::vector<topology::NodeIndex>& nodes,
                         const std::vector<double>& masses, double horizon) {
  if (!std::isfinite(stamp) || nodes.size() != masses.size() || nodes.empty()) return;
  if (!items_.empty() && stamp < items_.back().stamp) return;
  if (!items_.empty() && stamp == items_.back().stamp) items_.pop_back();
  items_.push_back({stamp, nodes, masses});
  while (items_.size() > 1 && items_.front().stamp < stamp - horizon) items_.pop_front();
  while (items_.size() > kMaxItems) items_.pop_front();  // beliefs faster than any tracker publishes
}

BeliefView BeliefHistory::atOrBefore(double t) const {
  for (auto it = items_.rbegin(); it != items_.rend(); ++it)
    if (it->stamp <= t) return {&it->nodes, &it->masses, it->stamp};
  return {};
}

std::vector<BeliefView> beliefViews(const std::vector<BeliefHistory>& histories, double stamp,
                                    const PickerAssociationOptions& options) {
  std::vector<const BeliefHistory*> pointers;
  for (const BeliefHistory& h : histories) pointers.push_back(&h);
  return beliefViews(pointers, stamp, options);
}

std::vector<BeliefView> beliefViews(const std::vector<const BeliefHistory*>& histories, double stamp,
                                    const PickerAssociationOptions& options) {
  std::vector<BeliefView> views;
  views.reserve(histories.size());
  for (const BeliefHistory* h : histories) views.push_back(h->atOrBefore(stamp - options.belief_lag));
  return views;
}

bool IdentityEvidence::add(const core::Observation& obs, const PickerAssociationOptions& o) {
  if (!obs.identifying || obs.picker_id.empty() || !o.isIdentitySensor(obs.sensor) || obs.nodes.empty() ||
      obs.nodes.size() != obs.likelihood.size() || !std::isfinite(obs.stamp))
    return false;
  Item& item = items_[obs.picker_id][obs.sensor + "|" + obs.robot_id];
  if (!item.likelihood.empty() && obs.stamp < item.stamp) return false;
  // Kept as published, not scaled to max 1: a read after many failed attempts, p (1 - p)^m, lies below the
  // floor everywhere and so changes no association. Scaled, its far-from-the-antenna shape (the attempts were
  // made from poses up to 5 m back) changed them 50x: three pickers, seeds 1..80, right lane 0.785 -> 0.775
  // (paired difference -0.010, 2.6 standard errors), wrong identities 598 -> 574.
  item.stamp = obs.stamp;
  item.likelihood.clear();
  item.likelihood.reserve(obs.nodes.size());
  for (std::size_t k = 0; k < obs.nodes.size(); ++k)
    if (std::isfinite(obs.likelihood[k]) && obs.likelihood[k] >= 0.0)
      item.likelihood[obs.nodes[k]] = obs.likelihood[k];
  return true;
}

double IdentityEvidence::ratio(const std::string& picker_id, double t, const Eigen::Vector2d& z,
                               const Eigen::Vector2d& mean, const Eigen::Matrix2d& covariance,
                               const topology::TopologicalMap& map, const PickerAssociationOptions& o) const {
  const auto picker = items_.find(picker_id);
  if (picker == items_.end()) return 1.0;
  // 3-point Gauss-Hermite rule per axis (nodes 0, +-sqrt(3) sigma; weights 2/3, 1/6, 1/6): exact for a
  // polynomial of degree 5 in each axis.
  static const double kNode[3] = {0.0, std::sqrt(3.0), -std::sqrt(3.0)};
  static const double kWeight[3] = {2.0 / 3.0, 1.0 / 6.0, 1.0 / 6.0};
  topology::TopologicalMap::EdgePoint points[9];
  topology::TopologicalMap::EdgePoint at_detection;  // found with the first evidence in the window
  double rho = 1.0;
  for (const auto& entry : picker->second) {
    const Item& item = entry.second;
    if (std::abs(t - item.stamp) > o.identity_window) continue;
    if (at_detection.from == topology::kInvalidNode) {  // per detection and picker: no lookups until needed
      const Eigen::LLT<Eigen::Matrix2d> llt(0.5 * (covariance + covariance.transpose()));
      if (llt.info() != Eigen::Success) return 1.0;
      const Eigen::Matrix2d root = llt.matrixL();
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
          points[3 * a + b] = map.nearestEdgePoint(mean + root * Eigen::Vector2d(kNode[a], kNode[b]));
      at_detection = map.nearestEdgePoint(z);
    }
    auto at_node = [&item](topology::NodeIndex n) {
      const auto it = item.likelihood.find(n);
      return it == item.likelihood.end() ? 0.0 : it->second;
    };
    // L read where the point is, between the two nodes of its edge (not at the nearest node: on a lane with
    // nodes 3.3 m apart a picker read 4 m from the antenna can stand 1.7 m from the nearest node, whose L
    // after failed read attempts is ~0, and the ratio then refused the true picker by 16x).
    auto value = [&at_node](const topology::TopologicalMap::EdgePoint& q) {
      const double l = at_node(q.from);
      return q.to == topology::kInvalidNode ? l : l + q.fraction * (at_node(q.to) - l);
    };
    double expected = 0.0;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) expected += kWeight[a] * kWeight[b] * value(points[3 * a + b]);
    rho *= std::max(value(at_detection), o.identity_floor) / std::max(expected, o.identity_floor);
  }
  return rho;
}

std::size_t IdentityEvidence::size() const {
  std::size_t n = 0;
  for (const auto& p : items_) n += p.second.size();
  return n;
}

namespace {

bool associable(const core::Observation& person, const PickerAssociationOptions& o) {
  return o.enabled && !person.identifying && person.position && person.position->allFinite() &&
         person.position_covariance.allFinite();
}

// l_i(z) for every picker: the mixture of the bias-corrected fix and the belief, times the identity evidence.
std::vector<double> personLikelihoods(const core::Observation& person,
                                      const std::vector<GnssIngest*>& pickers,
                                      const std::vector<BeliefView>& beliefs,
                                      const topology::TopologicalMap& map, const PickerAssociationOptions& o,
                                      const IdentityEvidence* evidence) {
  const Eigen::Vector2d z = *person.position;
  const Eigen::Matrix2d R = 0.5 * (person.position_covariance + person.position_covariance.transpose());
  std::vector<double> l(pickers.size(), 0.0);
  for (std::size_t i = 0; i < pickers.size(); ++i) {
    const GnssIngest::Prediction fix = pickers[i]->predictPosition(person.stamp, o.speed, o.max_fix_age);
    const double g = fix.valid ? gaussian(z - fix.mean, fix.covariance + R) : 0.0;
    const bool have_belief = i < beliefs.size() && beliefs[i].valid() &&
                             std::abs(person.stamp - beliefs[i].stamp) <= o.max_belief_age;
    const double b = have_belief ? beliefDensity(beliefs[i], map, z, R, o.belief_sigma) : 0.0;
    if (fix.valid && have_belief)
      l[i] = (1.0 - o.belief_weight) * g + o.belief_weight * b;
    else
      l[i] = fix.valid ? g : b;
    if (evidence && fix.valid)
      l[i] *= evidence->ratio(pickers[i]->pickerId(), person.stamp, z, fix.mean, fix.covariance + R, map, o);
  }
  return l;
}

// Identity (or candidates) from the probabilities already in r; an identified person is a bias sighting.
void decide(AssociationResult& r, const std::vector<GnssIngest*>& pickers,
            const PickerAssociationOptions& o) {
  std::size_t best = 0;
  for (std::size_t i = 0; i < pickers.size(); ++i)
    if (r.probabilities[i] > r.probabilities[best]) best = i;
  if (pickers.empty() || r.probabilities[best] < o.min_probability) {
    if (o.min_candidate_probability > 0.0 && !pickers.empty()) {
      for (std::size_t i = 0; i < pickers.size(); ++i)
        if (r.probabilities[i] >= o.min_candidate_probability) {
          r.observation.candidate_pickers.push_back(pickers[i]->pickerId());
          r.observation.candidate_probabilities.push_back(r.probabilities[i]);
        }
      r.concerns_nobody = r.observation.candidate_pickers.empty();
    }
    return;
  }
  r.picker = static_cast<int>(best);
  r.observation.identifying = true;
  r.observation.picker_id = pickers[best]->pickerId();
  const double p = r.probabilities[best];
  // The named picker as the one candidate, with its probability (the TPF's weigh_named_by_association).
  r.observation.candidate_pickers = {r.observation.picker_id};
  r.observation.candidate_probabilities = {p};
  if (p < o.sighting_min_probability) {
    r.bias.reason = "association probability below association_sighting_min_probability";
    return;
  }
  r.bias = pickers[best]->addSighting(
      r.observation.stamp, *r.observation.position,
      0.5 * (r.observation.position_covariance + r.observation.position_covariance.transpose()),
      o.weigh_sightings ? p : 1.0);
}

// Marginals of the joint association (associatePeople's comment) of people whose l rows are `l`.
constexpr double kCandidateFloor = 1e-4;
constexpr std::size_t kMaxEvents = 200000;

void jointMarginals(const std::vector<std::vector<double>>& l, double c,
                    std::vector<std::vector<double>>& p) {
  const std::size_t k = l.size();
  const std::size_t n = k ? l[0].size() : 0;
  p.assign(k, std::vector<double>(n, 0.0));
  std::vector<std::vector<std::size_t>> candidates(k);
  double events = 1.0;
  for (std::size_t j = 0; j < k; ++j) {
    double norm = c;
    for (double v : l[j]) norm += v;
    for (std::size_t i = 0; i < n; ++i)
      if (l[j][i] >= kCandidateFloor * norm) candidates[j].push_back(i);
    events *= static_cast<double>(candidates[j].size() + 1);
  }
  if (k == 1 || events > static_cast<double>(kMaxEvents)) {  // single-detection form
    for (std::size_t j = 0; j < k; ++j) {
      double norm = c;
      for (double v : l[j]) norm += v;
      for (std::size_t i = 0; i < n; ++i) p[j][i] = l[j][i] / norm;
    }
    return;
  }
  std::vector<int> chosen(k, -1);
  std::vector<char> used(n, 0);
  double total = 0.0;
  std::function<void(std::size_t, double)> walk = [&](std::size_t j, double w) {
    if (j == k) {
      total += w;
      for (std::size_t d = 0; d < k; ++d)
        if (chosen[d] >= 0) p[d][static_cast<std::size_t>(chosen[d])] += w;
      return;
    }
    chosen[j] = -1;
    walk(j + 1, w * c);
    for (std::size_t i : candidates[j]) {
      if (used[i]) continue;
      used[i] = 1;
      chosen[j] = static_cast<int>(i);
      walk(j + 1, w * l[j][i]);
      used[i] = 0;
    }
    chosen[j] = -1;
  };
  walk(0, 1.0);
  if (!(total > 0.0)) return;
  for (auto& row : p)
    for (double& v : row) v /= total;
}

}  // namespace

AssociationResult associatePerson(const core::Observation& person, const std::vector<GnssIngest*>& pickers,
                                  const std::vector<BeliefView>& beliefs, const topology::TopologicalMap& map,
                                  const PickerAssociationOptions& o, const IdentityEvidence* evidence) {
  return associatePeople({person}, pickers, beliefs, map, o, evidence).front();
}

std::vector<AssociationResult> associatePeople(const std::vector<core::Observation>& people,
                                               const std::vector<GnssIngest*>& pickers,
                                               const std::vector<BeliefView>& beliefs,
                                               const topology::TopologicalMap& map,
                                               const PickerAssociationOptions& o,
                                               const IdentityEvidence* evidence) {
  std::vector<AssociationResult> results(people.size());
  std::vector<std::size_t> index;  // the associable people
  std::vector<std::vector<double>> l;
  for (std::size_t j = 0; j < people.size(); ++j) {
    AssociationResult& r = results[j];
    r.observation = people[j];
    r.probabilities.assign(pickers.size(), 0.0);
    if (!associable(people[j], o)) continue;
    index.push_back(j);
    l.push_back(personLikelihoods(people[j], pickers, beliefs, map, o, evidence));
  }
  // Layers of people no two of which are within kSamePersonDistance (one person seen by two lasers lands in
  // two layers); each layer is associated jointly.
  std::vector<std::vector<std::size_t>> layers;  // positions in `index`
  for (std::size_t q = 0; q < index.size(); ++q) {
    const Eigen::Vector2d& z = *people[index[q]].position;
    auto apart = [&](const std::vector<std::size_t>& layer) {
      for (std::size_t other : layer)
        if ((*people[index[other]].position - z).norm() < kSamePersonDistance) return false;
      return true;
    };
    auto layer = std::find_if(layers.begin(), layers.end(), apart);
    if (layer == layers.end()) layer = layers.insert(layers.end(), std::vector<std::size_t>{});
    layer->push_back(q);
  }
  for (const std::vector<std::size_t>& layer : layers) {
    std::vector<std::vector<double>> layer_l, p;
    for (std::size_t q : layer) layer_l.push_back(l[q]);
    jointMarginals(layer_l, o.clutter_density, p);
    for (std::size_t m = 0; m < layer.size(); ++m) {
      AssociationResult& r = results[index[layer[m]]];
      r.probabilities = p[m];
      double assigned = 0.0;
      for (double v : p[m]) assigned += v;
      r.clutter_probability = std::max(0.0, 1.0 - assigned);
    }
  }
  for (std::size_t j : index) decide(results[j], pickers, o);  // bias sightings after every decision
  return results;
}

bool addIdentifyingSighting(const core::Observation& obs, const std::vector<GnssIngest*>& pickers) {
  if (!obs.identifying || !obs.position || !obs.position->allFinite() || !obs.position_covariance.allFinite())
    return false;
  for (GnssIngest* g : pickers) {
    if (g->pickerId() != obs.picker_id) continue;
    if (!g->options().bias.isSightingSensor(obs.sensor)) return false;
    return g->addSighting(obs.stamp, *obs.position, obs.position_covariance).accepted;
  }
  return false;
}

}  // namespace sensors
}  // namespace picker_localisation
