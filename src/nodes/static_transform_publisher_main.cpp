// static_transform_publisher x y z yaw pitch roll parent child
// Latches one transform on /tf_static (Debian ships tf2_ros without this executable).
#include <geometry_msgs/TransformStamped.h>
#include <ros/ros.h>
#include <tf2/LinearMath/Quaternion.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include <cstdlib>
#include <string>

int main(int argc, char** argv) {
  ros::init(argc, argv, "static_transform_publisher", ros::init_options::AnonymousName);
  std::vector<std::string> args;
  ros::removeROSArgs(argc, argv, args);
  if (args.size() != 9) {
    ROS_FATAL("usage: static_transform_publisher x y z yaw pitch roll parent_frame child_frame (m, rad)");
    return 1;
  }
  double v[6];
  for (int i = 0; i < 6; ++i) {
    char* end = nullptr;
    v[i] = std::strtod(args[static_cast<std::size_t>(i + 1)].c_str(), &end);
    if (end == args[static_cast<std::size_t>(i + 1)].c_str() || *end != '\0') {
      ROS_FATAL("static_transform_publisher: '%s' is not a number", args[static_cast<std::size_t>(i + 1)].c_str());
      return 1;
    }
  }
  geometry_msgs::TransformStamped t;
  t.header.frame_id = args[7];
  t.child_frame_id = args[8];
  t.transform.translation.x = v[0];
  t.transform.translation.y = v[1];
  t.transform.translation.z = v[2];
  tf2::Quaternion q;
  q.setRPY(v[5], v[4], v[3]);
  t.transform.rotation.x = q.x();
  t.transform.rotation.y = q.y();
  t.transform.rotation.z = q.z();
  t.transform.rotation.w = q.w();
  ros::NodeHandle nh;
  tf2_ros::StaticTransformBroadcaster broadcaster;
  t.header.stamp = ros::Time::now();
  broadcaster.sendTransform(t);
  ros::spin();
  return 0;
}
