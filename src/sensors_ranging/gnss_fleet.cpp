#include "picker_localisation/sensors_ranging/gnss_fleet.h"

#include <stdexcept>

namespace picker_localisation {
namespace sensors {

GnssFleet::GnssFleet(std::shared_ptr<const topology::TopologicalMap> map, const core::GeodeticDatum& datum,
                     GnssIngestOptions options)
    : map_(std::move(map)),
      datum_(std::make_unique<core::GeodeticDatum>(datum)),
      options_(std::move(options)) {
  if (!map_) throw std::invalid_argument("GnssFleet: null map");
}

GnssFleet::Picker* GnssFleet::add(const std::string& id) {
  if (find(id)) return nullptr;
  pickers_.push_back(std::make_unique<Picker>(id, map_, *datum_, options_));
  return pickers_.back().get();
}

bool GnssFleet::remove(const std::string& id) {
  for (auto it = pickers_.begin(); it != pickers_.end(); ++it)
    if ((*it)->ingest.pickerId() == id) {
      pickers_.erase(it);
      return true;
    }
  return false;
}

GnssFleet::Picker* GnssFleet::find(const std::string& id) {
  for (auto& p : pickers_)
    if (p->ingest.pickerId() == id) return p.get();
  return nullptr;
}

std::vector<GnssIngest*> GnssFleet::ingests() {
  std::vector<GnssIngest*> out;
  out.reserve(pickers_.size());
  for (auto& p : pickers_) out.push_back(&p->ingest);
  return out;
}

AssociationResult GnssFleet::associate(const core::Observation& person) {
  return associate(std::vector<core::Observation>{person}).front();
}

std::vector<AssociationResult> GnssFleet::associate(const std::vector<core::Observation>& people) {
  if (people.empty()) return {};
  std::vector<const BeliefHistory*> histories;
  histories.reserve(pickers_.size());
  for (const auto& p : pickers_) histories.push_back(&p->beliefs);
  std::vector<AssociationResult> results =
      associatePeople(people, ingests(), beliefViews(histories, people.front().stamp, options_.association),
                      *map_, options_.association, &identity_);
  for (const AssociationResult& a : results) {
    ++counters_.people;
    if (a.picker >= 0) ++counters_.identified;
    if (a.bias.accepted) ++counters_.sightings;
    if (a.concerns_nobody) ++counters_.nobody;
  }
  return results;
}

bool GnssFleet::wantsIdentified(bool identifying, const std::string& sensor) const {
  return identifying && ((options_.association.enabled && options_.association.isIdentitySensor(sensor)) ||
                         options_.bias.isSightingSensor(sensor));
}

bool GnssFleet::useIdentified(const core::Observation& obs) {
  if (!wantsIdentified(obs.identifying, obs.sensor)) return false;
  if (options_.association.enabled) identity_.add(obs, options_.association);
  if (!obs.position || !addIdentifyingSighting(obs, ingests())) return false;
  ++counters_.sightings;
  return true;
}

bool GnssFleet::addBelief(const std::string& id, double stamp, const std::vector<topology::NodeIndex>& nodes,
                          std::vector<double> masses) {
  Picker* p = find(id);
  if (!p || nodes.size() != masses.size() || !core::normaliseMasses(masses)) return false;
  p->beliefs.push(stamp, nodes, masses);
  return true;
}

void GnssFleet::adoptMap(std::shared_ptr<const topology::TopologicalMap> map,
                         const core::GeodeticDatum& datum, bool datum_moved) {
  if (!map) throw std::invalid_argument("GnssFleet::adoptMap: null map");
  map_ = std::move(map);
  datum_ = std::make_unique<core::GeodeticDatum>(datum);
  for (auto& p : pickers_) {
    p->ingest.setMap(map_, *datum_, datum_moved);
    p->beliefs.clear();  // node indices of the old map; the tracker's next beliefs refill them
  }
  identity_.clear();
}

void GnssFleet::reset() {
  for (auto& p : pickers_) {
    p->ingest = GnssIngest(p->ingest.pickerId(), map_, *datum_, options_);
    p->beliefs.clear();
  }
  identity_.clear();
}

}  // namespace sensors
}  // namespace picker_localisation
