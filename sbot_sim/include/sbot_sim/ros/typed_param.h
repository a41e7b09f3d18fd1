// Reading a node's private parameters with their types checked (the simulator, the swarm manager).
#pragma once

#include <cmath>
#include <sstream>
#include <string>
#include <type_traits>

#include <ros/ros.h>

namespace sbot_ros_params {

template <typename T> const char* paramTypeName();
template <> inline const char* paramTypeName<int>() { return "a whole number"; }
template <> inline const char* paramTypeName<double>() { return "a number"; }
template <> inline const char* paramTypeName<bool>() { return "true or false"; }
template <> inline const char* paramTypeName<std::string>() { return "a string"; }

/// `nh`'s parameter `name` into `value`, which keeps its default when the parameter is absent.
/// NodeHandle::param() reads a value of the wrong type (`_robots:=abc`, `_paused:=maybe`) as the
/// default without a word; here that is logged as fatal ("<who>: ~name must be ..."), naming the
/// type expected and the value found, and the result is false. A double must also be finite.
template <typename T>
bool readTypedParam(const ros::NodeHandle& nh, const std::string& name, T& value, const char* who = "simulator") {
  if (!nh.hasParam(name)) return true;
  if (nh.getParam(name, value)) {
    if constexpr (std::is_floating_point_v<T>) {
      if (!std::isfinite(value)) {
        ROS_FATAL("%s: ~%s must be a finite number, got %g", who, name.c_str(), static_cast<double>(value));
        return false;
      }
    }
    return true;
  }
  XmlRpc::XmlRpcValue found;
  nh.getParam(name, found);
  std::ostringstream text;
  text << found;
  ROS_FATAL("%s: ~%s must be %s, got '%s'", who, name.c_str(), paramTypeName<T>(), text.str().c_str());
  return false;
}

}  // namespace sbot_ros_params
