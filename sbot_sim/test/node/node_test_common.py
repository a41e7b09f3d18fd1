"""Helpers shared by the simulator_node rostests (imported by the test scripts next to it).

Everything waits in wall time: the tests run with /use_sim_time, and a paused simulator never
advances the clock rospy.sleep() would wait for.
"""
import math
import threading
import time

import rospy
from sbot_msgs.srv import SetPose, SetPoseRequest, Step, StepRequest
from std_srvs.srv import Trigger

ROBOTS = ['sbot_0', 'sbot_1', 'sbot_2']  # fixtures/three_robots.yaml
STEP = 0.01                              # [s] world.step of the fixture
SPEED_UNIT = 0.0028                      # [m/s] per s-bot speed unit


class Recorder:
    """Records every message of one topic (with its wall arrival time) and waits for conditions."""

    def __init__(self, topic, msg_type):
        self.topic = topic
        self.msgs = []
        self.wall = []
        self._cond = threading.Condition()
        self.sub = rospy.Subscriber(topic, msg_type, self._callback, queue_size=10000,
                                    tcp_nodelay=True)

    def _callback(self, msg):
        with self._cond:
            self.msgs.append(msg)
            self.wall.append(time.monotonic())
            self._cond.notify_all()

    def wait_connected(self, timeout=10.0):
        """Block until the publisher is connected: a paused simulator publishes only when stepped,
        and whatever it publishes before the connection exists is lost."""
        deadline = time.monotonic() + timeout
        while self.sub.get_num_connections() == 0:
            if time.monotonic() > deadline:
                raise AssertionError('no publisher connected to %s within %.0f s' % (self.topic, timeout))
            time.sleep(0.02)
        return self

    def unbounded_queue(self):
        """For /clock in a node using sim time: rospy's own /clock subscription (queue_size=1)
        shares the connection with ours, and its queue size would make rospy keep only the last
        message of every socket read. Lift it so a test sees every /clock message."""
        self.sub.impl.set_queue_size(-1)
        for conn in list(self.sub.impl.connections):
            if hasattr(conn, 'protocol') and hasattr(conn.protocol, 'queue_size'):
                conn.protocol.queue_size = None
        return self

    def snapshot(self):
        with self._cond:
            return list(self.msgs), list(self.wall)

    def last(self):
        with self._cond:
            return self.msgs[-1] if self.msgs else None

    def wait_for(self, predicate, timeout=10.0, what=None, first=False):
        """Latest (or with `first`, earliest) message satisfying `predicate`; raises AssertionError
        after `timeout` wall seconds."""
        deadline = time.monotonic() + timeout
        with self._cond:
            while True:
                for msg in (self.msgs if first else reversed(self.msgs)):
                    if predicate(msg):
                        return msg
                remaining = deadline - time.monotonic()
                if remaining <= 0 or rospy.is_shutdown():
                    raise AssertionError('no message on %s %s within %.0f s (%d received)' % (
                        self.topic, what or 'matching the condition', timeout, len(self.msgs)))
                self._cond.wait(min(remaining, 0.1))

    def wait_stamp(self, t, timeout=10.0):
        """The earliest message stamped at or after sim time `t`."""
        return self.wait_for(lambda m: m.header.stamp.to_sec() >= t - 1e-6, timeout,
                             'stamped >= %.3f s' % t, first=True)


def wait_services(names, timeout=30.0):
    for name in names:
        rospy.wait_for_service(name, timeout=timeout)


def wait_connected(publisher, timeout=10.0):
    deadline = time.monotonic() + timeout
    while publisher.get_num_connections() == 0:
        if time.monotonic() > deadline:
            raise AssertionError('nobody subscribed to %s within %.0f s' % (publisher.name, timeout))
        time.sleep(0.02)


def publish_and_settle(publisher, msg, settle=0.5):
    """Publish a command to the paused simulator and give it time to be received and handled."""
    wait_connected(publisher)
    publisher.publish(msg)
    time.sleep(settle)


class Sim:
    """Proxies for the /sim/* services."""

    def __init__(self, timeout=30.0):
        wait_services(['/sim/pause', '/sim/unpause', '/sim/reset', '/sim/step', '/sim/set_pose'],
                      timeout)
        self.pause = rospy.ServiceProxy('/sim/pause', Trigger)
        self.unpause = rospy.ServiceProxy('/sim/unpause', Trigger)
        self.reset = rospy.ServiceProxy('/sim/reset', Trigger)
        self._step = rospy.ServiceProxy('/sim/step', Step)
        self._set_pose = rospy.ServiceProxy('/sim/set_pose', SetPose)

    def step(self, steps):
        return self._step(StepRequest(steps=steps))

    def step_ok(self, testcase, steps):
        res = self.step(steps)
        testcase.assertTrue(res.success, 'step(%d) failed: %s' % (steps, res.message))
        return res.time

    def set_pose(self, robot, x, y, z, yaw):
        return self._set_pose(SetPoseRequest(robot=robot, x=x, y=y, z=z, yaw=yaw))


def yaw_of(q):
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def wrap(a):
    return math.atan2(math.sin(a), math.cos(a))


def planar_distance(p, q):
    return math.hypot(q.x - p.x, q.y - p.y)
