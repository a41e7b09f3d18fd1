#!/usr/bin/env python3
"""rostest (node_malformed_scenario.test): the simulator refuses bad input at start-up. It is run as a
subprocess against the rostest master; it must exit non-zero, quickly, with a message on stderr that
names the offending file and field."""
import os
import subprocess
import unittest

import rospkg
import rospy
import rostest
from roslib.packages import find_node

FIXTURES = os.path.join(os.path.dirname(os.path.abspath(__file__)), 'fixtures')


def simulator_binary():
    paths = find_node('sbot_sim', 'simulator_node', rospack=rospkg.RosPack())
    if not paths:
        raise AssertionError('simulator_node not found (is sbot_sim built?)')
    return paths[0]


class TestMalformedScenario(unittest.TestCase):
    counter = 0

    @classmethod
    def setUpClass(cls):
        rospy.init_node('test_malformed_scenario')
        cls.binary = simulator_binary()

    def run_node(self, *params):
        TestMalformedScenario.counter += 1
        name = 'bad_simulator_%d' % TestMalformedScenario.counter
        cmd = [self.binary, '__name:=' + name] + list(params)
        try:
            proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=30,
                                  universal_newlines=True)
        except subprocess.TimeoutExpired:
            self.fail('%s did not exit within 30 s' % ' '.join(cmd))
        return proc

    def assertRefused(self, proc, *needles):
        self.assertNotEqual(proc.returncode, 0, 'the simulator accepted it; stderr:\n' + proc.stderr)
        self.assertGreater(proc.returncode, 0, 'the simulator crashed (signal %d); stderr:\n%s'
                           % (-proc.returncode, proc.stderr))
        self.assertIn('FATAL', proc.stderr)
        for needle in needles:
            self.assertIn(needle, proc.stderr, 'stderr does not name %r:\n%s' % (needle, proc.stderr))

    def fixture(self, name):
        return os.path.join(FIXTURES, name)

    def test_negative_step(self):
        path = self.fixture('malformed_step.yaml')
        self.assertRefused(self.run_node('_scenario:=' + path), path, 'world.step')

    def test_unknown_level(self):
        path = self.fixture('malformed_level.yaml')
        self.assertRefused(self.run_node('_scenario:=' + path), path, 'robots[1].level', 'hyperdetailed')

    def test_non_numeric_pose(self):
        path = self.fixture('malformed_pose.yaml')
        self.assertRefused(self.run_node('_scenario:=' + path), path, 'robots[0].pose.x')

    def test_missing_file(self):
        path = self.fixture('no_such_scenario.yaml')
        self.assertRefused(self.run_node('_scenario:=' + path), path)

    def test_missing_scenario_parameter(self):
        self.assertRefused(self.run_node(), '~scenario')

    def test_invalid_publish_rate(self):
        path = self.fixture('three_robots.yaml')
        self.assertRefused(self.run_node('_scenario:=' + path, '_publish_rate:=-5.0'), '~publish_rate')

    def test_unknown_level_override(self):
        path = self.fixture('three_robots.yaml')
        self.assertRefused(self.run_node('_scenario:=' + path, '_level:=huge'), '~level', "'huge'")

    def test_invalid_robot_name(self):
        path = self.fixture('bad_robot_name.yaml')
        self.assertRefused(self.run_node('_scenario:=' + path), path, 'robots[0].name', "'sbot-0'")

    def test_effects_file_out_of_bounds(self):
        scenario = self.fixture('three_robots.yaml')
        effects = self.fixture('malformed.effects.yaml')
        self.assertRefused(self.run_node('_scenario:=' + scenario, '_effects:=' + effects), effects,
                           'effects[0].params.delay')

    def test_good_scenario_is_accepted(self):
        # Control: the same invocation with a valid scenario runs until its duration and exits 0.
        path = self.fixture('three_robots.yaml')
        proc = self.run_node('_scenario:=' + path, '_duration:=0.2', '_real_time_factor:=0.0')
        self.assertEqual(proc.returncode, 0, 'stderr:\n' + proc.stderr)
        self.assertIn('duration reached', proc.stdout)


if __name__ == '__main__':
    rostest.rosrun('sbot_sim', 'node_malformed_scenario', TestMalformedScenario)
