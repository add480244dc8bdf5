"""Live mode: raysim as the vessel's sensors on the network (docs/live.md)."""
