// SensorSuite: all sensors of one robot behind the standard s-bot API's read functions (sbot.h,
// seed Appendix A), in the API's units. It owns the modules appropriate to the robot's level, as
// the level's sidecar `extra` says (sbot_description/config/sbot_parameters.yaml):
//
//   channel      module            levels / sidecar key
//   Proximity    ProximitySensors  all; ir_model: lut (Fast, Simple) | raytrace (Basic, Medium, Detailed)
//   Ground       GroundSensors     ground_sensors: true (Medium, Detailed)
//   Light        LightSensors      light_ring: full (Medium, Detailed; 2.2.8 "available in the Medium
//                                  and Detailed models"); light_ring: leds (Fast, Simple, Basic) has
//                                  the LEDs (seen by cameras) but no sensors. SuiteOptions can force it.
//   Slope        Inclinometer      all
//   Sound        SoundSensors      all (Table 4.4)
//   FakeCamera   FakeCamera        all (2.2.5)
//   Battery      Battery           all (must be updated every step: update(dt))
//   Climate      ClimateSensors    all
// A read on an unavailable channel returns zeros (and an empty blob list); check available().
// Effects (effects.h): the IR, ground, light and sound modules pass their raw values through the
// world's effects themselves; the suite does the same for the modules that have none: slope
// (channel "slope", index 0 = pitch, 1 = roll, [deg]), battery ("battery", terminal voltage [V])
// and climate ("temperature" [deg C] / "humidity" [%], index 0 = left, 1 = right), each before
// rounding/clamping to the API range. The fake camera and the IMU accessors are not effected.
// The light ring and speaker ACTUATORS (setLightColor, ...) are forwarded to the Environment so a
// controller has the whole light/sound API in one place. Every module computes on read (no
// per-step cost) except the battery. Units and models: see the module headers.
//
// Lifetime: the suite keeps references to the World, the Robot and the Environment; destroy it
// before the robot is removed.
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "sbot_sim/core/sensors/battery.h"
#include "sbot_sim/core/sensors/climate.h"
#include "sbot_sim/core/sensors/environment.h"
#include "sbot_sim/core/sensors/fake_camera.h"
#include "sbot_sim/core/sensors/ground.h"
#include "sbot_sim/core/sensors/inclinometer.h"
#include "sbot_sim/core/sensors/light.h"
#include "sbot_sim/core/sensors/proximity.h"
#include "sbot_sim/core/sensors/sound.h"

namespace sbot {

class World;
class Robot;

namespace sensors {

enum class SensorChannel { Proximity, Ground, Light, Slope, Sound, FakeCamera, Battery, Climate };
/// "proximity", "ground", "light", "slope", "sound", "fake_camera", "battery", "climate".
const char* channelName(SensorChannel c);
const std::vector<SensorChannel>& allChannels();

struct SuiteOptions {
  /// Override the sidecar's ir_model ("lut" or "raytrace"); empty = sidecar.
  std::string ir_model;
  /// Force the light sensors on (true) or off (false); unset = sidecar light_ring.
  std::optional<bool> light_sensors;
  /// Force the ground sensors; unset = sidecar ground_sensors.
  std::optional<bool> ground_sensors;
  /// IR table for ir_model lut; null = defaultIrLookupTable() (the shipped file).
  const IrLookupTable* ir_lut = nullptr;
  BatteryParams battery;
};

class SensorSuite {
 public:
  SensorSuite(World& world, Robot& robot, Environment& env, const SuiteOptions& options = SuiteOptions());
  ~SensorSuite();
  SensorSuite(const SensorSuite&) = delete;
  SensorSuite& operator=(const SensorSuite&) = delete;

  bool available(SensorChannel channel) const;
  std::vector<SensorChannel> availableChannels() const;
  /// "lut" or "raytrace".
  std::string proximityModel() const;

  /// The per-step part: integrate the battery. Call once after every World::step() with its dt.
  void update(double dt);

  // ---- sbot.h reads ------------------------------------------------------------------------------
  unsigned getProximitySensor(unsigned sensor);                     ///< [0,8191]
  std::array<unsigned, kProximitySensors> getAllProximitySensors();
  unsigned getGroundSensor(unsigned sensor);                        ///< [0,255]
  std::array<unsigned, kGroundSensors> getAllGroundSensors();
  unsigned getLightSensor(unsigned sensor);                         ///< [0,700]
  std::array<unsigned, kLightSensors> getAllLightSensors();
  void getSlope(int* pitch, int* roll) const;                       ///< [deg]
  unsigned getBatteryVoltage() const;                               ///< [0,255] = 0..10 V
  void getTemperatureAndHumidityLeft(float* temperature, float* humidity);
  void getTemperatureAndHumidityRight(float* temperature, float* humidity);

  // ---- reads without an sbot.h function ----------------------------------------------------------
  /// Total perceived amplitude (eq. 2.13) at microphone k = 0..2, [0,1).
  double getSoundIntensity(unsigned mic);
  std::array<double, kMicrophones> getAllSoundIntensities();
  /// Fake camera blobs, nearest first.
  std::vector<Blob> getFakeCameraBlobs() const;
  /// base_link orientation (world) and body-frame angular velocity, for sensor_msgs/Imu.
  Quat imuOrientation() const;
  Vec3 imuAngularVelocity() const;

  // ---- light ring and speaker (sbot.h setLightColor / setAllLightColor / setSameLightColor) -----
  void setLightColor(unsigned light, unsigned r, unsigned g, unsigned b, unsigned blink);
  void setAllLightColor(const std::array<unsigned, kLedGroups>& r, const std::array<unsigned, kLedGroups>& g,
                        const std::array<unsigned, kLedGroups>& b, const std::array<unsigned, kLedGroups>& blink);
  void setSameLightColor(unsigned r, unsigned g, unsigned b, unsigned blink);
  void setSpeaker(double frequency_hz, double intensity = 1.0);
  void stopSpeaker();

  // ---- modules (null when not available) ---------------------------------------------------------
  ProximitySensors* proximity() { return proximity_.get(); }
  GroundSensors* ground() { return ground_.get(); }
  LightSensors* light() { return light_.get(); }
  SoundSensors* sound() { return sound_.get(); }
  FakeCamera* fakeCamera() { return fake_camera_.get(); }
  Battery& battery() { return *battery_; }
  ClimateSensors& climate() { return *climate_; }
  const Inclinometer& inclinometer() const { return *inclinometer_; }
  Robot& robot() { return robot_; }

 private:
  void readClimate(ClimateSensor& sensor, int index, float* temperature, float* humidity);
  World& world_;
  Robot& robot_;
  Environment& env_;
  std::unique_ptr<ProximitySensors> proximity_;
  std::unique_ptr<GroundSensors> ground_;
  std::unique_ptr<LightSensors> light_;
  std::unique_ptr<Inclinometer> inclinometer_;
  std::unique_ptr<SoundSensors> sound_;
  std::unique_ptr<FakeCamera> fake_camera_;
  std::unique_ptr<Battery> battery_;
  std::unique_ptr<ClimateSensors> climate_;
};

}  // namespace sensors
}  // namespace sbot
