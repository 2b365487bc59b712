// palcas federation server node: sample-weighted FedAvg of the RSUs' PDQN models.
#include <ros/ros.h>

#include <csignal>

#include "palcas_fedserver/fedserver_node.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "palcas_fedserver");
  // roslaunch ends nodes with SIGINT, a supervisor or `kill` with SIGTERM: both shut the node
  // down cleanly, so it writes its checkpoint instead of losing what it learnt.
  std::signal(SIGTERM, [](int) { ros::requestShutdown(); });
  ros::NodeHandle nh;
  ros::NodeHandle private_nh("~");
  try {
    palcas::fedserver::FedServerNode node(nh, private_nh);
    ros::spin();
  } catch (const std::exception& e) {
    ROS_FATAL("palcas fedserver: %s", e.what());
    return 1;
  }
  return 0;
}
