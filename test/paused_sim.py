"""Shared by the rostests whose simulator starts paused (launch arg paused:=true): connect, unpause,
and let the simulation run for a given simulated time, so a run is judged from t = 0."""
import time

import rosgraph
import rospy
from std_srvs.srv import Trigger


def unpause_and_run(subscribers, simulated, duration, wall_timeout):
    """Waits (up to 20 s each) until every subscriber is connected, calls /sim/unpause and returns
    once simulated() >= duration [s sim] or after wall_timeout [s wall]. Returns the wall time [s]
    the simulation ran."""
    for s in subscribers:
        deadline = time.monotonic() + 20
        while s.get_num_connections() == 0 and time.monotonic() < deadline:
            time.sleep(0.05)
    wall0 = time.monotonic()
    rospy.ServiceProxy('/sim/unpause', Trigger)()
    deadline = time.monotonic() + wall_timeout
    while time.monotonic() < deadline and simulated() < duration:
        time.sleep(0.05)
    return time.monotonic() - wall0


def wait_for_controllers(caller_id, robots, topic, publishers=True, timeout=60.0):
    """True once, for every robot r, a node other than the simulator publishes (publishers=True)
    or subscribes to /r/<topic>; False after timeout [s wall]."""
    master = rosgraph.Master(caller_id)
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        state = master.getSystemState()[0 if publishers else 1]
        nodes = {t: n for t, n in state}
        if all(any(not n.startswith('/simulator') for n in nodes.get('/%s/%s' % (r, topic), [])) for r in robots):
            return True
        time.sleep(0.2)
    return False
