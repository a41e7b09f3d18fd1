#!/usr/bin/env python3
"""Unpause the simulator once everyone who must watch from t = 0 is connected.

A swarm launch starts the simulator paused; this node advances it by one step (rosbag record and
other sim-time nodes wait for a non-zero /clock before they subscribe), waits until every robot's
ground_truth has `min_subscribers` subscribers (its controller, and the rosbag recorder when
recording) and every recorded topic has one, then until the publishing nodes report a live link
to every subscriber of those topics, then calls /sim/unpause. So a recording covers the run from
its first step, whatever the machine's speed.

Why the second wait: the master lists a subscriber as soon as it registers, but messages reach it
only once the publisher has accepted its connection. With 20 robots rosbag registers ~120 topics
in 0.2 s and the connections follow one by one; unpaused at registration, a loaded 2-core machine
can record nothing of six robots' ground truth in a 30 s demo (test/test_swarm_record.py).

Private parameters:
  ~robots           int   number of robots sbot_0 .. sbot_<n-1> (required)
  ~min_subscribers  int   subscribers each /sbot_<i>/ground_truth needs (default 1)
  ~recorded_topics  str   space-separated topics a recorder will subscribe to, each needing one
                          subscriber (default: none)
  ~timeout          float wall seconds to wait before unpausing anyway, with a warning (default 60)
"""
import time

try:
    from xmlrpc.client import ServerProxy
except ImportError:  # pragma: no cover - Python 2
    from xmlrpclib import ServerProxy

import rosgraph
import rospy
from sbot_msgs.srv import Step
from std_srvs.srv import Trigger

CALLER = '/start_when_ready'


def registrations(master):
    """{topic: [publisher nodes]}, {topic: [subscriber nodes]} as the master knows them."""
    publishers, subscribers, _ = master.getSystemState()
    return dict(publishers), dict(subscribers)


def live_links(master, node):
    """{topic: number of outbound connections} the publishing `node` reports (Slave API getBusInfo:
    [id, destination, direction, transport, topic, connected, ...]); {} if it cannot be asked."""
    try:
        code, _, bus = ServerProxy(master.lookupNode(node)).getBusInfo(CALLER)
    except Exception:  # a node that just went away or is still starting: ask again next round
        return {}
    links = {}
    if code == 1:
        for entry in bus:
            if len(entry) > 4 and entry[2] == 'o' and (len(entry) < 6 or entry[5]):
                links[entry[4]] = links.get(entry[4], 0) + 1
    return links


def not_ready(master, needed):
    """The topics of `needed` ({topic: subscribers}) that lack registered subscribers, or whose
    publishers do not have a live link to each of them yet."""
    publishers, subscribers = registrations(master)
    waiting = [t for t, n in needed.items() if len(subscribers.get(t, [])) < n]
    if waiting:
        return waiting
    links = {}
    for node in set(p for t in needed for p in publishers.get(t, [])):
        links[node] = live_links(master, node)
    return [t for t in needed for p in publishers.get(t, [])
            if links[p].get(t, 0) < len(subscribers.get(t, []))]


def main():
    rospy.init_node('start_when_ready')
    robots = rospy.get_param('~robots')
    needed_gt = rospy.get_param('~min_subscribers', 1)
    recorded = rospy.get_param('~recorded_topics', '').split()
    timeout = rospy.get_param('~timeout', 60.0)
    rospy.loginfo('start_when_ready: robots=%d min_subscribers=%d recorded topics=%d timeout=%.0f s',
                  robots, needed_gt, len(recorded), timeout)
    rospy.wait_for_service('/sim/step')
    rospy.ServiceProxy('/sim/step', Step)(1)  # t = one step: a valid (non-zero) ROS time
    master = rosgraph.Master(CALLER)
    needed = {t: 1 for t in recorded}
    for i in range(robots):
        topic = '/sbot_%d/ground_truth' % i
        needed[topic] = max(needed.get(topic, 0), needed_gt)
    start = time.time()
    while not rospy.is_shutdown():
        waiting = not_ready(master, needed)
        if not waiting:
            rospy.loginfo('start_when_ready: %d topics connected after %.1f s', len(needed), time.time() - start)
            break
        if time.time() > start + timeout:
            rospy.logwarn('start_when_ready: %d topics still lack subscribers or their connections (e.g. %s); '
                          'starting anyway', len(waiting), waiting[0])
            break
        time.sleep(0.2)
    rospy.wait_for_service('/sim/unpause')
    rospy.ServiceProxy('/sim/unpause', Trigger)()
    rospy.loginfo('start_when_ready: simulation unpaused')


if __name__ == '__main__':
    try:
        main()
    except rospy.ROSInterruptException:
        # The launch is shutting down (e.g. the simulator refused its scenario and said why): no traceback.
        pass
