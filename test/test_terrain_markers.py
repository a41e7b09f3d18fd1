#!/usr/bin/python3
"""rostests (terrain_markers_composite.test, terrain_markers_rough.test): what rviz draws of the
scenario's terrain is the terrain the simulator built from the scenario file.

/sim/markers sends the terrain to each new subscriber. For a composite world every box of the
scenario must come as a CUBE of its centre, size and pitch/yaw (ns terrain/boxes, id = its index);
for rough terrain the height field must come as a TRIANGLE_LIST (ns terrain/heightmap) over the
scenario's size whose heights span [0, height_range]. Param ~scenario: the scenario file."""
import math
import os
import sys
import threading
import unittest

import rospy
import rostest
import yaml

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import marker_array  # noqa: E402

CUBE, TRIANGLE_LIST = 1, 11


def quaternion(pitch, yaw):
    """(x, y, z, w) of roll 0, `pitch`, `yaw` (the simulator's quatFromRPY)."""
    cp, sp, cy, sy = math.cos(pitch / 2), math.sin(pitch / 2), math.cos(yaw / 2), math.sin(yaw / 2)
    return (-sp * sy, sp * cy, cp * sy, cp * cy)


class TerrainMarkers(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node('test_terrain_markers')
        with open(rospy.get_param('~scenario')) as f:
            cls.terrain = yaml.safe_load(f)['world']['terrain']
        cls.lock = threading.Lock()
        cls.terrain_markers = None
        cls.sub = rospy.Subscriber('/sim/markers', rospy.AnyMsg, cls.on_markers)

    @classmethod
    def on_markers(cls, msg):
        markers = [m for m in marker_array.decode(msg._buff) if m.ns.startswith('terrain/')]
        if markers:
            with cls.lock:
                cls.terrain_markers = markers

    def received(self):
        deadline = rospy.Time.now() + rospy.Duration(30.0)  # sim time runs at the scenario's pace
        while not rospy.is_shutdown():
            with self.lock:
                if self.terrain_markers is not None:
                    return self.terrain_markers
            if rospy.Time.now() > deadline:
                break
            rospy.sleep(0.1)
        self.fail('no terrain markers on /sim/markers')

    def test_boxes_are_the_scenarios(self):
        boxes = self.terrain.get('boxes') or []
        cubes = sorted((m for m in self.received() if m.ns == 'terrain/boxes'), key=lambda m: m.id)
        self.assertEqual(len(cubes), len(boxes), 'terrain/boxes markers against the scenario\'s boxes')
        for box, cube in zip(boxes, cubes):
            name = box.get('name', cube.id)
            self.assertEqual(cube.type, CUBE, name)
            self.assertEqual(cube.frame_id, 'world', name)
            for got, want in zip(cube.position, box['center']):
                self.assertAlmostEqual(got, want, places=6, msg='%s centre %s' % (name, cube.position))
            for got, want in zip(cube.scale, box['size']):
                self.assertAlmostEqual(got, want, places=6, msg='%s size %s' % (name, cube.scale))
            want_q = quaternion(box.get('pitch', 0.0), box.get('yaw', 0.0))
            dot = abs(sum(a * b for a, b in zip(cube.orientation, want_q)))
            self.assertAlmostEqual(dot, 1.0, places=6, msg='%s orientation %s, want %s' % (name, cube.orientation, want_q))

    def test_height_field_is_the_scenarios(self):
        fields = [m for m in self.received() if m.ns == 'terrain/heightmap']
        if self.terrain.get('type') != 'rough':
            self.assertEqual(fields, [], 'a height field drawn for a %s terrain' % self.terrain.get('type'))
            return
        self.assertEqual(len(fields), 1, 'terrain/heightmap markers')
        m = fields[0]
        self.assertEqual(m.type, TRIANGLE_LIST)
        self.assertGreater(len(m.points), 0)
        self.assertEqual(len(m.points) % 3, 0, 'whole triangles')
        half = self.terrain.get('size', 5.0) / 2.0
        hr = self.terrain['height_range']
        xs, ys, zs = zip(*m.points)
        self.assertLessEqual(max(abs(v) for v in xs + ys), half + 1e-6, 'drawn beyond the field\'s %g m' % (2 * half))
        self.assertAlmostEqual(max(xs) - min(xs), 2 * half, delta=0.05 * half, msg='x extent')
        self.assertAlmostEqual(max(ys) - min(ys), 2 * half, delta=0.05 * half, msg='y extent')
        self.assertGreaterEqual(min(zs), -1e-6, 'heights below 0')
        self.assertLessEqual(max(zs), hr + 1e-6, 'heights above the height range %g m' % hr)
        self.assertGreater(max(zs) - min(zs), 0.5 * hr, 'the drawn field spans its height range %g m' % hr)


if __name__ == '__main__':
    rostest.rosrun('swarmbot3d', 'test_terrain_markers', TerrainMarkers)
