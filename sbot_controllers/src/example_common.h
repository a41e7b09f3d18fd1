/* What the example controllers share, in plain C on sbot.h alone (so they still compile unchanged
 * for the real s-bot): start-up with error/warning reporting and a clean stop on SIGINT/SIGTERM,
 * speed clamping, the turret turned round, and the infrared ring's avoidance vector.
 * Header-only (static functions): each controller is one translation unit. */
#ifndef SBOT_EXAMPLE_COMMON_H
#define SBOT_EXAMPLE_COMMON_H

#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>

#include "sbot.h"

#define EXAMPLE_PI 3.14159265358979
#define TURRET_ROUND 90 /* [2 deg] the turret turned round: 180 deg */

static volatile sig_atomic_t running = 1; /* cleared by SIGINT / SIGTERM */
static const char *controller_name = "controller";

static void onSignal(int s) {
  (void)s;
  running = 0;
}
static void onError(const char *text) { fprintf(stderr, "[%s] error: %s\n", controller_name, text); }
static void onWarning(const char *text) { fprintf(stderr, "[%s] warning: %s\n", controller_name, text); }

/* initSwarmBot with messages prefixed by `name`; SIGINT / SIGTERM end the main loop (`running`). */
static inline void startController(const char *name) {
  controller_name = name;
  initSwarmBot(onError, onWarning);
  signal(SIGINT, onSignal);
  signal(SIGTERM, onSignal);
}

static inline int clampSpeed(double v) { return v > 127 ? 127 : v < -127 ? -127 : (int)lround(v); }

/* Turn the turret round (180 deg) and raise the gripper, standing still until the turret is there:
 * the three missing front IR positions (the gripper) then look backwards, the dense part of the
 * ring looks where the robot drives, and the gripper does not sweep into walls when it spins. */
static inline void turnTurretRound(void) {
  unsigned ir[15];
  setTurretRotation(TURRET_ROUND);
  setGripperElevation(90);
  while (running && abs(getTurretRotation() - TURRET_ROUND) > 2) {
    setSpeed(0, 0);
    getAllProximitySensors(ir); /* a blocking read paces the loop at the sampling rate */
  }
}

/* The IR ring's avoidance vector. Sensor k looks at bearing 40 + 20 k deg from the turret's front,
 * theta_k = that + `turret` [rad] from the direction of travel; activation a_k = min(1, reading / 40)
 * (reading 50 = 5 cm, 20 = 15 cm). Rear sensors (cos theta < -0.2) are ignored.
 *   turn  = sum a_k (0.3 + max(0, cos theta_k)) sign(sin theta_k)   (> 0: obstacle on the left)
 *   front = sum a_k max(0, cos theta_k)                              (> 0.9: something right ahead) */
static inline void irAvoidance(const unsigned ir[15], double turret, double *turn, double *front) {
  int k;
  *turn = 0;
  *front = 0;
  for (k = 0; k < 15; ++k) {
    const double theta = (40.0 + 20.0 * k) * EXAMPLE_PI / 180.0 + turret;
    double a = ir[k] / 40.0;
    if (a > 1) a = 1;
    if (cos(theta) < -0.2) continue;
    *turn += a * (0.3 + (cos(theta) > 0 ? cos(theta) : 0)) * (sin(theta) > 0 ? 1 : -1);
    if (cos(theta) > 0) *front += a * cos(theta);
  }
}

#endif
