#!/usr/bin/env python3
"""rostest (node_lockstep.test): the simulator's lock-step gate, with this test as sbot_0's
controller (sbot_msgs/ControllerSync on /sim/controller_sync; the protocol is in
sbot_sim/src/node/lockstep_gate.h). ~lockstep_controllers 1, ~lockstep_timeout 2 s, ground truth at
50 Hz (every 0.02 s of simulated time), slope at its default 10 Hz."""
import math
import os
import subprocess
import sys
import time
import unittest

import rospy
import rostest
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock
from sbot_msgs.msg import ControllerSync, LockstepHold, Slope, TrackSpeed

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from node_test_common import Recorder  # noqa: E402


def latest_clock(recorder):
    return recorder.msgs[-1].clock.to_sec() if recorder.msgs else 0.0


class TestLockstep(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node('test_lockstep')
        cls.clock = Recorder('/clock', Clock).wait_connected()
        cls.clock.unbounded_queue()
        cls.truth = Recorder('/sbot_0/ground_truth', Odometry).wait_connected()
        cls.hold = Recorder('/sbot_0/lockstep_hold', LockstepHold).wait_connected()
        cls.sync = rospy.Publisher('/sim/controller_sync', ControllerSync, queue_size=10)
        cls.speed = rospy.Publisher('/sbot_0/cmd_speed', TrackSpeed, queue_size=10)
        for pub in (cls.sync, cls.speed):
            deadline = time.monotonic() + 10
            while pub.get_num_connections() == 0 and time.monotonic() < deadline:
                time.sleep(0.02)

    def send_sync(self, robot, after, speed_commands, channel='ground_truth', new_subscription=False):
        m = ControllerSync(robot=robot, channel=channel, speed_commands=speed_commands,
                           new_subscription=new_subscription)
        m.after = rospy.Time.from_sec(after)
        self.sync.publish(m)

    def clock_after(self, wall):
        """The latest /clock after `wall` seconds of waiting."""
        time.sleep(wall)
        return latest_clock(self.clock)

    def test_the_gate(self):
        # 1. Before its controller announces itself the simulator does not step; a sync naming a
        #    robot that is not there does not count.
        self.assertEqual(self.clock_after(1.0), 0.0, 'stepped before the controller announced itself')
        self.send_sync('sbot_99', 0.0, 0)
        self.send_sync('a/b', 0.0, 0)
        self.assertEqual(self.clock_after(1.0), 0.0, 'a sync for an unknown robot started the run')

        # 2. Announced, waiting for ground truth after 0: it steps until it publishes the next ground
        #    truth (0.02 s), tells us so on lockstep_hold, and holds there.
        self.send_sync('sbot_0', 0.0, 0)
        self.hold.wait_for(lambda m: True, timeout=5.0)
        t1 = self.hold.msgs[-1].stamp.to_sec()
        self.assertAlmostEqual(t1, 0.02, places=6)
        self.assertEqual(list(self.hold.msgs[-1].topics), ['ground_truth'])
        self.assertAlmostEqual(self.hold.msgs[-1].latest[0].to_sec(), t1, places=6)
        self.assertAlmostEqual(self.clock_after(0.5), t1, places=6, msg='did not hold for the controller')

        # 3. A sync saying one cmd_speed was sent before it arrives keeps the hold: the command is
        #    still in flight. Once it arrives the simulator steps to the next ground truth.
        self.send_sync('sbot_0', t1, 1)
        self.assertAlmostEqual(self.clock_after(0.5), t1, places=6, msg='stepped with a command in flight')
        self.speed.publish(TrackSpeed(left=30, right=30))
        self.hold.wait_for(lambda m: m.stamp.to_sec() > t1 + 1e-9, timeout=5.0)
        t2 = self.hold.msgs[-1].stamp.to_sec()
        self.assertAlmostEqual(t2, t1 + 0.02, places=6)
        self.assertAlmostEqual(self.clock_after(0.5), t2, places=6)

        # 4. A controller that stays silent is dropped after ~lockstep_timeout (2 s wall) and the
        #    run goes on.
        self.assertGreater(self.clock_after(3.0), t2 + 0.1, 'a silent controller held the clock for good')

        # 5. A controller about to read a topic for the first time (new_subscription) holds the clock
        #    until the simulator's publisher has seen its own subscription, however long the
        #    connection takes (here: until we subscribe) and whoever else listens already (here a
        #    `rostopic hz`), so its first message is the first sample due after the sync, not one
        #    that depends on the connection's speed. It waits for a sample after t + 0.15 s: a hold
        #    before that is the new subscription's.
        other = subprocess.Popen(['/usr/bin/rostopic', 'hz', '/sbot_0/slope'], stdout=subprocess.DEVNULL,
                                 stderr=subprocess.DEVNULL)
        try:
            time.sleep(1.0)  # connected by now; the simulator publishes slope for it
            after = latest_clock(self.clock) + 0.15
            self.send_sync('sbot_0', after, 1, channel='slope', new_subscription=True)
            t3 = self.clock_after(0.3)
            self.assertLess(t3, after - 0.05, 'ran on to a sample after the sync instead of holding for the subscription')
            self.assertAlmostEqual(self.clock_after(0.6), t3, places=6,
                                   msg='stepped before the publisher knew the new subscriber')
            slope = Recorder('/sbot_0/slope', Slope)
            first = slope.wait_for(lambda m: True, timeout=5.0, first=True).header.stamp.to_sec()
        finally:
            other.terminate()
            other.wait(timeout=10)
        due = math.floor(t3 / 0.1 + 1e-6) * 0.1 + 0.1  # the next 10 Hz sampling instant after t3
        self.assertAlmostEqual(first, due, places=6, msg='first slope sample at %.3f s, held at %.3f s' % (first, t3))


if __name__ == '__main__':
    rostest.rosrun('sbot_sim', 'node_lockstep', TestLockstep)
