// palcas RSU node: one per cluster, each in its own namespace.
#include <ros/ros.h>

#include <csignal>

#include "palcas_rsu/rsu_node.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "palcas_rsu");
  // roslaunch ends nodes with SIGINT, a supervisor or `kill` with SIGTERM: both shut the node
  // down cleanly, so it writes its checkpoint instead of losing what it learnt.
  std::signal(SIGTERM, [](int) { ros::requestShutdown(); });
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
