#!/usr/bin/env python3
"""Unpause the simulator once everyone who must watch from t = 0 is subscribed.

A swarm launch starts the simulator paused; this node advances it by one step (rosbag record and
other sim-time nodes wait for a non-zero /clock before they subscribe), waits until every robot's
ground_truth has `min_subscribers` subscribers (its controller, and the rosbag recorder when
recording), then calls /sim/unpause. So a recording covers the run from its first step, whatever
the machine's speed.

Private parameters:
  ~robots           int   number of robots sbot_0 .. sbot_<n-1> (required)
  ~min_subscribers  int   subscribers each /sbot_<i>/ground_truth needs (default 1)
  ~timeout          float wall seconds to wait before unpausing anyway, with a warning (default 60)
"""
import time

import rosgraph
import rospy
from sbot_msgs.srv import Step
from std_srvs.srv import Trigger


def subscriber_counts(master):
    _, subscribers, _ = master.getSystemState()
    return {topic: len(nodes) for topic, nodes in subscribers}


def main():
    rospy.init_node('start_when_ready')
    robots = rospy.get_param('~robots')
    needed = rospy.get_param('~min_subscribers', 1)
    timeout = rospy.get_param('~timeout', 60.0)
    rospy.loginfo('start_when_ready: robots=%d min_subscribers=%d timeout=%.0f s', robots, needed, timeout)
    rospy.wait_for_service('/sim/step')
    rospy.ServiceProxy('/sim/step', Step)(1)  # t = one step: a valid (non-zero) ROS time
    master = rosgraph.Master('/start_when_ready')
    topics = ['/sbot_%d/ground_truth' % i for i in range(robots)]
    deadline = time.time() + timeout
    while not rospy.is_shutdown():
        counts = subscriber_counts(master)
        waiting = [t for t in topics if counts.get(t, 0) < needed]
        if not waiting:
            break
        if time.time() > deadline:
            rospy.logwarn('start_when_ready: %d topics still lack subscribers (e.g. %s); starting anyway',
                          len(waiting), waiting[0])
            break
        time.sleep(0.2)
    rospy.wait_for_service('/sim/unpause')
    rospy.ServiceProxy('/sim/unpause', Trigger)()
    rospy.loginfo('start_when_ready: simulation unpaused')


if __name__ == '__main__':
    main()
