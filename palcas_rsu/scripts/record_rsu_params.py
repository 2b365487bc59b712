#!/usr/bin/python3
"""Publishes the RSUs' parameters once, latched, on /rsu_params (std_msgs/String, JSON
{rsu_id: its private parameters}) so that a bag of the run carries them: replay_policy then
builds the RSUs the run had (network, scales, decision period) from the bag alone.
roslaunch sets every parameter before it starts a node, so they are all there at start.

    record_rsu_params.py RSU_ID...
"""
import json
import sys

import rospy
from std_msgs.msg import String


def main():
    rospy.init_node("palcas_record_rsu_params", anonymous=False)
    ids = [a for a in rospy.myargv(sys.argv)[1:] if a]
    params = {}
    for rsu_id in ids:
        name = "/%s/rsu" % rsu_id  # rsu.launch: <group ns=rsu_id><node name="rsu">
        if rospy.has_param(name):
            params[rsu_id] = rospy.get_param(name)
        else:
            rospy.logwarn("no parameters under %s: not recorded", name)
    pub = rospy.Publisher("/rsu_params", String, queue_size=1, latch=True)
    pub.publish(String(data=json.dumps(params, sort_keys=True)))
    rospy.spin()  # a latched message lives as long as its publisher


if __name__ == "__main__":
    main()
