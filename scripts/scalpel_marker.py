#!/usr/bin/python3
"""rviz interactive marker: a 6-DOF scalpel handle that publishes scalpel/pose.

Add an "InteractiveMarkers" display on /scalpel_marker/update in rviz and drag the handle.
Parameters: ~frame_id (tissue), ~initial_position ([0.09, 0.003, 0.028]: outside the thigh's
operation region), ~initial_orientation ([0, 0, 0, 1]), ~blade_length (0.02 m, drawing only),
~rate (Hz, 30: the current pose is republished so the node always has a fresh one).
The pose origin is the blade tip; the cutting edge runs along local +x (docs/SCENE.md "Scene
file", `scalpel`).
"""
import copy

import rospy
from geometry_msgs.msg import Point, PoseStamped
from interactive_markers.interactive_marker_server import InteractiveMarkerServer
from visualization_msgs.msg import InteractiveMarker, InteractiveMarkerControl, Marker


def controls():
    out = []
    for name, (w, x, y, z) in (("x", (1, 1, 0, 0)), ("y", (1, 0, 0, 1)), ("z", (1, 0, 1, 0))):
        for mode, prefix in ((InteractiveMarkerControl.ROTATE_AXIS, "rotate_"),
                             (InteractiveMarkerControl.MOVE_AXIS, "move_")):
            c = InteractiveMarkerControl()
            c.name = prefix + name
            c.orientation.w, c.orientation.x, c.orientation.y, c.orientation.z = w, x, y, z
            c.interaction_mode = mode
            out.append(c)
    return out


def main():
    rospy.init_node("scalpel_marker")
    frame_id = rospy.get_param("~frame_id", "tissue")
    pos = rospy.get_param("~initial_position", [0.09, 0.003, 0.028])
    ori = rospy.get_param("~initial_orientation", [0.0, 0.0, 0.0, 1.0])
    blade = float(rospy.get_param("~blade_length", 0.02))
    rate = float(rospy.get_param("~rate", 30.0))
    pub = rospy.Publisher("scalpel/pose", PoseStamped, queue_size=10)

    current = PoseStamped()
    current.header.frame_id = frame_id
    current.pose.position.x, current.pose.position.y, current.pose.position.z = pos
    (current.pose.orientation.x, current.pose.orientation.y, current.pose.orientation.z,
     current.pose.orientation.w) = ori

    im = InteractiveMarker()
    im.header.frame_id = frame_id
    im.name = "scalpel"
    im.description = "scalpel (tip at origin, edge along +x)"
    im.scale = 0.05
    im.pose = copy.deepcopy(current.pose)
    shape = Marker()
    shape.type = Marker.TRIANGLE_LIST
    shape.scale.x = shape.scale.y = shape.scale.z = 1.0
    shape.color.r, shape.color.g, shape.color.b, shape.color.a = 0.8, 0.8, 0.85, 1.0
    tip, heel, back = Point(0, 0, 0), Point(blade, 0, 0), Point(blade, 0, 0.3 * blade)
    shape.points = [tip, heel, back, tip, back, heel]
    visual = InteractiveMarkerControl()
    visual.always_visible = True
    visual.interaction_mode = InteractiveMarkerControl.MOVE_ROTATE_3D
    visual.markers.append(shape)
    im.controls.append(visual)
    im.controls.extend(controls())

    server = InteractiveMarkerServer("scalpel_marker")

    def feedback(fb):
        current.pose = fb.pose
        current.header.stamp = rospy.Time.now()
        pub.publish(current)

    server.insert(im, feedback)
    server.applyChanges()
    rospy.loginfo("scalpel_marker: drag the handle in rviz (InteractiveMarkers /scalpel_marker/update)")
    r = rospy.Rate(rate)
    while not rospy.is_shutdown():
        current.header.stamp = rospy.Time.now()
        pub.publish(current)
        try:
            r.sleep()
        except rospy.ROSInterruptException:
            break


if __name__ == "__main__":
    main()
