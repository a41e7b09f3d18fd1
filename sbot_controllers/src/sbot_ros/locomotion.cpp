// sbot.h tracks and turret: setSpeed, getSpeed, getTrackTorque, the turret rotation and torque.
#include "api.h"

#include <sbot_msgs/SetTurret.h>
#include <sbot_msgs/TrackSpeed.h>

using namespace sbot_api;

extern "C" {

void setSpeed(int left, int right) {
  if (!ready("setSpeed")) return;
  if (left < -127 || left > 127 || right < -127 || right > 127)
    report(false, "setSpeed(%d, %d): outside [-127, 127], clamped", left, right);
  sbot_msgs::TrackSpeed m;
  m.left = static_cast<int16_t>(left < -127 ? -127 : left > 127 ? 127 : left);
  m.right = static_cast<int16_t>(right < -127 ? -127 : right > 127 ? 127 : right);
  g->speed_pub.publish(m);
  ++g->speed_sent;
}

void getSpeed(int* left, int* right) {
  using M = sbot_msgs::TrackState;
  readFields("getSpeed", &Api::tracks, false, into(left, &M::measured_left), into(right, &M::measured_right));
}

void getTrackTorque(int* left, int* right) {
  using M = sbot_msgs::TrackState;
  readFields("getTrackTorque", &Api::tracks, false, into(left, &M::torque_left), into(right, &M::torque_right));
}

void setTurretRotation(int pos) {
  sbot_msgs::SetTurret srv;
  srv.request.position = toInt16(pos);
  call("set_turret", srv, "setTurretRotation");
}

int getTurretRotation(void) { return readField("getTurretRotation", &Api::turret, &sbot_msgs::TurretState::rotation); }

int getTurretRotationTorque(void) {
  return readField("getTurretRotationTorque", &Api::turret, &sbot_msgs::TurretState::torque);
}

}  // extern "C"
