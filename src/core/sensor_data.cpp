#include "picker_localisation/core/sensor_data.h"

#include <cmath>

namespace picker_localisation {
namespace core {

bool LaserScan::validRange(std::size_t i) const {
  if (i >= ranges.size()) return false;
  const double r = ranges[i];
  return std::isfinite(r) && r >= range_min && r <= range_max && r > 0.0;
}

std::size_t LaserScan::validCount() const {
  std::size_t n = 0;
  for (std::size_t i = 0; i < ranges.size(); ++i) n += validRange(i) ? 1 : 0;
  return n;
}

}  // namespace core
}  // namespace picker_localisation
