/* Calls every function of the standard s-bot API (sbot.h) once against the simulator and checks the
 * answers are plausible. Used by test/sbot_api_functions.test (test_sbot_api_functions.py); run in the
 * namespace of a Detailed s-bot (every module exists). Prints "FAIL: ..." lines and exits 1 on any
 * failure, "SBOT_API_OK" and 0 otherwise. Wall-clock waits: run the simulator at real time. */
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "sbot.h"

static int errors = 0, warnings = 0, failures = 0;
static void onError(const char *text) { ++errors; fprintf(stderr, "error: %s\n", text); }
static void onWarning(const char *text) { ++warnings; fprintf(stderr, "warning: %s\n", text); }

#define CHECK(cond, ...)                  \
  do {                                    \
    if (!(cond)) {                        \
      ++failures;                         \
      printf("FAIL: " __VA_ARGS__);       \
      printf("  (%s)\n", #cond);          \
    }                                     \
  } while (0)

int main(void) {
  int l = -999, r = -999, e, ro, d, pitch = 999, roll = 999, w0, i;
  unsigned in = 9999, ex = 9999, co = 9999, prox[15], ground[4], light[8];
  float t = -99, h = -99;
  unsigned rr[8] = {15, 0, 0, 15, 0, 0, 15, 0}, gg[8] = {0}, bb[8] = {0, 15, 0, 0, 15, 0, 0, 15};
  BlinkingRate blink[8] = {0, 1, 2, 3, 4, 5, 6, 7};

  initSwarmBot(onError, onWarning);
  CHECK(errors == 0, "initSwarmBot reported errors\n");

  setSpeed(30, 30);
  usleep(1500000);
  getSpeed(&l, &r);
  CHECK(l > 5 && r > 5, "getSpeed %d %d after setSpeed(30, 30)\n", l, r);
  getTrackTorque(&l, &r);
  CHECK(l >= -127 && l <= 127 && r >= -127 && r <= 127, "getTrackTorque %d %d\n", l, r);
  w0 = warnings;
  setSpeed(200, 0); /* clamped: a warning */
  CHECK(warnings > w0, "setSpeed(200, 0) gave no warning\n");
  setSpeed(0, 0);

  setTurretRotation(10);
  usleep(2000000);
  CHECK(abs(getTurretRotation() - 10) <= 3, "getTurretRotation %d, wanted 10\n", getTurretRotation());
  CHECK(abs(getTurretRotationTorque()) <= 127, "getTurretRotationTorque\n");

  w0 = warnings;
  setGripperElevation(100); /* clamped to 90: a warning */
  CHECK(warnings > w0, "setGripperElevation(100) gave no warning\n");
  setGripperElevation(20);
  setGripperAperture(30);
  usleep(2000000);
  e = getGripperElevation();
  CHECK(e >= -90 && e <= 90, "getGripperElevation %d\n", e);
  CHECK(getGripperAperture() >= 0 && getGripperAperture() <= 45, "getGripperAperture %d\n", getGripperAperture());
  CHECK(abs(getGripperElevationTorque()) <= 127, "getGripperElevationTorque\n");
  getGripperOpticalBarrier(&in, &ex, &co);
  CHECK(in <= 700 && ex <= 700 && co <= 700, "getGripperOpticalBarrier %u %u %u\n", in, ex, co);

  setSideArmPos(0, 20, 60);
  setSideArmOpened();
  setSideArmClosed();
  e = ro = d = -9999;
  getSideArmPos(&e, &ro, &d);
  CHECK(d > 0 && d < 200, "getSideArmPos depth %d\n", d);
  getSideArmTorque(&e, &ro, &d);
  CHECK(abs(e) <= 127 && abs(ro) <= 127 && abs(d) <= 127, "getSideArmTorque\n");
  in = ex = co = 9999;
  getSideArmOpticalBarrier(&in, &ex, &co);
  CHECK(in <= 700 && ex <= 700 && co <= 700, "getSideArmOpticalBarrier\n");

  setProximitySamplingRate(SAMPLING_RATE_20);
  getAllProximitySensors(prox);
  for (i = 0; i < 15; ++i) CHECK(prox[i] <= 8191, "proximity %d = %u\n", i, prox[i]);
  CHECK(getProximitySensor(3) <= 8191, "getProximitySensor\n");

  setGroundSamplingRate(SAMPLING_RATE_10);
  getAllGroundSensors(ground);
  for (i = 0; i < 4; ++i) CHECK(ground[i] <= 255, "ground %d = %u\n", i, ground[i]);
  CHECK(getGroundSensor(0) <= 255, "getGroundSensor\n");
  printf("ground %u %u %u %u\n", ground[0], ground[1], ground[2], ground[3]);

  setLightSamplingRate(SAMPLING_RATE_5);
  getAllLightSensors(light);
  for (i = 0; i < 8; ++i) CHECK(light[i] <= 700, "light %d = %u\n", i, light[i]);
  CHECK(getLightSensor(4) <= 700, "getLightSensor\n");
  setLightColor(0, 15, 0, 0, BLINKING_RATE_NO_BLINK);
  setAllLightColor(rr, gg, bb, blink);
  setSameLightColor(0, 15, 0, BLINKING_RATE_1);

  getTemperatureAndHumidityLeft(&t, &h);
  CHECK(t > -40 && t < 123 && h >= 0 && h <= 100, "left climate %.1f %.1f\n", t, h);
  t = h = -99;
  getTemperatureAndHumidityRight(&t, &h);
  CHECK(t > -40 && t < 123 && h >= 0 && h <= 100, "right climate %.1f %.1f\n", t, h);
  setSlopeSamplingRate(SAMPLING_RATE_10);
  getSlope(&pitch, &roll);
  CHECK(abs(pitch) <= 10 && abs(roll) <= 10, "getSlope %d %d on a flat floor\n", pitch, roll);
  CHECK(getBatteryVoltage() > 150, "getBatteryVoltage %u (a fresh 7.2 V pack reads ~184)\n", getBatteryVoltage());

  playMusic("symphony.mp3");
  stopMusic();

  CHECK(errors == 0, "%d errors reported\n", errors);
  shutdownSwarmBot();
  if (failures == 0) printf("SBOT_API_OK\n");
  return failures == 0 ? 0 : 1;
}
