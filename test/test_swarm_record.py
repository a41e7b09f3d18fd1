#!/usr/bin/env python3
"""rostest (swarm_record.test): the demo's recording works end to end.

Runs `roslaunch swarmbot3d swarm.launch record:=true` (against this rostest's master) with ~robots
robots for ~duration simulated seconds into a temporary bag, waits for it to finish, then checks
with the rosbag Python API that /clock, /tf and every robot's ground_truth, joint_states and
cmd_speed are there with a plausible number of messages, and that src/bag_summary.py exits 0 on the
bag and 1 on copies lacking topics (one without /tf, one with /clock only).
"""
import os
import shutil
import subprocess
import sys
import tempfile
import time
import unittest

import rosbag
import rospkg
import rospy
import rostest

PKG = 'swarmbot3d'


class SwarmRecordTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node('test_swarm_record')
        cls.robots = int(rospy.get_param('~robots', 5))
        cls.duration = float(rospy.get_param('~duration', 5.0))
        cls.publish_rate = float(rospy.get_param('~publish_rate', 50.0))
        cls.launch_timeout = float(rospy.get_param('~launch_timeout', 60.0))
        cls.real_time_factor = float(rospy.get_param('~real_time_factor', 1.0))
        cls.pkg_dir = rospkg.RosPack().get_path(PKG)
        cls.tmp = tempfile.mkdtemp(prefix='swarm_record_')
        cls.bag_path = os.path.join(cls.tmp, 'run.bag')
        cmd = ['roslaunch', os.path.join(cls.pkg_dir, 'launch', 'swarm.launch'),
               'robots:=%d' % cls.robots, 'duration:=%g' % cls.duration, 'record:=true',
               'bag:=%s' % cls.bag_path, 'headless:=true', 'controller:=true',
               'real_time_factor:=%g' % cls.real_time_factor,
               'publish_rate:=%g' % cls.publish_rate]
        cls.launch_log = os.path.join(cls.tmp, 'roslaunch.log')
        start = time.time()
        with open(cls.launch_log, 'w') as log:
            proc = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT)
            try:
                cls.launch_rc = proc.wait(timeout=cls.launch_timeout)
            except subprocess.TimeoutExpired:
                proc.terminate()
                cls.launch_rc = proc.wait(timeout=20)
                cls.launch_rc = 'timeout'
        cls.launch_wall = time.time() - start
        rospy.loginfo('test_swarm_record: roslaunch finished (%s) after %.1f s wall', cls.launch_rc, cls.launch_wall)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def launch_tail(self):
        try:
            with open(self.launch_log) as f:
                return ''.join(f.readlines()[-25:])
        except OSError:
            return '(no log)'

    def topics(self):
        self.assertTrue(os.path.isfile(self.bag_path),
                        'no bag written (roslaunch exit %s); log tail:\n%s' % (self.launch_rc, self.launch_tail()))
        with rosbag.Bag(self.bag_path) as bag:
            info = bag.get_type_and_topic_info()
        return {name: t.message_count for name, t in info.topics.items()}

    def bag_summary(self, path):
        script = os.path.join(self.pkg_dir, 'src', 'bag_summary.py')
        return subprocess.run([sys.executable, script, path], stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, universal_newlines=True, timeout=60)

    def test_0_launch_finished(self):
        self.assertEqual(self.launch_rc, 0, 'roslaunch did not end cleanly within %.0f s; log tail:\n%s'
                         % (self.launch_timeout, self.launch_tail()))

    def test_1_expected_topics(self):
        counts = self.topics()
        expected = ['/clock', '/tf'] + ['/sbot_%d/%s' % (i, t) for i in range(self.robots)
                                        for t in ('ground_truth', 'joint_states', 'cmd_speed')]
        missing = [t for t in expected if counts.get(t, 0) == 0]
        self.assertEqual(missing, [], 'topics missing or empty in the bag: %s (present: %s)' % (missing, sorted(counts)))

    def test_2_plausible_counts(self):
        counts = self.topics()
        # State topics: publish_rate over the whole run, from its first step (start_when_ready waits
        # for the recorder's connections before it unpauses; waiting for their registration only,
        # the demo can lose all of six robots' ground truth), never more than the run
        # could produce. Clock: every 10 ms step. Controllers: 10 Hz.
        state = self.duration * self.publish_rate
        bounds = {'/clock': (0.5 * self.duration * 100, 1.1 * self.duration * 100 + 5)}
        for i in range(self.robots):
            for t in ('ground_truth', 'joint_states', 'track_state', 'turret/state'):
                bounds['/sbot_%d/%s' % (i, t)] = (0.95 * state, 1.1 * state + 5)
            bounds['/sbot_%d/cmd_speed' % i] = (0.3 * self.duration * 10, 1.5 * self.duration * 10 + 5)
        # /tf: the simulator (one message per publish) and robot_state_publishers (10 Hz each).
        bounds['/tf'] = (0.5 * state, 1.5 * (state + self.robots * self.duration * 10) + 5)
        wrong = ['%s: %d not in [%.0f, %.0f]' % (t, counts.get(t, 0), lo, hi)
                 for t, (lo, hi) in sorted(bounds.items()) if not lo <= counts.get(t, 0) <= hi]
        self.assertEqual(wrong, [], 'implausible message counts: %s' % wrong)

    def test_3_bag_summary_accepts_the_bag(self):
        self.topics()
        result = self.bag_summary(self.bag_path)
        self.assertEqual(result.returncode, 0, 'bag_summary.py failed on a complete bag:\n%s' % result.stdout)
        self.assertIn('robots: %d' % self.robots, result.stdout)

    def test_4_bag_summary_rejects_incomplete_bags(self):
        self.topics()
        without_tf = os.path.join(self.tmp, 'without_tf.bag')
        clock_only = os.path.join(self.tmp, 'clock_only.bag')
        with rosbag.Bag(self.bag_path) as src, rosbag.Bag(without_tf, 'w') as a, rosbag.Bag(clock_only, 'w') as b:
            for topic, msg, t in src.read_messages(raw=True):
                if topic != '/tf':
                    a.write(topic, msg, t, raw=True)
                if topic == '/clock':
                    b.write(topic, msg, t, raw=True)
        with rosbag.Bag(without_tf) as check:
            self.assertNotIn('/tf', check.get_type_and_topic_info().topics)
        for path in (without_tf, clock_only):
            result = self.bag_summary(path)
            self.assertEqual(result.returncode, 1, 'bag_summary.py should exit 1 on %s, got %s:\n%s'
                             % (os.path.basename(path), result.returncode, result.stdout))

    def test_5_bag_summary_names_a_cut_off_bag_and_a_non_bag(self):
        # rosbag's own words ("Unindexed bag", a utf-8 codec error) did not say what to do or what it was.
        self.topics()
        cut = os.path.join(self.tmp, 'cut.bag')
        garbage = os.path.join(self.tmp, 'garbage.bag')
        with open(self.bag_path, 'rb') as f:
            data = f.read()
        with open(cut, 'wb') as f:
            f.write(data[:len(data) // 2])
        with open(garbage, 'wb') as f:
            f.write(bytes(range(128, 256)) * 32)
        for path, says in ((cut, 'rosbag reindex'), (garbage, 'not a rosbag')):
            result = self.bag_summary(path)
            self.assertEqual(result.returncode, 1, result.stdout)
            self.assertIn(says, result.stdout)


if __name__ == '__main__':
    rostest.rosrun(PKG, 'test_swarm_record', SwarmRecordTest)
