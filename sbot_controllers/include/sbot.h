/* sbot.h : c interface to the s-bot robot (c) 2003 Stephane Magnenat, LSA 2, EPFL, SwarmBot Project
 *
 * The standard s-bot API exactly as in the Swarmbot3d technical report, Appendix A. In this
 * repository it is implemented over ROS by libsbot_ros (sbot_controllers/src/sbot_ros/) against
 * the swarmbot3d simulator: a controller written for the real s-bot compiles and runs unchanged.
 * See sbot_controllers/README.md for how each function maps to topics and services.
 */
#ifndef __SBOT_H
#define __SBOT_H

/* Set up for C function definitions, even when using C++ */
#ifdef __cplusplus
extern "C" {
#endif

/** Sample sensor 50 times per second (50 Hz) */
#define SAMPLING_RATE_50 1
/** Sample sensor 33 times per second (33 Hz) */
#define SAMPLING_RATE_33 2
/** Sample sensor 20 times per second (20 Hz) */
#define SAMPLING_RATE_20 3
/** Sample sensor 10 times per second (10 Hz) */
#define SAMPLING_RATE_10 4
/** Sample sensor 5 times per second (5 Hz) */
#define SAMPLING_RATE_5 5
/** Sample sensor 2 times per second (2 Hz) */
#define SAMPLING_RATE_2 6
/** Sample sensor one time per second (1 Hz) */
#define SAMPLING_RATE_1 7
/** Sample sensor every two seconds (0.5 Hz) */
#define SAMPLING_RATE_0_5 8

/** The sampling rate. Can take values SAMPLING_RATE_xx */
typedef unsigned SamplingRate;

/** Do not blink leds*/
#define BLINKING_RATE_NO_BLINK 0
/** Blink leds 10 times per second (10 Hz) */
#define BLINKING_RATE_10 1
/** Blink leds 5 times per second (5 Hz) */
#define BLINKING_RATE_5 2
/** Blink leds 3.3 times per second (3.3 Hz) */
#define BLINKING_RATE_3_3 3
/** Blink leds 2.5 times per second (2.5 Hz) */
#define BLINKING_RATE_2_5 4
/** Blink leds 2 times per second (2 Hz) */
#define BLINKING_RATE_2 5
/** Blink leds one time per second (1 Hz) */
#define BLINKING_RATE_1 6
/** Blink leds every two seconds (0.5 Hz) */
#define BLINKING_RATE_0_5 7
/** Blink leds every three seconds (0.33 Hz) */
#define BLINKING_RATE_0_33 8
/** Blink leds every four seconds (0.25 Hz) */
#define BLINKING_RATE_0_25 9
/** Blink leds every five seconds (0.2 Hz) */
#define BLINKING_RATE_0_2 10

/** The blink rate. Can take values BLINKING_RATE_xx */
typedef unsigned BlinkingRate;

/** Initialize the s-bot. Request I2C low level interface and set default values. This function takes
 * two arguments : they are the callback function when an error (critical problem) or a warning
 * (non-critical problem) is encountered.
 * \param errorHandler a pointer to the error function which takes the string describing the error in argument.
 * \param warningHandler a pointer to the warning function which takes the string describing the error in argument. */
void initSwarmBot(void (*errorHandler)(const char *errorString), void (*warningHandler)(const char *warningString));

/** Shutdown the s-bot. This function free the low level interfaces to I2C */
void shutdownSwarmBot(void);

/** Set the speed of the tracks.
 * \param left Left motor speed. [-127;127]
 * \param right Right motor speed. [-127;127] */
void setSpeed(int left, int right);

/** Read the speed of the tracks.
 * \param left Left motor speed pointer. [-127;127]
 * \param right Right motor speed pointer. [-127;127] */
void getSpeed(int *left, int *right);

/** Read the torque of the tracks.
 * \param left Left track torque pointer. [-127;127]
 * \param right Right track torque pointer. [-127;127] */
void getTrackTorque(int *left, int *right);

/** Set the rotation angle of the turret.
 * \param pos Angle of rotation. +/- 0.75 turn. [-100;100] */
void setTurretRotation(int pos);

/** Read the rotation angle of the turret.
 * \return Angle of rotation. +/- 0.75 turn. [-100;100] */
int getTurretRotation(void);

/** Read the rotation torque of the turret.
 * \return pos Torque on turret rotation motor. [-127;127] */
int getTurretRotationTorque(void);

/** Set the elevation of the gripper.
 * \param elevation Angle of elevation in degree. [-90;90] */
void setGripperElevation(int elevation);

/** Read the elevation of the gripper.
 * \return Angle of elevation in degree. [-90;90] */
int getGripperElevation(void);

/** Set the aperture of the gripper.
 * \param aperture Angle of aperture in degree. [0;40] */
void setGripperAperture(int aperture);

/** Read the aperture of the gripper.
 * \return Angle of aperture of the gripper in degree. [0;40] */
int getGripperAperture(void);

/** Read the torque of the gripper.
 * \return Angler of aperture of the gripper in degree. [-127;127] */
int getGripperElevationTorque(void);

/** Read the optical barrier of the gripper.
 * \param internal Internal barrier pointer. 0 is obstructed, ~700 is empty. [0;700]
 * \param external External barrier pointer. 0 is obstructed, ~700 is empty. [0;700]
 * \param combined Combined barrier pointer. 0 is obstructed, ~700 is empty. [0;700] */
void getGripperOpticalBarrier(unsigned *internal, unsigned *external, unsigned *combined);

/** To be measured */
void setSideArmPos(int elevation, int rotation, int depth);

/** To be measured */
void getSideArmPos(int *elevation, int *rotation, int *depth);

/** To be measured */
void getSideArmTorque(int *elevation, int *rotation, int *depth);

/** Fully open the side-arm's gripper. */
void setSideArmOpened(void);

/** Fully close the side-arm's gripper. */
void setSideArmClosed(void);

/** Read the optical barrier of the side arm.
 * \param internal Internal barrier pointer. 0 is obstructed, ~700 is empty.[0;700]
 * \param external External barrier pointer. 0 is obstructed, ~700 is empty.[0;700]
 * \param combined Combined barrier pointer. 0 is obstructed, ~700 is empty.[0;700] */
void getSideArmOpticalBarrier(unsigned *internal, unsigned *external, unsigned *combined);

/** Read the value of a proximity sensor.
 * \param sensor Number of sensor. [0;14]
 * \return Distance to object. 20 is 15 cm, 50 is 5 cm, 1000 is 1 cm, 3700 is 0.5 cm. [0;8191] */
unsigned getProximitySensor(unsigned sensor);

/** Read the value of all proximity sensors.
 * \param sensors Array of distances to objects. For each value, 20 is 15 cm, 50 is 5 cm, 1000 is 1 cm,
 * 3700 is 0.5 cm. [0;8191] */
void getAllProximitySensors(unsigned sensors[15]);

/** Set the sampling rate of the proximity sensors.
 * \param rate Sampling rate. Can take values SAMPLING_RATE_xx. */
void setProximitySamplingRate(SamplingRate rate);

/** Read the value of a ground sensor.
 * \param sensor Number of sensor. [0;3]
 * \return Distance to object. 1 is 6mm, 25 is 2mm, 100 is 1mm. [0;255] */
unsigned getGroundSensor(unsigned sensor);

/** Read the value of all ground sensors.
 * \param sensors Array of distances to objects. For each value, 1 is 6mm, 25 is 2mm, 100 is 1mm. [0;255] */
void getAllGroundSensors(unsigned sensors[4]);

/** Set the sampling rate of the ground sensors.
 * \param rate Sampling rate. Can take values SAMPLING_RATE_xx. */
void setGroundSamplingRate(SamplingRate rate);

/** Read the value of a light sensor
 * \param sensor Number of sensor. [0;7]
 * \return Intensity. 0 is full dark, ~700 is full light.[0;700] */
unsigned getLightSensor(unsigned sensor);

/** Read the value of all light sensors.
 * \return Array of intensities. For each value, 0 is full dark, ~700 is full light. [0;700] */
void getAllLightSensors(unsigned sensors[8]);

/** Set the color of a light.
 * \param light Number of light. [0;7]
 * \param r Red intensity. [0;15]
 * \param g Green intensity. [0;15]
 * \param b Blue intensity. [0;15]
 * \param blink Blinking rate. Can take values BLINKING_RATE_xx. */
void setLightColor(unsigned light, unsigned r, unsigned g, unsigned b, BlinkingRate blink);

/** Set the color of all lights.
 * \param r Array of red intensities. For each value [0:15]
 * \param g Array of green intensities. For each value[0:15]
 * \param b Array of blue intensities. For each value [0:15]
 * \param blink Array of blinking rates. For each value, can take values BLINKING_RATE_xx. */
void setAllLightColor(unsigned r[8], unsigned g[8], unsigned b[8], BlinkingRate blink[8]);

/** Set the same color for all lights.
 * \param r Red intensity. [0;15]
 * \param g Green intensity. [0;15]
 * \param b Blue intensity. [0;15]
 * \param blink Blinking rate. Can take values BLINKING_RATE_xx. */
void setSameLightColor(unsigned r, unsigned g, unsigned b, BlinkingRate blink);

/** Set the sampling rate of the light sensors.
 * \param rate Sampling rate. Can take values SAMPLING_RATE_xx. */
void setLightSamplingRate(SamplingRate rate);

/** Read the left temperature and humditiy sensor.
 * \param temperature Temperature in degree pointer. [-40;123]
 * \param humidity Relative humidity in % pointer. [0;100] */
void getTemperatureAndHumidityLeft(float *temperature, float *humidity);

/** Read the right temperature and humditiy sensor.
 * \param temperature Temperature in degree pointer. [-40;123]
 * \param humidity Relative humidity in % pointer. [0;100] */
void getTemperatureAndHumidityRight(float *temperature, float *humidity);

/** Read the slope pitch & roll angles of the robot
 * \param pitch Pitch in degree pointer. [-180;180]
 * \param roll Roll in degree pointer. [-180;180] */
void getSlope(int *pitch, int *roll);

/** Set the sampling rate of the slope sensor.
 * \param rate Sampling rate. Can take values SAMPLING_RATE_xx. */
void setSlopeSamplingRate(SamplingRate rate);

/** Read the current battery voltage
 * \return Return the current battery voltage 0-10V [0;255] */
unsigned getBatteryVoltage(void);

/* TODO : - v4l abstraction for camera */

/** TO BE DEFINED */
void playMusic(const char *filename);

/** TO BE DEFINED */
void stopMusic(void);

/* Ends C function definitions when using C++ */
#ifdef __cplusplus
}
#endif

#endif
