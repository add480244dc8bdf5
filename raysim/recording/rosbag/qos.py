"""Offered QoS of every topic, as the real publishers offer it (what ``ros2 bag play`` re-offers).

Humble's ``ros2 bag play`` publishes each topic with the QoS recorded in ``metadata.yaml``; an
empty profile list makes it fall back to volatile, and then RViz 2's static-transform listener
(transient local) never receives ``/tf_static`` (rviz issue 916). The profiles:

| topic | reliability | durability | history | as |
|---|---|---|---|---|
| ``/tf_static`` | reliable | transient local | keep last 1 | tf2_ros StaticTransformBroadcaster |
| ``/tf`` | reliable | volatile | keep last 100 | tf2_ros TransformBroadcaster |
| every other topic | reliable | volatile | keep last 10 | ``rclcpp::QoS(10)``, the drivers' publishers (velodyne_pointcloud, nmea_navsat_driver, image_transport) |

Durations (deadline, lifespan, liveliness lease) are infinite, recorded as Humble records them.
"""

from __future__ import annotations

__all__ = ["offered_qos"]

#: Humble's record of an infinite duration (RMW_DURATION_INFINITE as sec, nsec).
_INFINITE = (2_147_483_647, 4_294_967_295)


def _profile(depth: int, transient_local: bool):
    from rosbags.interfaces import Qos, QosDurability, QosHistory, QosLiveliness, QosReliability, QosTime

    forever = QosTime(*_INFINITE)
    return Qos(history=QosHistory.KEEP_LAST, depth=depth, reliability=QosReliability.RELIABLE,
               durability=QosDurability.TRANSIENT_LOCAL if transient_local else QosDurability.VOLATILE,
               deadline=forever, lifespan=forever, liveliness=QosLiveliness.AUTOMATIC,
               liveliness_lease_duration=forever, avoid_ros_namespace_conventions=False)


def offered_qos(topic: str) -> list:
    """The offered QoS profiles (one publisher) of ``topic``, as rosbags ``Qos`` tuples."""
    if topic == "/tf_static":
        return [_profile(1, transient_local=True)]
    if topic == "/tf":
        return [_profile(100, transient_local=False)]
    return [_profile(10, transient_local=False)]
