/* Two s-bots connected by the front gripper go backwards up a step (seed 4.1.3, Figure 4.3),
 * written purely against the standard s-bot API (sbot.h). One process per robot:
 *
 *   sbot_step_climbing holder   the robot nearest the step. It grips the robot in front of it (opens
 *                               its jaws, creeps forward until the optical barrier sees the other
 *                               robot, closes), then reverses. When it senses the step (its tracks
 *                               load up or its body tilts: the rear treels touch the step face) it
 *                               raises its gripper arm and keeps reversing: braced on the held robot's
 *                               weight it tips forward about its own front wheels and its rear rises
 *                               onto the step (lowering the arm would have to lift its front about
 *                               its rear, which the arm's torque cannot). It then
 *                               levels the arm, reverses until the held robot is at the step (timed
 *                               from the distance between them), raises the arm to lift the held
 *                               robot's rear and pulls it up, and stops on the plateau.
 *   sbot_step_climbing held     the gripped robot. It reverses; when its tracks load up (it is
 *                               pushing a holder that has stopped at the step) it stands still for
 *                               the holder's lifting time, a fulcrum for the arm, then reverses again;
 *                               once it has climbed it stops when its tracks stay loaded (it pushes
 *                               the holder, which has stopped on the plateau).
 *   sbot_step_climbing single   one robot alone reverses into the step; the seed's single s-bot
 *                               topples backwards on 32 mm. It stops its tracks when it tilts beyond
 *                               45 deg, or once it has climbed and is level again.
 *
 * Time is counted in inclinometer samples (setSlopeSamplingRate(SAMPLING_RATE_10): getSlope returns
 * a fresh sample every 0.1 s of simulated time), so the script runs in simulated time whatever the
 * simulator's real-time factor. The two processes do not talk: each one senses the same event (the
 * holder stopping at the step) through its own tracks. LEDs show the phase (blue approaching, yellow
 * lifting, green done, red gave up or toppled).
 */
#include <string.h>

#include "example_common.h"

#define REVERSE (-15)       /* [track units] about 4.2 cm/s backwards */
#define CREEP 5             /* [track units] forward while gripping */
#define SAMPLE_S 0.1        /* [s] one inclinometer sample at SAMPLING_RATE_10 */
#define LOAD_TORQUE 15      /* [torque units] mean track torque (backwards) that means "pushing" */
#define LOAD_SAMPLES 2      /* consecutive loaded samples to call it an event */
#define STEP_TILT 3         /* [deg] tilt change that means the rear treels are on the step face */
#define LIFT_S 6.0          /* [s] arm raised while the holder climbs (the held robot stands) */
#define LEVEL_S 3.0         /* [s] arm level: reversing until the held robot reaches the step */
#define RAISE_S 2.5         /* [s] arm up: lifting the held robot's rear onto the step */
#define ARM_LIFT 20         /* [deg] lifts the holder's own rear */
#define ARM_UP 50           /* [deg] */
#define GRIP_BARRIER 60     /* optical barrier (0..700) at which the other robot is between the jaws */
#define LEVEL_TILT 4        /* [deg] "level" */
#define CLIMB_TILT 8        /* [deg] tilt that shows the robot is climbing */
#define DONE_LEVEL_S 2.0    /* [s] level after climbing = on the plateau */
#define HELD_CLIMB_TILT 15  /* [deg] the held robot's climb (it tilts ~20 deg; ~10 while the holder climbs) */
#define PUSH_TORQUE 12      /* [torque units] smoothed load of pushing the stopped holder (~20) */
#define PUSH_S 1.5          /* [s] ... held that long */
#define TOPPLE_TILT 45      /* [deg] */
#define START_S 8.0         /* [s] both robots start reversing together (gripping takes ~5.5 s) */
#define TIMEOUT_S 60.0      /* [s] give up */


static void leds(unsigned r, unsigned g, unsigned b) { setSameLightColor(r, g, b, BLINKING_RATE_NO_BLINK); }

/* End of the script: tracks stopped, LEDs green (done) or red (gave up, toppled). */
static void finish(int done) {
  setSpeed(0, 0);
  if (done) leds(0, 15, 0);
  else leds(15, 0, 0);
}

/* One sample of the robot's own state; blocks until the inclinometer's next sample (0.1 s). */
typedef struct {
  double t;     /* [s] simulated since start */
  int pitch;    /* [deg] */
  double load;  /* [torque units] mean of the two tracks, positive = pushing backwards */
} Sample;

static const char *role_name = "";
static int phase_now = 0;

static Sample next(Sample prev) {
  Sample s;
  int roll, left = 0, right = 0;
  getSlope(&s.pitch, &roll);
  getTrackTorque(&left, &right);
  s.t = prev.t + SAMPLE_S;
  s.load = -(left + right) / 2.0;
  if ((int)lround(s.t / SAMPLE_S) % 10 == 0)
    printf("[step_climbing] %s t %.1f phase %d pitch %d load %.0f\n", role_name, s.t, phase_now, s.pitch, s.load);
  return s;
}

/* Counts consecutive samples that satisfy a condition. */
static int streak(int *count, int condition) {
  *count = condition ? *count + 1 : 0;
  return *count >= LOAD_SAMPLES;
}

/* Levels out after a climb: true once the robot has tilted beyond CLIMB_TILT and then stayed within
 * LEVEL_TILT of its starting pitch for `level_s` seconds. */
typedef struct {
  int climbed;
  double level_since;
} PlateauDetector;

static int onPlateau(PlateauDetector *d, Sample s, int pitch0, double level_s) {
  const int tilt = abs(s.pitch - pitch0);
  if (tilt > CLIMB_TILT) {
    d->climbed = 1;
    d->level_since = -1;
  } else if (d->climbed && tilt <= LEVEL_TILT) {
    if (d->level_since < 0) d->level_since = s.t;
    return s.t - d->level_since >= level_s;
  } else {
    d->level_since = -1;
  }
  return 0;
}

/* Opens the jaws, creeps forward until the other robot is between them, closes. */
static int grip(Sample *s) {
  unsigned internal, external, combined;
  const double start = s->t;
  setGripperElevation(0);
  setGripperAperture(45);
  while (running && s->t - start < 1.0) *s = next(*s); /* jaws open */
  for (;;) {
    if (!running || s->t - start > 15.0) return 0;
    getGripperOpticalBarrier(&internal, &external, &combined);
    if (combined < GRIP_BARRIER) break;
    setSpeed(CREEP, CREEP);
    *s = next(*s);
  }
  setSpeed(0, 0);
  setGripperAperture(0);
  while (running && s->t - start < 20.0 && getGripperAperture() > 10) *s = next(*s);
  /* let the jaws settle on the ring */
  {
    const double closed = s->t;
    while (running && s->t - closed < 1.0) *s = next(*s);
  }
  return 1;
}

/* The holder's arm after it senses the step: raised a little (braced on the held robot, its own rear
 * rises onto the step), level (reversing until the held robot is at the step), up (lifting the held
 * robot's rear onto the step). */
typedef struct {
  int elevation;   /* [deg] */
  double seconds;  /* [s] simulated */
} ArmStep;
static const ArmStep kArmSchedule[] = {{ARM_LIFT, LIFT_S}, {0, LEVEL_S}, {ARM_UP, RAISE_S}};
#define ARM_STEPS ((int)(sizeof(kArmSchedule) / sizeof(kArmSchedule[0])))

static void holder(void) {
  /* phase: -1 reversing to the step, 0..ARM_STEPS-1 the arm schedule, ARM_STEPS pulling */
  int phase = -1;
  Sample s = {0, 0, 0};
  PlateauDetector plateau = {0, -1};
  int pitch0, loaded = 0;
  double since = 0;
  leds(0, 0, 15);
  s = next(s);
  if (!grip(&s)) {
    fprintf(stderr, "[step_climbing] holder: the other robot never came between the jaws\n");
    leds(15, 0, 0);
    return;
  }
  pitch0 = s.pitch;
  while (running && s.t < START_S) s = next(s);
  since = s.t;
  while (running && s.t <= TIMEOUT_S) {
    int done;
    setSpeed(REVERSE, REVERSE);
    s = next(s);
    phase_now = phase + 1;
    done = phase >= 0 && onPlateau(&plateau, s, pitch0, DONE_LEVEL_S);
    if (phase < 0) {
      setGripperElevation(0);
      /* (the first second of reversing loads the tracks too: accelerating the pair) */
      if (s.t - since > 1.0 &&
          streak(&loaded, s.load > LOAD_TORQUE || abs(s.pitch - pitch0) >= STEP_TILT)) {
        printf("[step_climbing] holder: step sensed at t %.1f s (load %.0f, pitch %d)\n", s.t, s.load, s.pitch);
        phase = 0;
        since = s.t;
        leds(15, 15, 0);
      }
    } else if (phase < ARM_STEPS) {
      setGripperElevation(kArmSchedule[phase].elevation);
      if (s.t - since >= kArmSchedule[phase].seconds) {
        ++phase;
        since = s.t;
      }
    } else {
      setGripperElevation(0);
      if (done) {
        printf("[step_climbing] holder: on the plateau at t %.1f s\n", s.t);
        finish(1);
        return;
      }
    }
  }
  finish(0);
}

static void held(void) {
  enum { REVERSING, BRACING, FOLLOWING } phase = REVERSING;
  Sample s = {0, 0, 0};
  int pitch0, loaded = 0, climbed = 0;
  double since = 0, load = 0, pushing_since = 0;
  leds(0, 0, 15);
  s = next(s);
  pitch0 = s.pitch;
  /* the holder grips meanwhile (jaws open, creep, close, settle) */
  while (running && s.t < START_S) {
    setSpeed(0, 0);
    s = next(s);
  }
  while (running && s.t < TIMEOUT_S) {
    phase_now = phase;
    switch (phase) {
      case REVERSING:
        setSpeed(REVERSE, REVERSE);
        if (s.t > START_S + 1.0 && streak(&loaded, s.load > LOAD_TORQUE)) {
          printf("[step_climbing] held: holder stopped at t %.1f s: bracing\n", s.t);
          phase = BRACING;
          since = s.t;
          leds(15, 15, 0);
        }
        break;
      case BRACING:
        setSpeed(0, 0);
        if (s.t - since >= LIFT_S) phase = FOLLOWING;
        break;
      case FOLLOWING:
        setSpeed(REVERSE, REVERSE);
        /* Over the step (it tilted like a climb), the holder stops first and this robot pushes it:
         * the tracks stay loaded (the climb loads them only for moments). */
        load = 0.7 * load + 0.3 * s.load;
        if (!climbed && abs(s.pitch - pitch0) > HELD_CLIMB_TILT) climbed = 1;
        if (!climbed || load <= PUSH_TORQUE) {
          pushing_since = s.t;
        } else if (s.t - pushing_since >= PUSH_S) {
          printf("[step_climbing] held: over the step, pushing the stopped holder at t %.1f s: stop\n", s.t);
          finish(1);
          return;
        }
        break;
    }
    s = next(s);
  }
  finish(0);
}

static void single(void) {
  Sample s = {0, 0, 0};
  PlateauDetector plateau = {0, -1};
  int pitch0;
  leds(0, 0, 15);
  s = next(s);
  pitch0 = s.pitch;
  while (running && s.t < TIMEOUT_S) {
    setSpeed(REVERSE, REVERSE);
    s = next(s);
    if (abs(s.pitch - pitch0) > TOPPLE_TILT) {
      printf("[step_climbing] single: toppled (pitch %d deg) at t %.1f s\n", s.pitch, s.t);
      finish(0);
      return;
    }
    if (onPlateau(&plateau, s, pitch0, DONE_LEVEL_S)) {
      printf("[step_climbing] single: on the plateau at t %.1f s\n", s.t);
      finish(1);
      return;
    }
  }
  finish(0);
}

int main(int argc, char **argv) {
  const char *role = argc > 1 ? argv[1] : "";
  if (strcmp(role, "holder") != 0 && strcmp(role, "held") != 0 && strcmp(role, "single") != 0) {
    fprintf(stderr, "usage: sbot_step_climbing holder|held|single   (got '%s')\n", role);
    return 2;
  }
  role_name = role;
  setvbuf(stdout, NULL, _IOLBF, 0);
  startController("step_climbing");
  setSlopeSamplingRate(SAMPLING_RATE_10);
  if (strcmp(role, "holder") == 0) holder();
  else if (strcmp(role, "held") == 0) held();
  else single();
  /* keep the process (and the robot's last command) alive until roslaunch stops it */
  while (running) {
    Sample s = {0, 0, 0};
    next(s);
  }
  shutdownSwarmBot();
  return 0;
}
