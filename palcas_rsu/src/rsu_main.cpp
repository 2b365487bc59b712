// palcas RSU node: one per cluster, each in its own namespace.
#include <ros/ros.h>

#include "palcas_rsu/rsu_node.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "palcas_rsu");
  ros::NodeHandle nh;
  ros::NodeHandle private_nh("~");
  try {
    palcas::rsu::RsuNode node(nh, private_nh);
    ros::spin();
    node.shutdown();
    return 0;
  } catch (const std::exception& e) {
    ROS_FATAL("palcas rsu: %s", e.what());
    return 1;
  }
}
