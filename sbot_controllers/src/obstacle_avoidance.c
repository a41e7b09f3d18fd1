/* Obstacle avoidance with the 15 infrared proximity sensors: a Braitenberg vehicle ("explorer",
 * vehicle 3b: each side's sensors slow the opposite track down... here: speed up the same-side track,
 * which turns the robot away), written purely against the standard s-bot API (sbot.h). It compiles
 * unchanged for the real s-bot; here it is linked with libsbot_ros and runs against the simulator.
 *
 * Sensor k looks at bearing 40 + 20 k degrees from the turret's front (the three front positions are
 * taken by the gripper); the turret is turned round so theta_k = 40 + 20 k + 180 deg from the
 * direction of travel. Activation a_k = min(1, reading / 40) (reading 50 = 5 cm, 20 = 15 cm).
 *   turn  = sum a_k * w_k * sign(sin theta_k),  w_k = 0.3 + max(0, cos theta_k)   (rear, cos < -0.2, ignored)
 *   front = sum a_k * max(0, cos theta_k)
 *   v = base * (1 - min(1, front)),  left = v + K turn,  right = v - K turn
 * If something is right ahead (front > 0.9) and neither side dominates, spin on the spot.
 */
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>

#include "sbot.h"

#define BASE_SPEED 30
#define TURN_GAIN 45
#define PI 3.14159265358979
#define TURRET_POS 90 /* [2 deg] */

static volatile sig_atomic_t running = 1;

static void onSignal(int s) {
  (void)s;
  running = 0;
}
static void onError(const char *text) { fprintf(stderr, "[obstacle_avoidance] error: %s\n", text); }
static void onWarning(const char *text) { fprintf(stderr, "[obstacle_avoidance] warning: %s\n", text); }

static int clampSpeed(double v) { return v > 127 ? 127 : v < -127 ? -127 : (int)lround(v); }

int main(void) {
  unsigned ir[15];
  int k;
  initSwarmBot(onError, onWarning);
  signal(SIGINT, onSignal);
  signal(SIGTERM, onSignal);
  setProximitySamplingRate(SAMPLING_RATE_10);
  /* Turn the turret round (90 units = 180 deg): the three missing front IR positions (the gripper)
   * then look backwards and the dense part of the ring looks where the robot drives. */
  setTurretRotation(TURRET_POS);
  setGripperElevation(90); /* raised: the gripper does not sweep into walls when the robot spins */
  while (running && abs(getTurretRotation() - TURRET_POS) > 2) {
    setSpeed(0, 0);
    getAllProximitySensors(ir);
  }
  setSameLightColor(0, 15, 0, BLINKING_RATE_NO_BLINK);
  while (running) {
    double turn = 0, front = 0, v;
    const double turret = getTurretRotation() * 2.0 * PI / 180.0;
    getAllProximitySensors(ir);
    for (k = 0; k < 15; ++k) {
      const double theta = (40.0 + 20.0 * k) * PI / 180.0 + turret; /* bearing from the treels' front */
      double a = ir[k] / 40.0;
      if (a > 1) a = 1;
      if (cos(theta) < -0.2) continue; /* rear sensors: nothing to avoid ahead */
      turn += a * (0.3 + (cos(theta) > 0 ? cos(theta) : 0)) * (sin(theta) > 0 ? 1 : -1);
      if (cos(theta) > 0) front += a * cos(theta);
    }
    v = BASE_SPEED * (1.0 - (front > 1 ? 1 : front));
    if (front > 0.9 && fabs(turn) < 0.2) turn = 1.0; /* dead ahead: spin (to the right) */
    setSpeed(clampSpeed(v + TURN_GAIN * turn), clampSpeed(v - TURN_GAIN * turn));
  }
  shutdownSwarmBot();
  return 0;
}
