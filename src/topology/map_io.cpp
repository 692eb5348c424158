#include "picker_localisation/topology/map_io.h"

#include <Eigen/Geometry>
#include <optional>

#include <yaml-cpp/yaml.h>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace picker_localisation {
namespace topology {

namespace {

class MapReader {
 public:
  explicit MapReader(std::string source) : source_(std::move(source)) {}

  TopologicalMap read(const YAML::Node& root, MapFormat format) {
    if (!root || root.IsNull()) throw MapError(source_, "the file is empty");
    if (format == MapFormat::kAuto) {
      if (root.IsMap() && root["nodes"]) {
        format = MapFormat::kTmap2;
      } else if (root.IsSequence()) {
        format = MapFormat::kLegacyTmap;
      } else {
        throw MapError(source_,
                       "not a topological map: the top level must be a mapping with a 'nodes' list (tmap2) or a "
                       "list of {meta, node} entries (legacy tmap)");
      }
    }
    const YAML::Node* list = &root;
    std::string name, metric_map;
    if (format == MapFormat::kTmap2) {
      if (!root.IsMap()) throw MapError(source_, "tmap2: the top level must be a mapping");
      if (!root["nodes"] || !root["nodes"].IsSequence())
        throw MapError(source_, "tmap2: 'nodes' must be a list", "", "nodes");
      list = &nodes_holder_;
      nodes_holder_ = root["nodes"];
      name = scalarOr(root["name"], "");
      metric_map = scalarOr(root["metric_map"], "");
    } else if (!root.IsSequence()) {
      throw MapError(source_, "legacy tmap: the top level must be a list of {meta, node} entries");
    }

    std::vector<Node> nodes;
    std::vector<EdgeSpec> edges;
    std::size_t i = 0;
    for (const YAML::Node& entry : *list) {
      readEntry(entry, i++, nodes, edges, metric_map, name);
    }
    std::optional<MapDatum> datum;
    if (format == MapFormat::kTmap2) {
      applyTransformation(root["transformation"], nodes);
      datum = readDatum(root["meta"]);
    }
    TopologicalMap map = TopologicalMap::build(name, std::move(nodes), edges, source_, metric_map);
    map.setDatum(datum);
    return map;
  }

 private:
  static std::string scalarOr(const YAML::Node& n, const std::string& fallback) {
    return n && n.IsScalar() ? n.as<std::string>() : fallback;
  }

  double number(const YAML::Node& parent, const char* key, const std::string& node, const std::string& path,
                bool required, double fallback = 0.0) {
    const YAML::Node v = parent[key];
    if (!v || v.IsNull()) {
      if (required) throw MapError(source_, "missing field", node, path);
      return fallback;
    }
    if (!v.IsScalar()) throw MapError(source_, "expected a number", node, path);
    const std::string text = v.Scalar();
    std::string lower;
    for (char c : text) lower.push_back(static_cast<char>(std::tolower(static_cast<unsigned char>(c))));
    if (lower == ".nan" || lower == ".inf" || lower == "-.inf" || lower == "+.inf")  // YAML's special floats
      throw MapError(source_, "number is not finite: '" + text + "'", node, path);
    try {
      std::size_t used = 0;
      double d = std::stod(text, &used);
      if (used != text.size()) throw std::invalid_argument(text);
      if (!std::isfinite(d)) throw MapError(source_, "number is not finite: '" + text + "'", node, path);
      return d;
    } catch (const std::logic_error&) {
      throw MapError(source_, "not a number: '" + text + "'", node, path);
    }
  }

  // tmap2 `transformation` (LCAS): node poses are in its child frame; parent <- child is the rotation
  // (quaternion w, x, y, z) and translation given. The map returned is in the parent frame (`map` on LCAS robots).
  void applyTransformation(const YAML::Node& t, std::vector<Node>& nodes) {
    if (!t || t.IsNull()) return;
    if (!t.IsMap()) throw MapError(source_, "'transformation' must be a mapping", "", "transformation");
    Eigen::Quaterniond r = Eigen::Quaterniond::Identity();
    Eigen::Vector3d x = Eigen::Vector3d::Zero();
    if (const YAML::Node q = t["rotation"]) {
      if (!q.IsMap()) throw MapError(source_, "expected a mapping", "", "transformation.rotation");
      r = Eigen::Quaterniond(number(q, "w", "", "transformation.rotation.w", false, 1.0),
                             number(q, "x", "", "transformation.rotation.x", false),
                             number(q, "y", "", "transformation.rotation.y", false),
                             number(q, "z", "", "transformation.rotation.z", false));
      if (!(r.norm() > 1e-9)) throw MapError(source_, "rotation quaternion is zero", "", "transformation.rotation");
      r.normalize();
    }
    if (const YAML::Node v = t["translation"]) {
      if (!v.IsMap()) throw MapError(source_, "expected a mapping", "", "transformation.translation");
      x = Eigen::Vector3d(number(v, "x", "", "transformation.translation.x", false),
                          number(v, "y", "", "transformation.translation.y", false),
                          number(v, "z", "", "transformation.translation.z", false));
    }
    if (r.isApprox(Eigen::Quaterniond::Identity(), 1e-12) && x.isZero(0.0)) return;
    for (Node& n : nodes) {
      n.position = r * n.position + x;
      const Eigen::Quaterniond o(n.orientation[3], n.orientation[0], n.orientation[1], n.orientation[2]);
      const Eigen::Quaterniond turned = (r * o).normalized();
      n.orientation = {turned.x(), turned.y(), turned.z(), turned.w()};
    }
  }

  // meta.datum_latitude / meta.datum_longitude (both or neither) and optional meta.datum_altitude.
  std::optional<MapDatum> readDatum(const YAML::Node& meta) {
    if (!meta || !meta.IsMap() || (!meta["datum_latitude"] && !meta["datum_longitude"])) return std::nullopt;
    MapDatum d;
    d.latitude = number(meta, "datum_latitude", "", "meta.datum_latitude", true);
    d.longitude = number(meta, "datum_longitude", "", "meta.datum_longitude", true);
    d.altitude = number(meta, "datum_altitude", "", "meta.datum_altitude", false);
    return d;  // the range is checked by TopologicalMap::setDatum
  }

  void readEntry(const YAML::Node& entry, std::size_t i, std::vector<Node>& nodes, std::vector<EdgeSpec>& edges,
                 std::string& metric_map, std::string& name) {
    const std::string where = "nodes[" + std::to_string(i) + "]";
    if (!entry.IsMap()) throw MapError(source_, where + " is not a mapping", "", "nodes");
    const YAML::Node body = entry["node"];
    if (!body || !body.IsMap()) throw MapError(source_, where + " has no 'node' mapping", "", "node");
    Node n;
    const YAML::Node name_node = body["name"];
    if (!name_node || !name_node.IsScalar() || name_node.Scalar().empty()) {
      // Fall back to meta.node, which both formats carry.
      const YAML::Node meta_name = entry["meta"] ? entry["meta"]["node"] : YAML::Node();
      if (!meta_name || !meta_name.IsScalar()) throw MapError(source_, where + " has no name", "", "node.name");
      n.name = meta_name.Scalar();
    } else {
      n.name = name_node.Scalar();
    }
    const YAML::Node pose = body["pose"];
    if (!pose || !pose.IsMap()) throw MapError(source_, "missing pose", n.name, "node.pose");
    const YAML::Node position = pose["position"];
    if (!position || !position.IsMap()) throw MapError(source_, "missing position", n.name, "node.pose.position");
    n.position.x() = number(position, "x", n.name, "node.pose.position.x", true);
    n.position.y() = number(position, "y", n.name, "node.pose.position.y", true);
    n.position.z() = number(position, "z", n.name, "node.pose.position.z", false);
    const YAML::Node orientation = pose["orientation"];
    if (orientation && orientation.IsMap()) {
      n.orientation[0] = number(orientation, "x", n.name, "node.pose.orientation.x", false);
      n.orientation[1] = number(orientation, "y", n.name, "node.pose.orientation.y", false);
      n.orientation[2] = number(orientation, "z", n.name, "node.pose.orientation.z", false);
      n.orientation[3] = number(orientation, "w", n.name, "node.pose.orientation.w", false, 1.0);
      double norm = std::sqrt(n.orientation[0] * n.orientation[0] + n.orientation[1] * n.orientation[1] +
                              n.orientation[2] * n.orientation[2] + n.orientation[3] * n.orientation[3]);
      if (norm < 1e-9) {
        n.orientation = {0.0, 0.0, 0.0, 1.0};
      } else {
        for (double& c : n.orientation) c /= norm;
      }
    }
    // Tags: meta.tag (tmap2 with tags) or node.tag; a scalar or a list.
    for (const YAML::Node& holder : {entry["meta"], body}) {
      if (!holder || !holder.IsMap() || !holder["tag"]) continue;
      const YAML::Node tags = holder["tag"];
      if (tags.IsScalar()) {
        n.tags.push_back(tags.Scalar());
      } else if (tags.IsSequence()) {
        for (const YAML::Node& t : tags)
          if (t.IsScalar()) n.tags.push_back(t.Scalar());
      }
    }
    if (metric_map.empty()) metric_map = scalarOr(body["map"], scalarOr(entry["meta"] ? entry["meta"]["map"] : YAML::Node(), ""));
    if (name.empty()) name = scalarOr(entry["meta"] ? entry["meta"]["pointset"] : YAML::Node(), scalarOr(body["pointset"], ""));

    const YAML::Node edge_list = body["edges"];
    if (edge_list && !edge_list.IsNull()) {
      if (!edge_list.IsSequence()) throw MapError(source_, "'edges' must be a list", n.name, "node.edges");
      std::size_t k = 0;
      for (const YAML::Node& e : edge_list) {
        const std::string field = "node.edges[" + std::to_string(k++) + "]";
        if (!e.IsMap()) throw MapError(source_, "edge is not a mapping", n.name, field);
        const YAML::Node target = e["node"];
        if (!target || !target.IsScalar() || target.Scalar().empty())
          throw MapError(source_, "edge has no target node", n.name, field + ".node");
        EdgeSpec spec;
        spec.source = n.name;
        spec.target = target.Scalar();
        spec.id = scalarOr(e["edge_id"], n.name + "_" + spec.target);
        spec.action = scalarOr(e["action"], "");
        edges.push_back(spec);
      }
    }
    nodes.push_back(std::move(n));
  }

  std::string source_;
  YAML::Node nodes_holder_;
};

}  // namespace

namespace {

TopologicalMap parseMapDom(const std::string& text, const std::string& source, MapFormat format) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw MapError(source, "YAML syntax error at line " + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  try {
    return MapReader(source).read(root, format);
  } catch (const MapError&) {
    throw;
  } catch (const YAML::Exception& e) {
    throw MapError(source, std::string("unexpected YAML structure: ") + e.msg);
  }
}

}  // namespace

TopologicalMap parseMap(const std::string& text, const std::string& source, MapFormat format) {
  if (text.size() > kMaxMapBytes)
    throw MapError(source, "map text of " + std::to_string(text.size()) + " bytes exceeds the limit of " +
                               std::to_string(kMaxMapBytes) + " bytes");
  TopologicalMap map = parseMapDom(text, source, format);
#if defined(__GLIBC__)
  // The yaml-cpp document of a large map is ~20x the file (357 MB peak for a 20,400-node map); it is gone now, but
  // glibc keeps the freed pages, so a tracker would hold them for its lifetime (535 MB RSS). Hand them back.
  malloc_trim(0);
#endif
  return map;
}

TopologicalMap loadMap(const std::string& path, MapFormat format) {
  // A device (/dev/zero), a FIFO or a directory would be read for ever or fail obscurely: regular files only,
  // and none larger than the parser can hold.
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (!ec && std::filesystem::exists(status)) {
    if (!std::filesystem::is_regular_file(status))
      throw MapError(path, "not a regular file (a directory, device or pipe)");
    const auto size = std::filesystem::file_size(path, ec);
    if (!ec && size > kMaxMapBytes)
      throw MapError(path, "file of " + std::to_string(size) + " bytes exceeds the limit of " +
                               std::to_string(kMaxMapBytes) + " bytes");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw MapError(path, "cannot open the file for reading");
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) throw MapError(path, "cannot read the file");
  return parseMap(buffer.str(), path, format);
}

}  // namespace topology
}  // namespace picker_localisation
