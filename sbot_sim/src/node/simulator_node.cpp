// simulator_node: runs one scenario of the s-bot swarm simulator and exposes it to ROS.
// Parameters, topics and services: see sim_ros_interface.h and docs/ros_api.md.
#include <csignal>

#include <ros/ros.h>

#include "sim_ros_interface.h"

int main(int argc, char** argv) {
  // Our own SIGINT/SIGTERM handling: the loop finishes its step, logs the run summary, then shuts
  // ROS down (roscpp's handler would shut down first and swallow the summary).
  ros::init(argc, argv, "simulator", ros::init_options::NoSigintHandler);
  std::signal(SIGINT, sbot_node::SimRosInterface::requestStop);
  std::signal(SIGTERM, sbot_node::SimRosInterface::requestStop);
  // Exit status: 2 when the scenario or a parameter is refused at start-up, 1 when a step fails
  // (an ODE error ends the process with 1 itself: src/core/ode_errors.h), 0 otherwise.
  int code = 2;
  {
    sbot_node::SimRosInterface sim;
    if (sim.init()) code = sim.run();
  }
  ros::shutdown();
  return code;
}
