/* Phototaxis with the 8 light sensors of the light ring, plus infrared obstacle avoidance, written
 * purely against the standard s-bot API (sbot.h).
 *
 * Light sensor k looks at bearing 45 k degrees (counter-clockwise from the front). The light
 * direction is the bearing of the vector sum  sum L_k (cos theta_k, sin theta_k);  the robot turns
 * toward it (proportional steering; on the spot when the light is behind) and slows down when the
 * infrared sensors see an obstacle ahead, turning away from it as in obstacle_avoidance.c.
 */
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>

#include "sbot.h"

#define BASE_SPEED 40
#define STEER_GAIN 35
#define AVOID_GAIN 50
#define PI 3.14159265358979
#define TURRET_POS 90 /* [2 deg] */

static volatile sig_atomic_t running = 1;

static void onSignal(int s) {
  (void)s;
  running = 0;
}
static void onError(const char *text) { fprintf(stderr, "[phototaxis] error: %s\n", text); }
static void onWarning(const char *text) { fprintf(stderr, "[phototaxis] warning: %s\n", text); }

static int clampSpeed(double v) { return v > 127 ? 127 : v < -127 ? -127 : (int)lround(v); }

int main(void) {
  unsigned light[8], ir[15];
  int k;
  initSwarmBot(onError, onWarning);
  signal(SIGINT, onSignal);
  signal(SIGTERM, onSignal);
  setLightSamplingRate(SAMPLING_RATE_10);
  setProximitySamplingRate(SAMPLING_RATE_10);
  /* Turn the turret round (90 units = 180 deg): the three missing front IR positions (the gripper)
   * then look backwards and the dense part of the ring looks where the robot drives. */
  setTurretRotation(TURRET_POS);
  setGripperElevation(90); /* raised: the gripper does not sweep into walls when the robot spins */
  while (running && abs(getTurretRotation() - TURRET_POS) > 2) {
    setSpeed(0, 0);
    getAllProximitySensors(ir);
  }
  setSameLightColor(15, 15, 0, BLINKING_RATE_NO_BLINK);
  while (running) {
    double lx = 0, ly = 0, phi, v, steer, turn = 0, front = 0;
    const double turret = getTurretRotation() * 2.0 * PI / 180.0;
    getAllLightSensors(light);
    getAllProximitySensors(ir);
    for (k = 0; k < 8; ++k) {
      const double theta = 45.0 * k * PI / 180.0 + turret;
      lx += light[k] * cos(theta);
      ly += light[k] * sin(theta);
    }
    for (k = 0; k < 15; ++k) {
      const double theta = (40.0 + 20.0 * k) * PI / 180.0 + turret;
      double a = ir[k] / 40.0;
      if (a > 1) a = 1;
      if (cos(theta) < -0.2) continue;
      turn += a * (0.3 + (cos(theta) > 0 ? cos(theta) : 0)) * (sin(theta) > 0 ? 1 : -1);
      if (cos(theta) > 0) front += a * cos(theta);
    }
    phi = (lx == 0 && ly == 0) ? 0 : atan2(ly, lx); /* + = light on the left */
    if (fabs(phi) > PI / 2) {
      v = 0;
      steer = phi > 0 ? STEER_GAIN : -STEER_GAIN;
    } else {
      v = BASE_SPEED;
      steer = STEER_GAIN * phi / (PI / 2);
    }
    v *= 1.0 - (front > 1 ? 1 : front);
    /* steer > 0 turns left (right track faster); obstacle on the left (turn > 0) turns right */
    setSpeed(clampSpeed(v - steer + AVOID_GAIN * turn), clampSpeed(v + steer - AVOID_GAIN * turn));
  }
  shutdownSwarmBot();
  return 0;
}
