// palcas federation server node: sample-weighted FedAvg of the RSUs' PDQN models.
#include <ros/ros.h>

#include "palcas_fedserver/fedserver_node.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "palcas_fedserver");
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
