// The simulator node's sensor publishers, one line each, in the order they publish within a step.
// Each names a file in this folder that defines `const SensorPublisherType& <name>Publisher()`.
// Included by table.cpp only, with SBOT_SENSOR_PUBLISHER defined.
SBOT_SENSOR_PUBLISHER(proximity)
SBOT_SENSOR_PUBLISHER(ground)
SBOT_SENSOR_PUBLISHER(light)
SBOT_SENSOR_PUBLISHER(slope)
SBOT_SENSOR_PUBLISHER(imu)
SBOT_SENSOR_PUBLISHER(sound)
SBOT_SENSOR_PUBLISHER(fakeCamera)
SBOT_SENSOR_PUBLISHER(gripper)
SBOT_SENSOR_PUBLISHER(sideArm)
SBOT_SENSOR_PUBLISHER(battery)
SBOT_SENSOR_PUBLISHER(climate)
SBOT_SENSOR_PUBLISHER(leds)
SBOT_SENSOR_PUBLISHER(markers)
SBOT_SENSOR_PUBLISHER(rawCamera)
