// tmap_info FILE: prints a topological map's summary as `key: value` lines.
// Exit status: 0 on success, 2 on a malformed or unreadable file (one line on stderr), 1 on bad usage.
#include "picker_localisation/topology/map_io.h"

#include <cstdio>
#include <iostream>

int main(int argc, char** argv) {
  using namespace picker_localisation::topology;
  if (argc != 2 || std::string(argv[1]) == "-h" || std::string(argv[1]) == "--help") {
    std::cerr << "usage: tmap_info FILE   (tmap2 or legacy tmap YAML)\n";
    return argc == 2 ? 0 : 1;
  }
  try {
    const TopologicalMap map = loadMap(argv[1]);
    const BoundingBox b = map.boundingBox();
    std::cout << "name: " << map.name() << "\n"
              << "nodes: " << map.numNodes() << "\n"
              << "directed_edges: " << map.numDirectedEdges() << "\n"
              << "undirected_edges: " << map.numUndirectedEdges() << "\n"
              << "lanes: " << map.numLanes() << "\n"
              << "components: " << map.numComponents() << "\n";
    char bbox[160];
    std::snprintf(bbox, sizeof(bbox), "bbox: [%.3f, %.3f, %.3f, %.3f]", b.min_x, b.min_y, b.max_x, b.max_y);
    std::cout << bbox << "   # min_x, min_y, max_x, max_y (m)\n";
    if (const auto& d = map.datum()) {
      char datum[160];
      std::snprintf(datum, sizeof(datum), "datum: [%.7f, %.7f, %.2f]", d->latitude, d->longitude, d->altitude);
      std::cout << datum << "   # meta.datum_latitude, _longitude (deg), _altitude (m)\n";
    }
    return 0;
  } catch (const MapError& e) {
    std::cerr << "tmap_info: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "tmap_info: " << argv[1] << ": " << e.what() << "\n";
    return 2;
  }
}
