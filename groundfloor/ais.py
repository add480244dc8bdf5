"""AIS facts that the renderer writes and the TDM reads (ITU-R M.1371-5; docs/reference.md section 4, "Reporting
intervals").

- The navigational status of a Class A position report (messages 1-3, bits 38-41); a Class B report carries none.
- A Class A ship at anchor or moored and not moving faster than 3 kn reports every 3 minutes (Table 1).
"""

from __future__ import annotations

__all__ = ["HELD_MAX_SOG_KN", "HELD_REPORT_INTERVAL_S", "NAV_STATUS", "NAV_STATUS_AT_ANCHOR", "NAV_STATUS_MOORED",
           "NAV_STATUS_NOT_DEFINED", "NAV_STATUS_UNDER_WAY"]

#: Navigational status codes: under way using engine, at anchor, moored, and "not defined" (the default, what a
#: Class B report stands for).
NAV_STATUS_UNDER_WAY, NAV_STATUS_AT_ANCHOR, NAV_STATUS_MOORED, NAV_STATUS_NOT_DEFINED = 0, 1, 5, 15
#: The statuses a scenario names, by name.
NAV_STATUS = {"under_way": NAV_STATUS_UNDER_WAY, "at_anchor": NAV_STATUS_AT_ANCHOR, "moored": NAV_STATUS_MOORED}
#: Reporting interval of a Class A ship at anchor or moored, s.
HELD_REPORT_INTERVAL_S = 180.0
#: The speed over ground up to which a ship at anchor or moored reports at that interval, kn.
HELD_MAX_SOG_KN = 3.0
