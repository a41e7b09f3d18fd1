#include "sbot_sim/core/sensors/sound.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/robot.h"
#include "sbot_sim/core/robot_description.h"
#include "sbot_sim/core/sensors/sensor_common.h"
#include "sbot_sim/core/world.h"

namespace sbot::sensors {

double soundAmplitudeTerm(double alpha, double distance, double p0) {
  return (1.0 - 0.9 * alpha / M_PI) / (1.0 + distance * distance / p0);
}

double totalPerceivedAmplitude(double amplitude) { return 2.0 / (1.0 + std::exp(-amplitude)) - 1.0; }

SoundSensors::SoundSensors(World& world, Robot& robot, const Environment& env)
    : world_(world), robot_(robot), env_(env) {
  params_.noise = extraNumber(robot.description(), "sound_noise", params_.noise);
  for (int i = 0; i < kMicrophones; ++i) {
    links_[i] = LinkRef("mic_" + std::to_string(i));
    if (!robot.hasLink(links_[i].name())) {
      throw ConfigError(robot.description().urdf_path, "link " + links_[i].name(), "missing (needed by the microphones)");
    }
  }
}

double SoundSensors::rawAmplitude(int mic) const {
  if (mic < 0 || mic >= kMicrophones) throw std::out_of_range("microphone must be in [0,2]");
  const Pose pose = robot_.linkPose(links_[mic]);
  const Vec3 axis = pose.orientation * Vec3::UnitX();
  double a = 0;
  for (Robot* other : world_.robots()) {
    if (other == &robot_) continue;
    const Speaker& sp = env_.speaker(other->name());
    if (!sp.on || sp.intensity <= 0) continue;
    if (sp.frequency < params_.band_low || sp.frequency > params_.band_high) continue;
    const Vec3 source = other->hasLink("speaker")  ? other->linkPose("speaker").position
                        : other->hasLink("turret") ? other->linkPose("turret").position
                                                   : other->basePose().position;
    const Vec3 v = source - pose.position;
    const double d = v.norm();
    const double alpha = d > 0 ? std::acos(std::max(-1.0, std::min(1.0, axis.dot(v) / d))) : 0.0;
    a += sp.intensity * soundAmplitudeTerm(alpha, d, params_.p0);
  }
  return a;
}

double SoundSensors::amplitude(int mic) {
  SensorSample s;
  s.channel = "sound";
  s.index = mic;
  s.value = rawAmplitude(mic);
  double a = applyEffects(world_, robot_, s);
  if (std::isnan(a) || a < 0) a = 0;
  if (a > 0 && params_.noise > 0) a *= 1.0 + robot_.random().uniform("sound", -params_.noise, params_.noise);
  return a;
}

std::array<double, kMicrophones> SoundSensors::readAll() {
  std::array<double, kMicrophones> out{};
  for (int i = 0; i < kMicrophones; ++i) out[i] = read(i);
  return out;
}

}  // namespace sbot::sensors
