// simulator_node: runs one scenario of the s-bot swarm simulator and exposes it to ROS.
// Parameters, topics and services: see sim_ros_interface.h and the README.
#include <ros/ros.h>

#include "sim_ros_interface.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "simulator");
  int code = 1;
  {
    sbot_node::SimRosInterface sim;
    if (sim.init()) code = sim.run();
  }
  ros::shutdown();
  return code;
}
