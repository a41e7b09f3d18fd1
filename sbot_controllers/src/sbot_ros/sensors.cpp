// sbot.h sensors: proximity, ground, light (sampled: readSensor / readAll), slope, climate, battery.
#include "api.h"

using namespace sbot_api;

extern "C" {

unsigned getProximitySensor(unsigned sensor) { return readSensor("getProximitySensor", &Api::proximity, sensor, 15); }

void getAllProximitySensors(unsigned sensors[15]) { readAll("getAllProximitySensors", &Api::proximity, sensors, 15); }

void setProximitySamplingRate(SamplingRate rate) { setRate("proximity", rate, "setProximitySamplingRate"); }

unsigned getGroundSensor(unsigned sensor) { return readSensor("getGroundSensor", &Api::ground, sensor, 4); }

void getAllGroundSensors(unsigned sensors[4]) { readAll("getAllGroundSensors", &Api::ground, sensors, 4); }

void setGroundSamplingRate(SamplingRate rate) { setRate("ground", rate, "setGroundSamplingRate"); }

unsigned getLightSensor(unsigned sensor) { return readSensor("getLightSensor", &Api::light, sensor, 8); }

void getAllLightSensors(unsigned sensors[8]) { readAll("getAllLightSensors", &Api::light, sensors, 8); }

void setLightSamplingRate(SamplingRate rate) { setRate("light", rate, "setLightSamplingRate"); }

void getTemperatureAndHumidityLeft(float* temperature, float* humidity) {
  using M = sbot_msgs::Climate;
  readFields("getTemperatureAndHumidityLeft", &Api::climate, false, into(temperature, &M::temperature_left),
             into(humidity, &M::humidity_left));
}

void getTemperatureAndHumidityRight(float* temperature, float* humidity) {
  using M = sbot_msgs::Climate;
  readFields("getTemperatureAndHumidityRight", &Api::climate, false, into(temperature, &M::temperature_right),
             into(humidity, &M::humidity_right));
}

void getSlope(int* pitch, int* roll) {
  readFields("getSlope", &Api::slope, true, into(pitch, &sbot_msgs::Slope::pitch), into(roll, &sbot_msgs::Slope::roll));
}

void setSlopeSamplingRate(SamplingRate rate) { setRate("slope", rate, "setSlopeSamplingRate"); }

unsigned getBatteryVoltage(void) {
  return readField("getBatteryVoltage", &Api::battery, &sbot_msgs::Battery::voltage_units);
}

}  // extern "C"
