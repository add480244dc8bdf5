"""Front ends of the TDM: raw sensor scans in, :class:`tdm.detections.Detections` out."""
