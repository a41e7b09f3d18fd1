/* Phototaxis with the 8 light sensors of the light ring, plus infrared obstacle avoidance, written
 * purely against the standard s-bot API (sbot.h).
 *
 * Light sensor k looks at bearing 45 k degrees (counter-clockwise from the front). The light
 * direction is the bearing of the vector sum  sum L_k (cos theta_k, sin theta_k);  the robot turns
 * toward it (proportional steering; on the spot when the light is behind) and slows down when the
 * infrared sensors see an obstacle ahead, turning away from it as in obstacle_avoidance.c.
 */
#include "example_common.h"

#define BASE_SPEED 40
#define STEER_GAIN 35
#define AVOID_GAIN 50

int main(void) {
  unsigned light[8], ir[15];
  int k;
  startController("phototaxis");
  setLightSamplingRate(SAMPLING_RATE_10);
  setProximitySamplingRate(SAMPLING_RATE_10);
  turnTurretRound();
  setSameLightColor(15, 15, 0, BLINKING_RATE_NO_BLINK);
  while (running) {
    double lx = 0, ly = 0, phi, v, steer, turn, front;
    const double turret = getTurretRotation() * 2.0 * EXAMPLE_PI / 180.0;
    getAllLightSensors(light);
    getAllProximitySensors(ir);
    for (k = 0; k < 8; ++k) {
      const double theta = 45.0 * k * EXAMPLE_PI / 180.0 + turret;
      lx += light[k] * cos(theta);
      ly += light[k] * sin(theta);
    }
    irAvoidance(ir, turret, &turn, &front);
    phi = (lx == 0 && ly == 0) ? 0 : atan2(ly, lx); /* + = light on the left */
    if (fabs(phi) > EXAMPLE_PI / 2) {
      v = 0;
      steer = phi > 0 ? STEER_GAIN : -STEER_GAIN;
    } else {
      v = BASE_SPEED;
      steer = STEER_GAIN * phi / (EXAMPLE_PI / 2);
    }
    v *= 1.0 - (front > 1 ? 1 : front);
    /* steer > 0 turns left (right track faster); obstacle on the left (turn > 0) turns right */
    setSpeed(clampSpeed(v - steer + AVOID_GAIN * turn), clampSpeed(v + steer - AVOID_GAIN * turn));
  }
  shutdownSwarmBot();
  return 0;
}
