// rviz markers for people detections (PersonDetectionArray has no rviz display).
#pragma once

#include <picker_localisation/PersonDetectionArray.h>
#include <visualization_msgs/MarkerArray.h>

namespace picker_localisation {
namespace ros_adapter {

// One cylinder per person (blue: LiDAR only, green: camera-confirmed, orange: other sensors; opacity from the
// confidence) and a label with the track id, in the array's frame; a DELETEALL first so old people vanish.
visualization_msgs::MarkerArray personMarkers(const picker_localisation::PersonDetectionArray& people);

}  // namespace ros_adapter
}  // namespace picker_localisation
