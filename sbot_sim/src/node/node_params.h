// Reading the node's private parameters with their types checked.
#pragma once

#include <sstream>
#include <string>

#include <ros/ros.h>

namespace sbot_node {

template <typename T> const char* paramTypeName();
template <> inline const char* paramTypeName<int>() { return "a whole number"; }
template <> inline const char* paramTypeName<double>() { return "a number"; }
template <> inline const char* paramTypeName<bool>() { return "true or false"; }
template <> inline const char* paramTypeName<std::string>() { return "a string"; }

/// `nh`'s parameter `name` into `value`, which keeps its default when the parameter is absent.
/// NodeHandle::param() reads a value of the wrong type (`_robots:=abc`, `_paused:=maybe`) as the
/// default without a word; here that is logged as fatal, naming the type expected and the value
/// found, and the result is false.
template <typename T>
bool readTypedParam(const ros::NodeHandle& nh, const std::string& name, T& value) {
  if (!nh.hasParam(name)) return true;
  if (nh.getParam(name, value)) return true;
  XmlRpc::XmlRpcValue found;
  nh.getParam(name, found);
  std::ostringstream text;
  text << found;
  ROS_FATAL("simulator: ~%s must be %s, got '%s'", name.c_str(), paramTypeName<T>(), text.str().c_str());
  return false;
}

}  // namespace sbot_node
