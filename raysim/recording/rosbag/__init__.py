"""A recording as a ROS 2 bag (rosbag2 directory, metadata version 8 for Humble, one MCAP file).

Written from the recording's own files after the sensors (and after the TDM in ``raysim run``),
one message at a time, in log-time order across topics, zstd-compressed chunks with CRCs, every
topic with the QoS its real publisher offers. docs/formats.md "rosbag/" lists the topics; the
modules:

| module | job |
|---|---|
| :mod:`.msgs` | the typestore (Humble plus marine_sensor_msgs, nmea_msgs, vision_msgs, foxglove_msgs, tdm_msgs) and message builders |
| :mod:`.storage` | the MCAP file: rosbags' rosbag2 writer over the mcap library's chunked, compressed, CRC'd writer |
| :mod:`.qos` | the offered QoS per topic |
| :mod:`.sensors` | tf_static (mounts), LiDAR clouds, radar sectors and PPI pictures, AIS sentences |
| :mod:`.ownship` | fix, pose, tf, IMU and odometry from the navigation solution, with covariances |
| :mod:`.objects` | truth boxes, labels and GeoJSON; detected targets as their own message, markers, detections and GeoJSON |
| :mod:`.writer` | the merge of every stream into the bag |
"""

from raysim.recording.rosbag.msgs import (DETECTED_TARGET_ARRAY_MSG, DETECTED_TARGET_MSG, GEOJSON_MSG, NMEA_SENTENCE_MSG,
                                          RADAR_ECHO_MSG, RADAR_SECTOR_MSG, VISION_MSGS)
from raysim.recording.rosbag.sensors import POINT_STEP
from raysim.recording.rosbag.writer import write_rosbag

__all__ = ["write_rosbag", "RADAR_SECTOR_MSG", "RADAR_ECHO_MSG", "NMEA_SENTENCE_MSG", "DETECTED_TARGET_MSG",
           "DETECTED_TARGET_ARRAY_MSG", "GEOJSON_MSG", "VISION_MSGS", "POINT_STEP"]
