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
#include "example_common.h"

#define BASE_SPEED 30
#define TURN_GAIN 45

int main(void) {
  unsigned ir[15];
  startController("obstacle_avoidance");
  setProximitySamplingRate(SAMPLING_RATE_10);
  turnTurretRound();
  setSameLightColor(0, 15, 0, BLINKING_RATE_NO_BLINK);
  while (running) {
    double turn, front, v;
    getAllProximitySensors(ir);
    irAvoidance(ir, getTurretRotation() * 2.0 * EXAMPLE_PI / 180.0, &turn, &front);
    v = BASE_SPEED * (1.0 - (front > 1 ? 1 : front));
    if (front > 0.9 && fabs(turn) < 0.2) turn = 1.0; /* dead ahead: spin (to the right) */
    setSpeed(clampSpeed(v + TURN_GAIN * turn), clampSpeed(v - TURN_GAIN * turn));
  }
  shutdownSwarmBot();
  return 0;
}
