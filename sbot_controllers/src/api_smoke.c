/* Calls every function of the standard s-bot API (sbot.h) once against the simulator and checks the
 * answers are plausible. Used by test/sbot_api_functions.test (test_sbot_api_functions.py); run in the
 * namespace of a Detailed s-bot (every module exists). Prints "FAIL: ..." lines and exits 1 on any
 * failure, "SBOT_API_OK" and 0 otherwise. Wall-clock waits: run the simulator at real time.
 *
 * `sbot_api_smoke missing`, in the namespace of a Simple s-bot (no ground or light sensors, no side
 * arm): each getter of a missing module reports one error (once, not per call) and returns at once,
 * as a failed read does (sensor arrays 0, the side arm's outputs untouched); prints
 * "SBOT_API_MISSING_OK". */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
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

static double wallSeconds(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* Getters of modules a Simple s-bot lacks: one error each, at once, as a failed read. */
static int missingModules(void) {
  unsigned ground[4] = {7, 7, 7, 7}, light[8] = {7, 7, 7, 7, 7, 7, 7, 7};
  int e = 7, ro = 7, d = 7, round;
  double t0;
  initSwarmBot(onError, onWarning);
  CHECK(errors == 0, "initSwarmBot reported errors\n");
  t0 = wallSeconds();
  for (round = 0; round < 3; ++round) {
    getAllGroundSensors(ground);
    getAllLightSensors(light);
    getSideArmPos(&e, &ro, &d);
  }
  /* Before: each call waited 2 s for a message that never comes (18 s for these 9 calls). */
  CHECK(wallSeconds() - t0 < 3.0, "9 getters of missing modules took %.1f s\n", wallSeconds() - t0);
  CHECK(errors == 3, "%d errors for ground, light and side arm (expected one each)\n", errors);
  CHECK(ground[0] == 0 && light[0] == 0 && e == 7, "ground %u, light %u, side arm elevation %d: expected 0, 0 and "
        "untouched 7\n", ground[0], light[0], e);
  shutdownSwarmBot();
  if (failures == 0) printf("SBOT_API_MISSING_OK\n");
  return failures == 0 ? 0 : 1;
}

int main(int argc, char **argv) {
  int l = -999, r = -999, e, ro, d, pitch = 999, roll = 999, w0, i;
  unsigned in = 9999, ex = 9999, co = 9999, prox[15], ground[4], light[8];
  float t = -99, h = -99;
  unsigned rr[8] = {15, 0, 0, 15, 0, 0, 15, 0}, gg[8] = {0}, bb[8] = {0, 15, 0, 0, 15, 0, 0, 15};
  BlinkingRate blink[8] = {0, 1, 2, 3, 4, 5, 6, 7};

  if (argc > 1 && strcmp(argv[1], "missing") == 0) return missingModules();
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

  /* Beyond int16: clamped to the positive limits (a bare cast wrapped 40000 to -25536, the opposite). */
  setSideArmPos(40000, 0, 60);
  usleep(1500000);
  e = ro = d = -9999;
  getSideArmPos(&e, &ro, &d);
  CHECK(e > 0, "getSideArmPos elevation %d after setSideArmPos(40000, 0, 60): moved the wrong way\n", e);
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
  /* Out of range: warnings that name the caller's values (the test reads them). */
  w0 = warnings;
  setLightColor(300, 15, 0, 0, BLINKING_RATE_NO_BLINK);
  setProximitySamplingRate(0);
  CHECK(warnings >= w0 + 2, "setLightColor(300, ...) and setProximitySamplingRate(0) gave no warnings\n");
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
