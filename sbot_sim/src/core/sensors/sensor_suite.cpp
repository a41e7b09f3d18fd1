#include "sbot_sim/core/sensors/sensor_suite.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/robot.h"
#include "sbot_sim/core/robot_description.h"
#include "sbot_sim/core/sensors/sensor_common.h"
#include "sbot_sim/core/world.h"

namespace sbot::sensors {

const char* channelName(SensorChannel c) {
  switch (c) {
    case SensorChannel::Proximity: return "proximity";
    case SensorChannel::Ground: return "ground";
    case SensorChannel::Light: return "light";
    case SensorChannel::Slope: return "slope";
    case SensorChannel::Sound: return "sound";
    case SensorChannel::FakeCamera: return "fake_camera";
    case SensorChannel::Battery: return "battery";
    case SensorChannel::Climate: return "climate";
  }
  return "?";
}

const std::vector<SensorChannel>& allChannels() {
  static const std::vector<SensorChannel> all{SensorChannel::Proximity, SensorChannel::Ground,
                                              SensorChannel::Light,     SensorChannel::Slope,
                                              SensorChannel::Sound,     SensorChannel::FakeCamera,
                                              SensorChannel::Battery,   SensorChannel::Climate};
  return all;
}

SensorSuite::SensorSuite(World& world, Robot& robot, Environment& env, const SuiteOptions& options)
    : world_(world), robot_(robot), env_(env) {
  const RobotDescription& d = robot.description();
  // Proximity: every level has the 15 IR frames.
  const std::string ir_model = options.ir_model.empty() ? d.extraOr("ir_model", "raytrace") : options.ir_model;
  if (ir_model == "lut") {
    const IrLookupTable* lut = options.ir_lut ? options.ir_lut : &defaultIrLookupTable();
    proximity_ = std::make_unique<ProximitySensors>(world, robot, ProximitySensors::Model::LookupTable, lut);
  } else if (ir_model == "raytrace") {
    proximity_ = std::make_unique<ProximitySensors>(world, robot, ProximitySensors::Model::RayTraced);
  } else {
    throw ConfigError(d.sidecar_path, "extra/ir_model", "expected 'lut' or 'raytrace', got '" + ir_model + "'");
  }
  const bool ground = options.ground_sensors.value_or(extraBool(d, "ground_sensors", false));
  if (ground) ground_ = std::make_unique<GroundSensors>(world, robot);
  const bool light = options.light_sensors.value_or(d.extraOr("light_ring", "full") == "full");
  if (light) light_ = std::make_unique<LightSensors>(world, robot, env);
  inclinometer_ = std::make_unique<Inclinometer>(robot);
  sound_ = std::make_unique<SoundSensors>(world, robot, env);
  fake_camera_ = std::make_unique<FakeCamera>(world, robot, env);
  battery_ = std::make_unique<Battery>(robot, options.battery);
  climate_ = std::make_unique<ClimateSensors>(env);
}

SensorSuite::~SensorSuite() = default;

bool SensorSuite::available(SensorChannel c) const {
  switch (c) {
    case SensorChannel::Proximity: return proximity_ != nullptr;
    case SensorChannel::Ground: return ground_ != nullptr;
    case SensorChannel::Light: return light_ != nullptr;
    case SensorChannel::Slope: return inclinometer_ != nullptr;
    case SensorChannel::Sound: return sound_ != nullptr;
    case SensorChannel::FakeCamera: return fake_camera_ != nullptr;
    case SensorChannel::Battery: return battery_ != nullptr;
    case SensorChannel::Climate: return climate_ != nullptr;
  }
  return false;
}

std::vector<SensorChannel> SensorSuite::availableChannels() const {
  std::vector<SensorChannel> out;
  for (SensorChannel c : allChannels())
    if (available(c)) out.push_back(c);
  return out;
}

std::string SensorSuite::proximityModel() const {
  return proximity_ && proximity_->model() == ProximitySensors::Model::LookupTable ? "lut" : "raytrace";
}

void SensorSuite::update(double dt) { battery_->update(dt); }

unsigned SensorSuite::getProximitySensor(unsigned sensor) {
  if (sensor >= kProximitySensors) throw std::out_of_range("proximity sensor must be in [0,14]");
  return proximity_ ? proximity_->read(static_cast<int>(sensor)) : 0;
}

std::array<unsigned, kProximitySensors> SensorSuite::getAllProximitySensors() {
  return proximity_ ? proximity_->readAll() : std::array<unsigned, kProximitySensors>{};
}

unsigned SensorSuite::getGroundSensor(unsigned sensor) {
  if (sensor >= kGroundSensors) throw std::out_of_range("ground sensor must be in [0,3]");
  return ground_ ? ground_->read(static_cast<int>(sensor)) : 0;
}

std::array<unsigned, kGroundSensors> SensorSuite::getAllGroundSensors() {
  return ground_ ? ground_->readAll() : std::array<unsigned, kGroundSensors>{};
}

unsigned SensorSuite::getLightSensor(unsigned sensor) {
  if (sensor >= kLightSensors) throw std::out_of_range("light sensor must be in [0,7]");
  return light_ ? light_->read(static_cast<int>(sensor)) : 0;
}

std::array<unsigned, kLightSensors> SensorSuite::getAllLightSensors() {
  return light_ ? light_->readAll() : std::array<unsigned, kLightSensors>{};
}

namespace {

// Pass one raw value of a module without its own effects hook through the world's effects.
double effected(const World& world, const Robot& robot, const char* channel, int index, double value) {
  if (world.effects().empty()) return value;
  SensorSample s;
  s.channel = channel;
  s.index = index;
  s.value = value;
  return applyEffects(world, robot, s);
}

int roundDegrees(double deg) {
  if (std::isnan(deg)) return 0;
  return static_cast<int>(std::lround(std::max(-180.0, std::min(180.0, deg))));
}

}  // namespace

void SensorSuite::getSlope(int* pitch, int* roll) const {
  const Slope s = inclinometer_->slope();
  if (pitch) *pitch = roundDegrees(effected(world_, robot_, "slope", 0, s.pitch));
  if (roll) *roll = roundDegrees(effected(world_, robot_, "slope", 1, s.roll));
}

unsigned SensorSuite::getBatteryVoltage() const {
  const double v = effected(world_, robot_, "battery", 0, battery_->voltage());
  const double r = v / battery_->params().full_scale_voltage * 255.0;
  return std::isnan(r) ? 0u : static_cast<unsigned>(std::lround(std::max(0.0, std::min(255.0, r))));
}

void SensorSuite::readClimate(ClimateSensor& sensor, int index, float* temperature, float* humidity) {
  if (temperature) {
    const double t = effected(world_, robot_, "temperature", index, sensor.temperature());
    *temperature = static_cast<float>(std::isnan(t) ? 0.0 : std::max(-40.0, std::min(123.0, t)));
  }
  if (humidity) {
    const double h = effected(world_, robot_, "humidity", index, sensor.humidity());
    *humidity = static_cast<float>(std::isnan(h) ? 0.0 : std::max(0.0, std::min(100.0, h)));
  }
}

void SensorSuite::getTemperatureAndHumidityLeft(float* temperature, float* humidity) {
  readClimate(climate_->left(), 0, temperature, humidity);
}

void SensorSuite::getTemperatureAndHumidityRight(float* temperature, float* humidity) {
  readClimate(climate_->right(), 1, temperature, humidity);
}

double SensorSuite::getSoundIntensity(unsigned mic) {
  if (mic >= kMicrophones) throw std::out_of_range("microphone must be in [0,2]");
  return sound_->read(static_cast<int>(mic));
}

std::array<double, kMicrophones> SensorSuite::getAllSoundIntensities() { return sound_->readAll(); }

std::vector<Blob> SensorSuite::getFakeCameraBlobs() const { return fake_camera_->blobs(); }

Quat SensorSuite::imuOrientation() const { return inclinometer_->orientation(); }
Vec3 SensorSuite::imuAngularVelocity() const { return inclinometer_->angularVelocity(); }

void SensorSuite::setLightColor(unsigned light, unsigned r, unsigned g, unsigned b, unsigned blink) {
  if (light >= static_cast<unsigned>(kLedGroups)) throw std::out_of_range("light must be in [0,7]");
  env_.setLightColor(robot_.name(), static_cast<int>(light), r, g, b, blink);
}

void SensorSuite::setAllLightColor(const std::array<unsigned, kLedGroups>& r,
                                   const std::array<unsigned, kLedGroups>& g,
                                   const std::array<unsigned, kLedGroups>& b,
                                   const std::array<unsigned, kLedGroups>& blink) {
  env_.setAllLightColor(robot_.name(), r, g, b, blink);
}

void SensorSuite::setSameLightColor(unsigned r, unsigned g, unsigned b, unsigned blink) {
  env_.setSameLightColor(robot_.name(), r, g, b, blink);
}

void SensorSuite::setSpeaker(double frequency_hz, double intensity) {
  env_.setSpeaker(robot_.name(), frequency_hz, intensity);
}

void SensorSuite::stopSpeaker() { env_.stopSpeaker(robot_.name()); }

}  // namespace sbot::sensors
