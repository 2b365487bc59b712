// palcas bridge node: SUMO in-process (libsumo) or an external sumo-gui (libtraci),
// depending on which library this executable was linked with.
#include <ros/ros.h>

#include "palcas_sumo_bridge/bridge_node.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "palcas_sumo_bridge");
  ros::NodeHandle nh;
  ros::NodeHandle private_nh("~");
  try {
    palcas::bridge::BridgeNode node(nh, private_nh);
    return node.run();
  } catch (const std::exception& e) {
    ROS_FATAL("palcas bridge: %s", e.what());
    return 1;
  }
}
