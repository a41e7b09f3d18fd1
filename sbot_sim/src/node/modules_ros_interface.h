// The sensor and actuator modules of every robot on ROS: one sbot::sensors::Environment for the
// world (lamps, ambient light, LED rings, speakers, climate), and per robot one SensorSuite, one
// FrontGripper and one SideArm (core/sensors, core/actuators), with their topics and services in the
// robot's namespace. Physics stays in the core; this class converts.
//
// Per robot <r> (topics published at their own rate [Hz, sim time], param ~rates/<channel>,
// changeable at run time through <r>/set_sampling_rate; a topic nobody subscribes to is not computed):
//   proximity            sbot_msgs/ProximityArray   ~rates/proximity (10)
//   proximity/ir_<k>     sensor_msgs/Range          same rate, k = 0..14, only while subscribed;
//                        not advertised with ~per_sensor_topics false (nor light/sensor_<k>)
//   ground               sbot_msgs/GroundArray      ~rates/ground (10)     Medium, Detailed
//   light                sbot_msgs/LightArray       ~rates/light (10)      Medium, Detailed
//   slope                sbot_msgs/Slope            ~rates/slope (10)
//   imu                  sensor_msgs/Imu            ~rates/imu (10)   orientation + angular velocity
//   sound                sbot_msgs/SoundState       ~rates/sound (10)
//   camera/blobs         sbot_msgs/BlobArray        ~rates/camera (10)   fake camera
//   gripper/state        sbot_msgs/GripperState     ~rates/gripper (10)
//   side_arm/state       sbot_msgs/SideArmState     ~rates/side_arm (10)  Detailed only
//   battery              sbot_msgs/Battery          ~rates/battery (1)
//   climate              sbot_msgs/Climate          ~rates/climate (1)
//   leds/state           sbot_msgs/LedState         ~rates/leds (10)
//   sensor_markers       visualization_msgs/MarkerArray ~rates/markers (10): IR rays coloured by
//                        reading, LED groups in their colours, the lamps (frame world)
//   camera/image_raw     sensor_msgs/Image rgb8 + camera/camera_info (image_transport), ~rates/raw_camera
//                        (5): the omnidirectional camera (sensors/raw_camera.h), ray-cast in software,
//                        ~camera/width x ~camera/height (640 x 448), rendered at 1/~camera/internal_scale
//                        (4) and upscaled; only rendered while subscribed
//   sensors_available    sbot_msgs/SensorsAvailable latched
//   leds                 sbot_msgs/LedState         command (subscribed): all 8 groups at once
//   speaker              std_msgs/Float64           command: frequency [Hz], <= 0 = silence
// Each sensor family's topics are one SensorPublisher (sensor_publishers/, registered in its table.h).
// Services: set_gripper, set_side_arm, set_leds, set_sampling_rate (sbot_msgs/Set*).
// World: /sim/set_lamp, /sim/set_ambient_light; lamps and ambient light from the scenario YAML's
// world.lamps [{position: [x,y,z], intensity: mcd, colour: [r,g,b]}] and world.ambient_light.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include <ros/ros.h>
#include <sbot_msgs/LedState.h>
#include <sbot_msgs/SetAmbientLight.h>
#include <sbot_msgs/SetGripper.h>
#include <sbot_msgs/SetLamp.h>
#include <sbot_msgs/SetLeds.h>
#include <sbot_msgs/SetSamplingRate.h>
#include <sbot_msgs/SetSideArm.h>
#include <std_msgs/Float64.h>

#include "sbot_sim/core/scenario.h"
#include "sensor_publishers/sensor_publisher.h"

namespace sbot_node {

/// Hz of an sbot.h SAMPLING_RATE_xx code (1..8); 0 for an unknown code.
double samplingRateHz(unsigned code);

class RobotModulesRos {
 public:
  /// per_sensor_topics: ~per_sensor_topics (read once for all robots by ModulesRosInterface).
  RobotModulesRos(ros::NodeHandle nh, ros::NodeHandle pnh, const std::string& name, bool per_sensor_topics);
  ~RobotModulesRos();
  void bind(sbot::World& world, sbot::sensors::Environment& env, sbot::Robot& robot);
  void unbind();
  bool bound() const { return topics_.robot != nullptr; }
  const std::string& name() const { return name_; }
  /// After every world step: module updates (battery, gripper, side arm) and due publications.
  void update(double dt, double sim_time);
  sbot::sensors::SensorSuite* suite() { return suite_.get(); }
  sbot::actuators::FrontGripper* gripper() { return gripper_.get(); }

 private:
  void publishAvailable();
  void onLeds(const sbot_msgs::LedState::ConstPtr& msg);
  void onSpeaker(const std_msgs::Float64::ConstPtr& msg);
  bool onSetGripper(sbot_msgs::SetGripper::Request& req, sbot_msgs::SetGripper::Response& res);
  bool onSetSideArm(sbot_msgs::SetSideArm::Request& req, sbot_msgs::SetSideArm::Response& res);
  bool onSetLeds(sbot_msgs::SetLeds::Request& req, sbot_msgs::SetLeds::Response& res);
  bool onSetSamplingRate(sbot_msgs::SetSamplingRate::Request& req, sbot_msgs::SetSamplingRate::Response& res);

  std::string name_;
  std::unique_ptr<sbot::sensors::SensorSuite> suite_;
  std::unique_ptr<sbot::actuators::FrontGripper> gripper_;
  std::unique_ptr<sbot::actuators::SideArm> side_arm_;
  /// Node handle, subscriber rosters, rates and the modules above for the publishers; before them,
  /// which it outlives.
  RobotTopics topics_;
  std::vector<std::unique_ptr<SensorPublisher>> publishers_;  ///< sensorPublisherTable()'s order
  double next_any_ = 0;  ///< [s] earliest topics_.rates()[*].next
  ros::Publisher available_pub_;
  ros::Subscriber leds_sub_, speaker_sub_;
  ros::ServiceServer set_gripper_srv_, set_side_arm_srv_, set_leds_srv_, set_rate_srv_;
};

class ModulesRosInterface {
 public:
  /// `scenario`'s lamps and ambient light (checked by the core's scenario parser) are the sensed
  /// environment; /sim/set_lamp and /sim/set_ambient_light change them, and the changes outlive a reset.
  ModulesRosInterface(ros::NodeHandle nh, ros::NodeHandle pnh, std::unique_ptr<sbot::World>& world,
                      const sbot::Scenario& scenario);
  ~ModulesRosInterface();
  /// ~rates/<channel>: every channel one of the modules' (an unknown one was ignored), a number.
  /// Logs what is wrong as fatal and returns false.
  static bool checkRateParams(const ros::NodeHandle& pnh);
  /// Build the Environment for the current world and bind every robot. Call after the world exists.
  void attach();
  /// Drop every module and the Environment. Call before the world is destroyed (reset, shutdown).
  void detach();
  /// After every World::step().
  void afterStep(double sim_time);
  // Hooks for spawn / delete / model switch (SwarmRosInterface).
  void robotAdded(sbot::Robot& robot);
  void robotRemoving(sbot::Robot& robot);
  void robotRebuilt(sbot::Robot& robot);
  sbot::sensors::Environment* environment() { return env_.get(); }

 private:
  bool onSetLamp(sbot_msgs::SetLamp::Request& req, sbot_msgs::SetLamp::Response& res);
  bool onSetAmbient(sbot_msgs::SetAmbientLight::Request& req, sbot_msgs::SetAmbientLight::Response& res);
  RobotModulesRos& modulesFor(const std::string& name);

  ros::NodeHandle nh_, pnh_;
  std::unique_ptr<sbot::World>& world_;
  sbot::World* bound_world_ = nullptr;
  std::vector<sbot::LampSpawn> lamps_;
  double ambient_ = 0;  ///< [mcd/cm^2]
  std::unique_ptr<sbot::sensors::Environment> env_;
  std::map<std::string, std::unique_ptr<RobotModulesRos>> robots_;
  bool per_sensor_topics_ = true;  ///< ~per_sensor_topics, for every robot's modules
  ros::ServiceServer set_lamp_srv_, set_ambient_srv_;
};

}  // namespace sbot_node
