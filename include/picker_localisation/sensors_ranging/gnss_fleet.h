// gnss_ingest's work for a whole fleet of pickers, ROS-free: one GnssIngest per picker with a GNSS device,
// the trackers' recent beliefs, identity evidence, the association of anonymous people with the pickers (Khan
// et al. 2020 Sec. VI), and identifying observations used as bias sightings. The gnss_ingest node drives it
// from its topics (and keeps conversions, stamp ordering, publishing and diagnostics); the offline runner
// drives it from the simulator's events, so both associate and correct the same way.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "picker_localisation/core/geodetic_datum.h"
#include "picker_localisation/core/observation.h"
#include "picker_localisation/sensors_ranging/gnss_ingest.h"
#include "picker_localisation/sensors_ranging/picker_association.h"
#include "picker_localisation/topology/topological_map.h"

namespace picker_localisation {
namespace sensors {

class GnssFleet {
 public:
  struct Picker {
    Picker(const std::string& id, std::shared_ptr<const topology::TopologicalMap> map,
           const core::GeodeticDatum& datum, const GnssIngestOptions& options)
        : ingest(id, std::move(map), datum, options) {}
    GnssIngest ingest;      // fix checks, bias estimate
    BeliefHistory beliefs;  // its tracker's beliefs, read association_belief_lag before a detection
  };
  struct Counters {
    std::size_t people = 0, identified = 0,
                nobody = 0;     // anonymous people associated / identified / nobody's
    std::size_t sightings = 0;  // bias sightings accepted (people and identifying)
  };

  GnssFleet(std::shared_ptr<const topology::TopologicalMap> map, const core::GeodeticDatum& datum,
            GnssIngestOptions options);

  // A picker with a GNSS device, last in the association's order; nullptr when it is there already.
  Picker* add(const std::string& id);
  bool remove(const std::string& id);
  Picker* find(const std::string& id);
  const std::vector<std::unique_ptr<Picker>>& pickers() const { return pickers_; }
  std::size_t size() const { return pickers_.size(); }

  // One fix of a picker (GnssIngest::process).
  GnssResult processFix(Picker& picker, const core::GnssFix& fix) { return picker.ingest.process(fix); }
  // An anonymous person (leg_detector, other people detectors) associated with the pickers against each one's
  // bias-corrected fix, its belief association_belief_lag before the detection and the identity evidence
  // (associatePerson); an identified person is a bias sighting of that picker.
  AssociationResult associate(const core::Observation& person);
  // The people of one scan of one sensor, jointly (associatePeople): each picker is at most one of them.
  std::vector<AssociationResult> associate(const std::vector<core::Observation>& people);
  // Whether an observation of the fleet's observation stream is of use here: identifying, from a sensor in
  // association_identity_sensors or bias_sighting_sensors (the node's filter before decoding a message).
  bool wantsIdentified(bool identifying, const std::string& sensor) const;
  // Uses such an observation: identity evidence for the association and, with a metric position, a bias
  // sighting (addIdentifyingSighting). Returns whether a sighting was accepted; others are ignored.
  bool useIdentified(const core::Observation& obs);
  // A belief of picker `id`'s tracker (nodes with non-negative masses, normalised here). False when the
  // picker has no GNSS here or no mass is positive and finite (nothing kept).
  bool addBelief(const std::string& id, double stamp, const std::vector<topology::NodeIndex>& nodes,
                 std::vector<double> masses);
  // A new map (and datum, when it moved): every ingest places fixes on it; beliefs and identity evidence,
  // which name nodes of the old map, are forgotten.
  void adoptMap(std::shared_ptr<const topology::TopologicalMap> map, const core::GeodeticDatum& datum,
                bool datum_moved);
  // The clock jumped back (a bag looped, a simulator restarted): fix histories, bias estimates, beliefs and
  // identity evidence forgotten (every later stamp would be "not after the last accepted one").
  void reset();

  const Counters& counters() const { return counters_; }
  const GnssIngestOptions& options() const { return options_; }
  const topology::TopologicalMap& map() const { return *map_; }

 private:
  std::vector<GnssIngest*> ingests();

  std::shared_ptr<const topology::TopologicalMap> map_;
  std::unique_ptr<core::GeodeticDatum> datum_;
  GnssIngestOptions options_;
  std::vector<std::unique_ptr<Picker>> pickers_;
  IdentityEvidence identity_;  // RFID reads / failed reads per picker (association_identity_sensors)
  Counters counters_;
};

}  // namespace sensors
}  // namespace picker_localisation
